"""Do two runs of the pipeline give the same science? Compares the results of two checkouts byte by byte.

Usage:
    python benchmarks/same_science.py BASE_RESULTS NEW_RESULTS
    python benchmarks/same_science.py --build REV [--jobs 2]

The first form compares two ``results/`` folders. The second builds both:
it checks out revision REV of this repository and the working tree (with
its uncommitted changes) into temporary folders, runs ``snakemake -j2`` in
each with that checkout's own library on ``PYTHONPATH``, and compares.

Checks (exit code 1 when one fails):
* byte-identical: ``validation/errors.tsv``, ``device/summary.tsv`` and
  every stride table (``strides/**``);
* ``tables/impedance.tsv`` identical cell by cell after renaming the old
  columns to the new ones (:data:`RENAMED`) and leaving out the columns
  only the new table has (the optimiser's start counts);
* every other TSV under ``results/`` is listed as identical or not (for
  information).
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

#: Columns of the impedance table renamed to carry their units: old -> new.
RENAMED = {
    "K": "K_nm_per_rad",
    "D": "D_nms_per_rad",
    "K_ci95_low": "K_ci95_low_nm_per_rad",
    "K_ci95_high": "K_ci95_high_nm_per_rad",
    "D_ci95_low": "D_ci95_low_nms_per_rad",
    "D_ci95_high": "D_ci95_high_nms_per_rad",
    "K_true": "K_true_nm_per_rad",
    "D_true": "D_true_nms_per_rad",
    "K_error": "K_error_nm_per_rad",
    "D_error": "D_error_nms_per_rad",
    "cost_rad2": "sum_sq_error_rad2",
}
#: Files that must be byte-identical (relative to results/; globs).
IDENTICAL = ("validation/errors.tsv", "device/summary.tsv", "strides/**/*.tsv", "strides/*.tsv")


def _same_bytes(base: Path, new: Path) -> list[str]:
    problems, seen = [], set()
    for pattern in IDENTICAL:
        for path in sorted(base.glob(pattern)):
            rel = path.relative_to(base)
            if rel in seen:
                continue
            seen.add(rel)
            other = new / rel
            if not other.is_file():
                problems.append(f"{rel}: missing in the new results")
            elif not filecmp.cmp(path, other, shallow=False):
                problems.append(f"{rel}: bytes differ")
    print(f"byte-identical: {len(seen) - len(problems)} of {len(seen)} files")
    return problems


def _same_impedance(base: Path, new: Path) -> list[str]:
    rel = Path("tables/impedance.tsv")
    old = pd.read_csv(base / rel, sep="\t", dtype=str, keep_default_na=False).rename(columns=RENAMED)
    now = pd.read_csv(new / rel, sep="\t", dtype=str, keep_default_na=False)
    extra = [c for c in now.columns if c not in old.columns]
    missing = [c for c in old.columns if c not in now.columns]
    if missing:
        return [f"{rel}: column(s) {missing} of the old table are gone"]
    now = now[list(old.columns)]
    if now.shape != old.shape:
        return [f"{rel}: {now.shape[0]} rows against {old.shape[0]}"]
    diff = now != old
    print(f"{rel}: {int(diff.to_numpy().sum())} differing cells of {diff.size} after renaming; new columns {extra}")
    rows, cols = diff.to_numpy().nonzero()
    return [
        f"{rel}: row {i}, column {old.columns[j]}: {old.iat[i, j]!r} -> {now.iat[i, j]!r}"
        for i, j in zip(rows[:20], cols[:20])
    ]


def _others(base: Path, new: Path) -> None:
    for path in sorted(base.rglob("*.tsv")):
        rel = path.relative_to(base)
        if "benchmarks" in rel.parts:
            continue
        other = new / rel
        state = "missing" if not other.is_file() else ("same" if filecmp.cmp(path, other, shallow=False) else "differs")
        print(f"  {state:8s} {rel}")


def compare(base: Path, new: Path) -> int:
    problems = _same_bytes(base, new) + _same_impedance(base, new)
    print("all TSV tables under results/:")
    _others(base, new)
    for p in problems:
        print("FAIL", p)
    print("same science" if not problems else f"{len(problems)} problem(s)")
    return 1 if problems else 0


def _run(checkout: Path, jobs: int) -> Path:
    env = dict(os.environ, PYTHONPATH=str(checkout / "src"))
    subprocess.run([sys.executable, "-m", "compileall", "-q", "src"], cwd=checkout, env=env, check=True)
    subprocess.run(["snakemake", f"-j{jobs}", "--quiet", "rules"], cwd=checkout, env=env, check=True)
    return checkout / "results"


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
                if (root / f).is_file():
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
    args = parser.parse_args()
    if args.build:
        return build(args.build, args.jobs)
    if len(args.results) != 2:
        parser.error("give BASE_RESULTS and NEW_RESULTS, or --build REV")
    return compare(Path(args.results[0]), Path(args.results[1]))


if __name__ == "__main__":
    sys.exit(main())
