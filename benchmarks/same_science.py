"""Do two runs of the pipeline give the same science? Compares the results of two checkouts byte by byte.

Usage:
    python benchmarks/same_science.py BASE_RESULTS NEW_RESULTS
    python benchmarks/same_science.py --build REV [--jobs 2]

The first form compares two ``results/`` folders. The second builds both:
it checks out revision REV of this repository and the working tree (with
its uncommitted changes) into temporary folders, runs ``snakemake -j2`` in
each with that checkout's own library on ``PYTHONPATH``, and compares.

Every file of the base run (job logs and timings aside) must be in the new run,
at its new place where the layout moved it (:data:`MOVED`), with the same bytes;
files only the new run has are listed. Exit code 1 when a file differs or is
missing.

With ``--science PCT`` a change that moves numbers in their last digits (another IK
solver) passes when the science is the same: every stride count, outlier verdict
and status of the stride tables and the trial summary, every fit's status, stride
and null-pair counts, and the validation study's files identical, and each fitted
K and D within PCT % of the base run's (estimates at a bound of 0 within PCT % of
the joint's largest estimate). The largest differences are printed.
"""

from __future__ import annotations

import argparse
import filecmp
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pandas as pd

from loper_analysis.layout import RAW_DIR, RESULTS_DIR

#: Result files the layout moved: old path -> new path (relative to results/).
MOVED = {
    "tables/impedance.tsv": "impedance/impedance.tsv",
    "tables/impedance_summary.tsv": "impedance/summary.tsv",
    "tables/literature.tsv": "impedance/literature.tsv",
    "tables/tables.md": "report/tables.md",
    "figures/impedance.png": "impedance/impedance.png",
}
#: Folders of per-job logs and timings, which differ from run to run.
NOT_COMPARED = ("logs", "benchmarks")


def new_place(rel: str) -> str:
    """Where a file of an older run stands in this layout (``figures/S01/fit.png`` -> ``impedance/S01/fit.png``)."""
    if rel in MOVED:
        return MOVED[rel]
    if rel.startswith("figures/"):
        return "impedance/" + rel.removeprefix("figures/")
    if rel.startswith("responses/"):  # an onset's mean response beside its fit
        return "impedance/" + rel.removeprefix("responses/")
    if rel.startswith("loadcell/"):  # the load cell's forces beside the events of the trial they were read with
        return "events/" + rel.removeprefix("loadcell/")
    return rel


def _files(results: Path) -> list[str]:
    return sorted(
        p.relative_to(results).as_posix()
        for p in results.rglob("*")
        if p.is_file() and p.relative_to(results).parts[0] not in NOT_COMPARED
    )


def compare(base: Path, new: Path) -> int:
    """Print the comparison of two results folders; 1 when a base file is missing or differs in the new."""
    problems, same = [], 0
    for rel in _files(base):
        other = new / new_place(rel)
        if not other.is_file():
            problems.append(f"{rel}: missing in the new results (looked for {new_place(rel)})")
        elif not filecmp.cmp(base / rel, other, shallow=False):
            problems.append(f"{rel}: bytes differ")
        else:
            same += 1
    mapped = {new_place(rel) for rel in _files(base)}
    extra = [rel for rel in _files(new) if rel not in mapped]
    print(f"byte-identical: {same} of {same + len(problems)} files of the base run")
    for rel in extra:
        print(f"  only in the new run: {rel}")
    for p in problems:
        print("FAIL", p)
    print("same science" if not problems else f"{len(problems)} problem(s)")
    return 1 if problems else 0


#: Columns that must not move at all: counts, verdicts and statuses (strides summary, fits).
EXACT_COLUMNS = {
    "strides/summary.tsv": ("subject", "trial", "n_strides", "n_perturbed", "n_removed", "n_kept", "status"),
    "impedance/impedance.tsv": ("subject", "onset_ms", "joint", "status", "n_strides", "n_null_pairs"),
}
#: Fitted values held to the tolerance, and their columns.
FITTED = ("K_nm_per_rad", "D_nms_per_rad")


