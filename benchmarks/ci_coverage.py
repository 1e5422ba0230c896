"""How often do the 95 % confidence intervals of the impedance fits hold the truth? A coverage measurement.

Usage: python benchmarks/ci_coverage.py [--subjects N] [--seed S] [--jobs J] [--keep DIR]

Builds a copy of the workflow with N synthetic subjects (anthropometrics drawn from the study's
subjects, true K and D drawn around the group values as in the default study, the default design:
2 trials of 45 s per onset, noise model ``null_pairs``), runs ``snakemake -jJ
results/tables/impedance.tsv`` (the processing chain from the simulated C3D files to the fits; no
validation study, no device tests) and counts, per joint and parameter, the fitted rows (``ok`` or
``not_identifiable``) whose 95 % CI holds the truth. Prints a Markdown table; each subject gives three
fits (onsets 50, 175, 300 ms), so 34 subjects give 102. ``--keep DIR`` keeps the project (its
``results/tables/impedance.tsv``) for a closer look.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from loper_analysis.markdown import markdown_table

ROOT = Path(__file__).resolve().parents[1]


def coverage_table(table: pd.DataFrame) -> pd.DataFrame:
    """Per joint and parameter: fitted rows, rows whose CI holds the truth, coverage, median CI width."""
    fitted = table[table["status"].isin(["ok", "not_identifiable"])]
    rows = []
    for joint in ("hip", "knee", "ankle"):
        g = fitted[fitted["joint"] == joint]
        for p, unit in (("K", "nm_per_rad"), ("D", "nms_per_rad")):
            low, high = g[f"{p}_ci95_low_{unit}"], g[f"{p}_ci95_high_{unit}"]
            truth = g[f"{p}_true_{unit}"]
            has_ci = low.notna() & high.notna()
            inside = has_ci & (low <= truth) & (truth <= high)
            rows.append({"joint": joint, "parameter": p, "n_fits": int(has_ci.sum()), "n_inside": int(inside.sum()),
                         "coverage_pct": 100.0 * inside.sum() / max(int(has_ci.sum()), 1),
                         "median_ci_width": float(np.median((high - low)[has_ci])) if has_ci.any() else np.nan,
                         "n_not_identifiable": int((g["status"] == "not_identifiable").sum())})
    return pd.DataFrame(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--subjects", type=int, default=34)
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--keep", type=Path)
    args = ap.parse_args()
    work = args.keep or Path(tempfile.mkdtemp(prefix="ci_coverage_"))
    work.mkdir(parents=True, exist_ok=True)
    for item in ("Snakefile", "workflow", "config"):
        target = work / item
        if not target.exists():
            (shutil.copytree if (ROOT / item).is_dir() else shutil.copy)(ROOT / item, target)
    names = [f"C{k:03d}" for k in range(1, args.subjects + 1)]
    (work / "config/coverage_subjects.tsv").write_text(
        "subject\tsource\n" + "".join(f"{s}\tsynthetic\n" for s in names))
    (work / "config/coverage.yaml").write_text(yaml.safe_dump({
        "subjects": "config/coverage_subjects.tsv", "seed": args.seed, "device": {"subject": names[0]}}))
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-m", "snakemake", "-j", str(args.jobs), "results/tables/impedance.tsv",
                          "--configfile", "config/coverage.yaml", "-q"], cwd=work, check=False)
    if res.returncode:
        raise SystemExit(f"snakemake failed in {work} (exit {res.returncode})")
    table = pd.read_csv(work / "results/tables/impedance.tsv", sep="\t")
    out = coverage_table(table)
    print(f"{args.subjects} synthetic subjects, {table.groupby(['subject', 'onset_ms']).ngroups} subject x onset fits, "
          f"seed {args.seed}, {time.perf_counter() - t0:.0f} s with -j{args.jobs}; statuses: "
          f"{table['status'].value_counts().to_dict()}")
    print(markdown_table(out.round(3)))
    if args.keep is None:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
