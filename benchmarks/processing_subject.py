"""Processing one subject's 8 walking trials end to end (read -> IK -> strides) with `snakemake -j2`.

Usage: python benchmarks/processing_subject.py [walking_duration_s [ik_chunks]]
       (defaults: 240 s, the study's trials; the config's opensim.ik_chunks)

Copies the workflow into a temporary directory with one synthetic subject,
generates its raw files first (not timed: C3D + robot logs, as a lab records
them), then times the processing rules up to the stride tables of all 8
walking trials and the transparency analysis. Prints wall time and the
per-rule CPU time from Snakemake's benchmark files.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
import yaml

from loper_analysis.layout import Paths, fill
from loper_analysis.study_design import StudyDesign

ROOT = Path(__file__).resolve().parents[1]
PATHS = Paths()


def main(duration_s: float = 240.0, ik_chunks: int | None = None) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for item in ("Snakefile", "workflow", "config"):
            src = ROOT / item
            (shutil.copytree if src.is_dir() else shutil.copy)(src, work / item)
        cfg = yaml.safe_load((ROOT / "config/config.yaml").read_text())
        cfg["synthetic"]["walking_duration_s"] = duration_s
        if ik_chunks is not None:
            cfg["opensim"]["ik_chunks"] = ik_chunks
        (work / "config/config.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False))
        (work / "config/subjects.tsv").write_text(
            "subject\tsource\tsex\tage_yr\theight_m\tmass_kg\nS01\tsynthetic\tmale\t26\t1.80\t72.0\n"
        )
        trials = StudyDesign.from_config(cfg["trials"]).walking_trials()
        raw = [fill(PATHS.raw.c3d, subject="S01", trial=t) for t in [cfg["trials"]["static"], *trials]]

        def run(*targets: str) -> None:
            res = subprocess.run(
                [sys.executable, "-m", "snakemake", "--cores", "2", *targets, "--quiet", "all"],
                cwd=work,
                capture_output=True,
                text=True,
            )
            if res.returncode:
                sys.exit(res.stderr[-3000:])

        t0 = time.perf_counter()
        run(*raw)
        t1 = time.perf_counter()
        targets = [fill(PATHS.strides.strides, subject="S01", trial=t) for t in trials] + [PATHS.transparency.rmsd]
        run(*targets)
        t2 = time.perf_counter()
        rows = []
        benchmarks = (work / PATHS.benchmark("rule", "job")).parents[1]
        for tsv in benchmarks.rglob("*.tsv"):
            rule = tsv.relative_to(benchmarks).parts[0]
            if rule.startswith("synthetic"):
                continue
            rows.append({"rule": rule, "cpu_s": pd.read_csv(tsv, sep="\t")["cpu_time"].iloc[0]})
        cpu = pd.DataFrame(rows).groupby("rule")["cpu_s"].agg(["count", "sum"]).sort_values("sum", ascending=False)
        n_frames = int(duration_s * 128)
    print(
        f"raw files of 1 subject, {len(trials)} walking trials of {duration_s:.0f} s ({n_frames} frames each) "
        f"+ static: {t1 - t0:.1f} s (not part of the target)"
    )
    print(
        f"processing (markers, model, IK in {cfg['opensim']['ik_chunks']} chunks/trial, events, load cell, strides, "
        f"transparency) with -j2: {t2 - t1:.1f} s wall (target 180 s)"
    )
    print("CPU time per rule (s):")
    print(cpu.to_string(float_format=lambda v: f"{v:.1f}"))


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 240.0, int(sys.argv[2]) if len(sys.argv) > 2 else None)
