"""Processing one subject's 8 walking trials end to end (read -> IK -> strides) with `snakemake -j2`.

Usage: python benchmarks/processing_subject.py [walking_duration_s [ik_chunks]] [--model gait2392]
       (defaults: 240 s, the study's trials; the config's ik.ik_chunks; the generated model)

Copies the workflow into a temporary directory with one subject, generates its
raw files first (not timed: C3D + robot logs, as a lab records them), then
times the processing rules up to the stride tables of all 8 walking trials and
the transparency analysis. Prints wall time and the per-rule CPU time from
Snakemake's benchmark files.

With ``--model gait2392`` the subject is a recorded one in the study's own model:
its session is written as a lab exports it (QTM-style C3D files with the lab's
labels, gaps and treadmill plates, MATLAB robot logs; the tests' lab export),
with gait2392's 39 scale markers, and the workflow runs with
``examples/gait2392/config.yaml`` (gait2392 scaled with the lab's ScaleTool
setup). The design and trial lengths are the same as the generated model's.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
import yaml

from loper_analysis.layout import fill
from loper_analysis.stages import study_paths
from loper_analysis.stages.settings import stage_settings

ROOT = Path(__file__).resolve().parents[1]
PATHS = study_paths()


def _lab_session(work: Path, cfg: dict, trials: list[str]) -> tuple[str, list[str]]:
    """Write subject R01's session in gait2392 as a lab exports it; returns the subject and the extra
    ``--configfile`` arguments."""
    sys.path.insert(0, str(ROOT))
    from tests.lab_export_session import LabExportFiles, LabExportSettings, lab_export_session

    example = work / "examples" / "gait2392"
    out = work / fill(PATHS.raw.c3d, subject="R01", trial="x")
    files = LabExportFiles(
        out.parent,
        example / "gait2392_simbody.osim",
        example / "gait2392_Scale_MarkerSet.xml",
        example / "qtm_label_map.tsv",
    )
    mass_kg = 75.1646  # gait2392's own: the scaled model keeps its masses
    lab_export_session(files, "R01", trials, 1.80, mass_kg, LabExportSettings.from_config(cfg))
    (work / "config/subjects.tsv").write_text(f"subject\tsource\theight_m\tmass_kg\nR01\trecorded\t1.80\t{mass_kg}\n")
    (work / "config/bench.yaml").write_text(yaml.safe_dump({"device": {"subject": "R01"}}))
    return "R01", ["--configfile", "examples/gait2392/config.yaml", "config/bench.yaml"]


def main(duration_s: float = 240.0, ik_chunks: int | None = None, model: str = "generated") -> None:
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for item in ("Snakefile", "workflow", "config", "examples"):
            src = ROOT / item
            (shutil.copytree if src.is_dir() else shutil.copy)(src, work / item)
        cfg = yaml.safe_load((ROOT / "config/config.yaml").read_text())
        cfg["synthetic"]["walking_duration_s"] = duration_s
        if ik_chunks is not None:
            cfg["ik"]["ik_chunks"] = ik_chunks
        (work / "config/config.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False))
        (work / "config/subjects.tsv").write_text(
            "subject\tsource\tsex\tage_yr\theight_m\tmass_kg\nS01\tsynthetic\tmale\t26\t1.80\t72.0\n"
        )
        trials = stage_settings(cfg, "study").design.walking_trials()
        subject, extra = "S01", []
        t0 = time.perf_counter()
        if model == "gait2392":
            subject, extra = _lab_session(work, cfg, trials)
        raw = [fill(PATHS.raw.c3d, subject=subject, trial=t) for t in [cfg["study"]["static"], *trials]]

        def run(*targets: str) -> None:
            res = subprocess.run(
                [sys.executable, "-m", "snakemake", "--cores", "2", *targets, *extra, "--quiet", "all"],
                cwd=work,
                capture_output=True,
                text=True,
            )
            if res.returncode:
                sys.exit(res.stderr[-3000:] + res.stdout[-3000:])

        if model != "gait2392":  # a recorded subject's files are the lab's: no rule makes them
            run(*raw)
        t1 = time.perf_counter()
        targets = [fill(PATHS.strides.strides, subject=subject, trial=t) for t in trials] + [PATHS.transparency.rmsd]
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
    print(f"model: {model}")
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
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("walking_duration_s", nargs="?", type=float, default=240.0)
    parser.add_argument("ik_chunks", nargs="?", type=int)
    parser.add_argument("--model", choices=("generated", "gait2392"), default="generated")
    args = parser.parse_args()
    main(args.walking_duration_s, args.ik_chunks, args.model)
