"""The calibration of the front page's truth verdicts: many synthetic fits at the study's design, kept as a table.

Usage: python benchmarks/truth_recovery_calibration.py [--subjects N] [--seed S] [--jobs J] [--configfile FILE ...]
                                                       [--out FILE] [--keep FILE] [--rows FILE]
                                                       [--code-version TEXT]

The default run's three synthetic subjects give about 26 joint fits: too few to tell intervals that hold the
truth in 95 % of fits from intervals that hold it in 85 %. This script fits N synthetic subjects (default 34:
102 subject x onset fits, about 300 joint fits) at the design of ``config/config.yaml`` (with ``--configfile``
files layered over it) at the coordinate level, with the machinery of ``benchmarks/ci_coverage.py --mode
coordinates`` (:func:`ci_coverage.run_coordinates`: the workflow's own simulated walking, the chain's IK error
added to the angles, the load-cell step, ``fit_onset``; subjects C001, C002, ..., none of the study's), and
writes the table the front page's verdicts rest on (:data:`loper_analysis.report.calibration.CALIBRATION_COLUMNS`)
to the config's ``report.calibration`` (``config/calibration/truth_recovery.tsv``): per joint and parameter the
fits, the 95 % intervals holding the truth, the estimates within the study's tolerance, the rows
``not_identifiable``, counted as the front page counts them
(:func:`loper_analysis.report.headline.truth_recovery`); and the run's date, seed, size, the code it ran and the
fingerprint of its design (:func:`loper_analysis.report.calibration.design_fingerprint` of the config's synthetic
lab, markers and fit settings, as the workflow's report settings compute it). Regenerate it after any change
to the fit's code or to a setting of the design: the front page of a run whose fingerprint differs says so and
judges that run's own counts only.

``--seed``: default 2024, the default study's. ``--keep FILE`` also writes the fitted rows (the impedance
table's columns); ``--rows FILE`` counts rows kept earlier instead of fitting (their seed is ``--seed``'s).
``--code-version`` names the code when the project is no git checkout (default: the package's version and the
checkout's commit, ``-dirty`` with uncommitted changes in ``src/``). About 5-10 min for 34 subjects with
``--jobs 2`` on two free cores.
"""

from __future__ import annotations

import argparse
import datetime
import importlib.metadata
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))

from ci_coverage import binomial_interval, run_coordinates, study_lab_config  # noqa: E402

from loper_analysis.io.atomic import write_tsv  # noqa: E402
from loper_analysis.io.readers import read_tsv  # noqa: E402
from loper_analysis.report.calibration import calibration_from_table, calibration_table  # noqa: E402
from loper_analysis.report.headline import COVERAGE_TARGET, PARAMETER_KINDS, WITHIN_TOLERANCE_TARGET  # noqa: E402
from loper_analysis.report.markdown import markdown_table  # noqa: E402
from loper_analysis.stages.settings import stage_settings  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def code_version() -> str:
    """``loper-analysis 0.1.0, commit c9bf764`` (``-dirty`` with uncommitted changes in ``src/``); the version
    alone outside a git checkout."""
    version = f"loper-analysis {importlib.metadata.version('loper-analysis')}"
    git = ["git", "-C", str(ROOT)]
    head = subprocess.run([*git, "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=False)
    if head.returncode:
        return version
    changed = [*git, "status", "--porcelain", "--untracked-files=no", "--", "src"]
    status = subprocess.run(changed, capture_output=True, text=True, check=False)
    return f"{version}, commit {head.stdout.strip()}{'-dirty' if status.stdout.strip() else ''}"


def summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per joint and parameter, and pooled: the shares of the calibration with their binomial 95 % intervals."""
    rows = []
    pooled = [
        *(
            (f"{r['joint']} {r['parameter']}", r["n_fits"], r["n_truth_in_ci95"], r["n_within_tolerance"])
            for r in table.to_dict("records")
        ),
        *(
            (f"all {p}", *(int(table.loc[table["parameter"] == p, c].sum()) for c in ("n_fits", "n_truth_in_ci95",
                                                                                       "n_within_tolerance")))
            for p in PARAMETER_KINDS
        ),
    ]  # fmt: skip
    for name, n, inside, within in pooled:
        ci, tol = binomial_interval(int(inside), int(n)), binomial_interval(int(within), int(n))
        rows.append(
            {
                "fits": name,
                "n": int(n),
                "truth in 95 % CI": f"{inside} ({100 * inside / n:.1f} %; {100 * ci[0]:.1f}-{100 * ci[1]:.1f})",
                "within tolerance": f"{within} ({100 * within / n:.1f} %; {100 * tol[0]:.1f}-{100 * tol[1]:.1f})",
            }
        )
    return pd.DataFrame(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--subjects", type=int, default=34, help="synthetic subjects (3 fits each; default 34)")
    ap.add_argument("--seed", type=int, default=2024, help="default 2024, the default study's")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--configfile", nargs="+", default=[], help="config files layered over config/config.yaml")
    ap.add_argument("--out", type=Path, help="the table (default: the config's report.calibration)")
    ap.add_argument("--keep", type=Path, help="also write the fitted rows here (TSV)")
    ap.add_argument("--rows", type=Path, help="count these rows (kept with --keep) instead of fitting")
    ap.add_argument("--code-version", help="the code that ran (default: the package's version and git commit)")
    args = ap.parse_args()
    seed = args.seed
    config = study_lab_config(args.configfile, seed)
    report = stage_settings(config, "report")
    out = args.out or (None if report.calibration is None else ROOT / report.calibration)
    if out is None:
        raise SystemExit("the config names no calibration table (report.calibration: null): give --out FILE")
    t0 = time.perf_counter()
    if args.rows is not None:
        rows = read_tsv(args.rows, "impedance rows")
    else:
        names = [f"C{k:03d}" for k in range(1, args.subjects + 1)]
        rows = run_coordinates(names, config, 1.0, args.jobs)
        if args.keep is not None:
            write_tsv(rows, args.keep)
    table = calibration_table(
        rows,
        date=datetime.date.today().isoformat(),
        seed=seed,
        mode="coordinates",
        code_version=args.code_version or code_version(),
        fingerprint=report.design_fingerprint,
        source=str(args.rows or "the fitted rows"),
    )
    out.parent.mkdir(parents=True, exist_ok=True)
    write_tsv(table, out)
    calibration = calibration_from_table(read_tsv(out, "calibration table", dtype=str, keep_default_na=False), str(out))
    statuses = rows["status"].value_counts().to_dict()
    print(
        f"{out}: {calibration.n_subjects} synthetic subjects, {calibration.n_subject_onset_fits} subject x onset fits, "
        f"seed {seed}, design fingerprint {calibration.design_fingerprint}, {time.perf_counter() - t0:.0f} s with "
        f"{args.jobs} job(s); statuses {statuses}"
    )
    print(markdown_table(summary(table)))
    low, high = COVERAGE_TARGET
    print(
        f"targets: intervals {100 * low:.0f}-{100 * high:.0f} % (pooled K and D), within tolerance >= "
        f"{100 * WITHIN_TOLERANCE_TARGET:.0f} % (K and D each)"
    )


if __name__ == "__main__":
    main()
