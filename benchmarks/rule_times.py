"""Where a workflow run spent its time, per rule: start-up, file I/O and compute.

Usage: python benchmarks/rule_times.py [results]

Reads Snakemake's benchmark file of every job (``results/benchmarks/{rule}/...tsv``, column ``s``: the
job's wall time, from launch to exit) and the last line of the job's log (``results/logs/{rule}/...log``,
written by ``loper_analysis.stages.rule_log``): the wall time from the job's first file access to its end,
the part of it spent reading and writing files, and the first imports of OpenSim or ezc3d made by a reader.
Per job:

* start-up = s - (time after the first file access) + those imports: launching Python, Snakemake's script
  preamble, importing numpy, pandas, SciPy, OpenSim ...;
* I/O = reading inputs and writing outputs (parsing and formatting included: the atomic writer and the
  readers of ``loper_analysis.io``; a figure's rendering counts as writing it);
* compute = the rest.

Prints one row per rule (jobs, wall and its split in s, largest first) and the total. With ``-j2`` the total
is about twice the run's wall time when both cores are busy. Snakemake's ``cpu_time`` column is not used:
it samples the process tree and under-reports.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pandas as pd

from loper_analysis.layout import RESULTS_DIR

TIMING = re.compile(r"job time: after_first_io_s=([0-9.]+) io_s=(-?[0-9.]+) library_import_s=([0-9.]+)")


def job_split(wall_s: float, log_text: str | None) -> dict[str, float]:
    """start-up, I/O and compute seconds of one job from its wall time and its log (None: all unsplit)."""
    m = TIMING.search(log_text or "")
    if m is None:
        return {"startup_s": float("nan"), "io_s": float("nan"), "compute_s": float("nan")}
    after, io, imports = (float(g) for g in m.groups())
    io = max(io, 0.0)
    startup = max(wall_s - after, 0.0) + imports
    return {"startup_s": startup, "io_s": io, "compute_s": max(wall_s - startup - io, 0.0)}


def rule_times(results: Path) -> pd.DataFrame:
    """One row per rule: rule, jobs, wall_s, startup_s, io_s, compute_s (sums over its jobs), share_pct."""
    bench = results / "benchmarks"
    rows = []
    for path in sorted(bench.rglob("*.tsv")):
        frame = pd.read_csv(path, sep="\t")
        if "s" not in frame or frame.empty:
            raise SystemExit(f"{path}: not a Snakemake benchmark file (no column 's')")
        rel = path.relative_to(bench)
        log = results / "logs" / rel.with_suffix(".log")
        wall = float(frame["s"].iloc[-1])
        rows.append(
            {"rule": rel.parts[0], "wall_s": wall, **job_split(wall, log.read_text() if log.is_file() else None)}
        )
    if not rows:
        raise SystemExit(f"{bench}: no benchmark files")
    table = (
        pd.DataFrame(rows)
        .groupby("rule")
        .agg(
            jobs=("wall_s", "size"),
            wall_s=("wall_s", "sum"),
            startup_s=("startup_s", "sum"),
            io_s=("io_s", "sum"),
            compute_s=("compute_s", "sum"),
        )
        .reset_index()
    )
    table["share_pct"] = 100.0 * table["wall_s"] / table["wall_s"].sum()
    return table.sort_values("wall_s", ascending=False, ignore_index=True)


def main(results: str = RESULTS_DIR) -> None:
    root = Path(results)
    if root.name == "benchmarks":  # the former argument: results/benchmarks
        root = root.parent
    table = rule_times(root)
    print(table.to_string(index=False, float_format=lambda v: f"{v:.1f}"))
    total = table[["wall_s", "startup_s", "io_s", "compute_s"]].sum()
    print(
        f"total: {int(table['jobs'].sum())} jobs, {total['wall_s']:.0f} s of job wall time: start-up "
        f"{total['startup_s']:.0f} s, I/O {total['io_s']:.0f} s, compute {total['compute_s']:.0f} s"
    )


if __name__ == "__main__":
    main(*sys.argv[1:2])