def science(base: Path, new: Path, tolerance_pct: float) -> int:
    """Print whether two results folders hold the same science within ``tolerance_pct`` (%); 1 when not."""
    problems = []
    for rel, columns in EXACT_COLUMNS.items():
        a, b = (pd.read_csv(d / rel, sep="\t", keep_default_na=False) for d in (base, new))
        if not a[list(columns)].equals(b[list(columns)]):
            problems.append(f"{rel}: {', '.join(columns)} differ")
    for folder in ("validation",):
        for f in sorted((base / folder).glob("*.tsv")):
            if not filecmp.cmp(f, new / folder / f.name, shallow=False):
                problems.append(f"{folder}/{f.name}: bytes differ")
    for f in sorted((base / "strides").rglob("*.strides.tsv")):
        a, b = (pd.read_csv(p, sep="\t", keep_default_na=False) for p in (f, new / f.relative_to(base)))
        verdicts = ["stride", "side", "perturbed", "removed", "reason"]
        if len(a) != len(b) or not a[verdicts].equals(b[verdicts]):
            problems.append(f"{f.relative_to(base)}: strides or their verdicts differ")
    a, b = (pd.read_csv(d / "impedance/impedance.tsv", sep="\t") for d in (base, new))
    worst = 0.0
    for column in FITTED:
        scale = a.groupby("joint")[column].transform(lambda v: v.abs().max())
        denominator = a[column].abs().where(a[column].abs() > tolerance_pct / 100 * scale, scale)
        pct = 100 * (b[column] - a[column]).abs() / denominator
        k = int(pct.idxmax())
        worst = max(worst, float(pct.max()))
        print(
            f"{column}: largest difference {pct.max():.3f} % ({a.subject[k]} {a.onset_ms[k]} ms {a.joint[k]}: "
            f"{a[column][k]:.6g} -> {b[column][k]:.6g}); median {pct.median():.4f} %"
        )
    if worst > tolerance_pct:
        problems.append(f"a fitted K or D moved by {worst:.3f} % > {tolerance_pct:g} %")
    for p in problems:
        print("FAIL", p)
    print(f"same science within {tolerance_pct:g} %" if not problems else f"{len(problems)} problem(s)")
    return 1 if problems else 0


def _run(checkout: Path, jobs: int) -> Path:
    env = dict(os.environ, PYTHONPATH=str(checkout / "src"))
    subprocess.run([sys.executable, "-m", "compileall", "-q", "src"], cwd=checkout, env=env, check=True)
    subprocess.run(["snakemake", f"-j{jobs}", "--quiet", "rules"], cwd=checkout, env=env, check=True)
    return checkout / RESULTS_DIR


def build(rev: str, jobs: int) -> int:
    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory(prefix="same-science-") as tmp:
        base, new = Path(tmp) / "base", Path(tmp) / "new"
        subprocess.run(["git", "worktree", "add", "--detach", str(base), rev], cwd=root, check=True)
        try:
            files = subprocess.run(
                ["git", "ls-files", "-co", "--exclude-standard"], cwd=root, check=True, capture_output=True, text=True
            ).stdout.split()
            for f in files:
                if (root / f).is_file() and not f.startswith((f"{RESULTS_DIR}/", f"{RAW_DIR.split('/')[0]}/")):
                    (new / f).parent.mkdir(parents=True, exist_ok=True)
                    (new / f).write_bytes((root / f).read_bytes())
            return compare(_run(base, jobs), _run(new, jobs))
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(base)], cwd=root, check=False)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", nargs="*", help="BASE_RESULTS NEW_RESULTS")
    parser.add_argument("--build", metavar="REV", help="build REV and the working tree, then compare")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--science", type=float, metavar="PCT", help="compare the science within PCT %%")
    args = parser.parse_args()
    if args.build:
        return build(args.build, args.jobs)
    if len(args.results) != 2:
        parser.error("give BASE_RESULTS and NEW_RESULTS, or --build REV")
    base, new = Path(args.results[0]), Path(args.results[1])
    if args.science is not None:
        compare(base, new)
        return science(base, new, args.science)
    return compare(base, new)


if __name__ == "__main__":
    sys.exit(main())
