"""How the workflow's cost grows: wall and CPU time from nothing for n subjects, trial length and cores.

Usage: python benchmarks/scaling.py [--cases 1x45x2 3x45x1 ...] [--out scaling.tsv]

A case ``NxTxJ`` runs ``snakemake -jJ`` from nothing in a fresh copy of the project, with the first N
subjects of ``config/subjects_paper.tsv`` and walking trials of T s (``synthetic.walking_duration_s``;
everything else as ``config/config.yaml``). Each run's wall time, and the user + system CPU time of
Snakemake and all its jobs (``os.times`` of the finished children), are printed with the job count and the number of
motion-capture frames of the walking trials (128 Hz). A least-squares fit CPU = a + b * frames + c * subjects over the
cases shows the per-frame cost, the per-subject part (static trial, model, fits, the jobs' start-up) and the
fixed part (validation study, device tests, aggregate tables and figures).
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_CASES = ["1x45x1", "1x45x2", "3x45x1", "3x45x2", "9x45x2", "1x240x2", "3x240x2"]
RATE_HZ = 128.0


def run_case(n_subjects: int, duration_s: float, cores: int, work: Path) -> dict:
    """Run one case from nothing in ``work``; returns its row."""
    for item in ("Snakefile", "workflow", "config"):
        src = ROOT / item
        if src.exists():
            (shutil.copytree if src.is_dir() else shutil.copy)(src, work / item)
    sheet = pd.read_csv(ROOT / "config/subjects_paper.tsv", sep="\t", dtype={"subject": str}, comment="#")
    sheet.head(n_subjects).to_csv(work / "config/scaling_subjects.tsv", sep="\t", index=False)
    overlay = {
        "subjects": "config/scaling_subjects.tsv",
        "synthetic": {"walking_duration_s": duration_s},
        "device": {"subject": str(sheet.subject.iloc[0])},
    }
    (work / "config/scaling.yaml").write_text(yaml.safe_dump(overlay))
    start = time.perf_counter()
    proc = subprocess.Popen(
        [sys.executable, "-m", "snakemake", f"-j{cores}", "--configfile", "config/scaling.yaml"],
        cwd=work,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    out, _ = proc.communicate()
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise SystemExit(f"case {n_subjects}x{duration_s:g}x{cores} failed:\n{out[-3000:]}")
    jobs = int(re.search(r"^total\s+(\d+)", out, re.M).group(1))
    return {
        "subjects": n_subjects,
        "trial_s": duration_s,
        "cores": cores,
        "jobs": jobs,
        "walking_frames": n_subjects * 8 * round(duration_s * RATE_HZ),
        "wall_s": wall,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="*", default=DEFAULT_CASES)
    parser.add_argument("--out", default=None, help="also write the table here (TSV)")
    args = parser.parse_args()
    rows = []
    for case in args.cases:
        n, t, j = case.split("x")
        with tempfile.TemporaryDirectory(prefix="loper-scaling-") as tmp:
            before = os.times()
            row = run_case(int(n), float(t), int(j), Path(tmp))
            after = os.times()
        row["cpu_s"] = (after.children_user - before.children_user) + (after.children_system - before.children_system)
        rows.append(row)
        print(
            pd.DataFrame([row]).to_string(index=False, header=len(rows) == 1, float_format=lambda v: f"{v:.0f}"),
            flush=True,
        )
    table = pd.DataFrame(rows)
    print(table.to_string(index=False, float_format=lambda v: f"{v:.0f}"))
    if len(table) >= 3 and table.walking_frames.nunique() >= 2 and table.subjects.nunique() >= 2:
        design = np.column_stack([np.ones(len(table)), table.walking_frames, table.subjects])
        (a, b, c), *_ = np.linalg.lstsq(design, table.cpu_s.to_numpy(float), rcond=None)
        fit = design @ np.array([a, b, c])
        print(
            f"CPU = {a:.0f} s + {1e3 * b:.3f} ms per walking frame + {c:.1f} s per subject (largest deviation "
            f"{np.max(np.abs(table.cpu_s - fit) / table.cpu_s) * 100:.0f} % of a case's CPU)"
        )
    if args.out:
        table.to_csv(args.out, sep="\t", index=False, float_format="%.1f")


if __name__ == "__main__":
    main()
