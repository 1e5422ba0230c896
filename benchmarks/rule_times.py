"""Where a workflow run spent its time: Snakemake's benchmark files summed per rule.

Usage: python benchmarks/rule_times.py [results/benchmarks]

Prints, per rule, the number of jobs and the sum of their wall times (column ``s``), largest first,
and the total. With ``-j2`` the sum is about twice the run's wall time when both cores are busy.
Snakemake's ``cpu_time`` column is not summed: it samples the process tree and under-reports
(on the paper run: 1,060 s of CPU for IK jobs whose wall times sum to 2,885 s, while
``/usr/bin/time`` counted user + system = the summed wall times).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd


def rule_times(root: Path) -> pd.DataFrame:
    """One row per rule: rule, jobs, wall_s (sum over its jobs), share_pct; largest first."""
    rows = []
    for path in sorted(root.rglob("*.tsv")):
        frame = pd.read_csv(path, sep="\t")
        if "s" not in frame or frame.empty:
            raise SystemExit(f"{path}: not a Snakemake benchmark file (no column 's')")
        rows.append({"rule": path.relative_to(root).parts[0], "wall_s": float(frame["s"].iloc[-1])})
    if not rows:
        raise SystemExit(f"{root}: no benchmark files")
    table = pd.DataFrame(rows).groupby("rule").agg(jobs=("wall_s", "size"), wall_s=("wall_s", "sum")).reset_index()
    table["share_pct"] = 100.0 * table["wall_s"] / table["wall_s"].sum()
    return table.sort_values("wall_s", ascending=False, ignore_index=True)


def main(root: str = "results/benchmarks") -> None:
    table = rule_times(Path(root))
    print(table.to_string(index=False, float_format=lambda v: f"{v:.1f}"))
    print(f"total: {int(table['jobs'].sum())} jobs, {table['wall_s'].sum():.0f} s of job wall time")


if __name__ == "__main__":
    main(*sys.argv[1:2])
