"""Wall time and accuracy of the whole validation study with `snakemake -j2`.

Usage: python benchmarks/validation_study.py
Copies the workflow into a temporary directory (your results/ stay untouched),
runs `snakemake -j2 results/validation/summary.tsv` there, and prints the wall
time and the summary against the targets (no-noise errors within 0.05 N·m/rad and 0.005 N·m·s/rad).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

from loper_analysis.stages import study_paths

ROOT = Path(__file__).resolve().parents[1]
PATHS = study_paths()


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for item in ("Snakefile", "workflow", "config"):
            src = ROOT / item
            (shutil.copytree if src.is_dir() else shutil.copy)(src, work / item)
        t0 = time.perf_counter()
        res = subprocess.run(
            [sys.executable, "-m", "snakemake", "-j2", PATHS.validation.summary],
            cwd=work,
            capture_output=True,
            text=True,
        )
        wall = time.perf_counter() - t0
        if res.returncode:
            sys.exit(res.stderr[-3000:])
        summary = pd.read_csv(work / PATHS.validation.summary, sep="\t")
        bench = pd.concat(
            pd.read_csv(p, sep="\t") for p in (work / PATHS.benchmark("validation_chunk", "*")).parent.glob("*.tsv")
        )
    print(
        f"validation study (729 combinations x 2 conditions x 10 starts), snakemake -j2: {wall:.1f} s wall "
        f"(chunk jobs {bench.s.sum():.1f} s CPU in all)"
    )
    pd.set_option("display.width", 200)
    cols = [
        "condition",
        "parameter",
        "min_error",
        "max_error",
        "sd_error",
        "study_min_error",
        "study_max_error",
        "study_sd_error",
    ]
    print(summary[cols].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    clean = summary[summary.condition == "no_noise"].set_index("parameter")["max_abs_error"]
    k_ok = clean[clean.index.str.startswith("K")].max() <= 0.05
    d_ok = clean[clean.index.str.startswith("D")].max() <= 0.005
    print(
        f"no noise: max |dK| {clean[clean.index.str.startswith('K')].max():.4g} (target 0.05) "
        f"{'ok' if k_ok else 'MISSED'}; max |dD| {clean[clean.index.str.startswith('D')].max():.4g} "
        f"(target 0.005) {'ok' if d_ok else 'MISSED'}"
    )
    noisy = summary[summary.condition == "noise"].set_index("parameter")
    for p in ("K_hip", "D_hip", "K_knee", "D_knee"):
        ok = noisy.loc[p, "sd_error"] <= noisy.loc[p, "study_sd_error"]
        print(
            f"noise: SD {p} {noisy.loc[p, 'sd_error']:.4g} vs study {noisy.loc[p, 'study_sd_error']:.4g} "
            f"{'ok' if ok else 'MISSED'}"
        )
    print(f"speed: {wall:.1f} s (target 60 s) {'ok' if wall <= 60 else 'MISSED'}")


if __name__ == "__main__":
    main()
