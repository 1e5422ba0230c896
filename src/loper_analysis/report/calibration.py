"""The calibration of the front page's truth verdicts: many synthetic fits at the study's design, kept as a table.

Three synthetic subjects give some 26 joint fits: too few to tell a chain whose intervals hold the truth in 95 %
of fits from one whose intervals hold it in 85 %. The verdicts therefore rest on a calibration run, many
synthetic subjects fitted at the same design (``benchmarks/truth_recovery_calibration.py``), whose counts the
repository keeps in a table (``report.calibration``, ``config/calibration/truth_recovery.tsv`` by default) and
the report reads:

* :data:`CALIBRATION_COLUMNS` - the table: one row per joint and parameter (K, D) with the fits, how many 95 %
  intervals held the truth, how many estimates lay within tolerance
  (:data:`~loper_analysis.impedance.identification.across_subjects.TRUTH_TOLERANCE`, the tolerance written in
  the row), the rows ``not_identifiable``; and, the same on every row, the run's date, seed, size, the way it
  was fitted, the code it ran and the fingerprint of its design;
* :func:`calibration_table` - that table from a calibration run's impedance rows;
* :func:`calibration_from_table` - the table read back and checked (:class:`Calibration`);
* :func:`design_values`, :func:`design_fingerprint` - what a run's design is: every field of the settings of
  :data:`CALIBRATED_STAGES` but the seed, and a short hash of them.

K in N·m/rad, D in N·m·s/rad.
"""

from __future__ import annotations

import dataclasses
import datetime
import hashlib
import json
import math
import numbers
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import pandas as pd

from loper_analysis.checks import require_columns, where
from loper_analysis.constants import JOINTS, UNIT_SUFFIX
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.across_subjects import TRUTH_TOLERANCE
from loper_analysis.report.headline import PARAMETER_KINDS, truth_recovery

__all__ = [
    "CALIBRATED_STAGES",
    "CALIBRATION_COLUMNS",
    "FINGERPRINT_LENGTH",
    "MODES",
    "Calibration",
    "CalibrationRow",
    "calibration_from_table",
    "calibration_table",
    "design_fingerprint",
    "design_values",
]

#: The stages whose settings decide a synthetic study's fits, and so make its design: the synthetic lab
#: (:class:`~loper_analysis.synthetic.lab_session.LabSessionSettings`: the trial design, the lab, the device, the
#: gait variability and adaptation, the pulses, the true impedance), the markers (their low-pass, which the
#: load-cell force shares) and the fit (:class:`~loper_analysis.stages.impedance.step.FitSettings`: the window, the
#: strides' outlier rule, the counterfactual, every identification setting). Every field of their settings but
#: :data:`LEFT_OUT`.
CALIBRATED_STAGES: tuple[str, ...] = ("synthetic", "markers", "impedance")
#: Fields left out of the design: the seed draws the subjects, it is not the design (the table names its own).
LEFT_OUT: tuple[str, ...] = ("seed",)
#: Hexadecimal digits of a design fingerprint.
FINGERPRINT_LENGTH = 16
#: How a calibration run fitted its subjects: from the simulated coordinates with the chain's IK error added
#: (``benchmarks/ci_coverage.py --mode coordinates``), or the whole workflow from the C3D files.
MODES: tuple[str, ...] = ("coordinates", "chain")
#: The tolerance's floor column of each parameter (N·m/rad for K, N·m·s/rad for D; blank on the other's rows).
_FLOOR = {p: f"tolerance_floor_{UNIT_SUFFIX[p]}" for p in PARAMETER_KINDS}
#: Columns of the calibration table, in order.
CALIBRATION_COLUMNS: tuple[str, ...] = (
    "joint",
    "parameter",
    "n_fits",
    "n_truth_in_ci95",
    "n_within_tolerance",
    "n_not_identifiable",
    "tolerance_pct",
    *_FLOOR.values(),
    "calibration_date",
    "seed",
    "n_subjects",
    "n_subject_onset_fits",
    "mode",
    "code_version",
    "design_fingerprint",
)
#: Columns that hold the same value on every row: the run's.
_RUN_COLUMNS = CALIBRATION_COLUMNS[CALIBRATION_COLUMNS.index("calibration_date") :]
_COUNTS = ("n_fits", "n_truth_in_ci95", "n_within_tolerance", "n_not_identifiable")


# ------------------------------------------------------------------------------------------------- the design


def _plain(value: Any) -> Any:
    """A settings value as JSON: numbers as floats (``45`` and ``45.0`` are one value), sequences as lists."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, numbers.Real):
        return float(value)
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return str(value)  # a path


def _flatten(value: Any, name: str, out: dict[str, Any]) -> None:
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            if f.name not in LEFT_OUT:
                _flatten(getattr(value, f.name), f"{name}.{f.name}", out)
    elif isinstance(value, Mapping):
        for key, item in value.items():
            _flatten(item, f"{name}.{key}", out)
    else:
        out[name] = _plain(value)


def design_values(settings: Mapping[str, Any]) -> dict[str, Any]:
    """The design of a run: every field of each stage's settings, nested types and mappings spelled out.

    Parameters
    ----------
    settings : Mapping[str, Any]
        Stage name -> its settings (those of :data:`CALIBRATED_STAGES`, as
        :func:`loper_analysis.stages.settings.stage_settings` builds them).

    Returns
    -------
    dict
        Dotted name (``synthetic.lab.marker_noise_sd_m``, ``impedance.identification.n_starts``) -> value (numbers
        as floats, sequences as lists), sorted by name; the fields of :data:`LEFT_OUT` left out.
    """
    out: dict[str, Any] = {}
    for stage, value in settings.items():
        _flatten(value, stage, out)
    return dict(sorted(out.items()))


def design_fingerprint(settings: Mapping[str, Any]) -> str:
    """The first :data:`FINGERPRINT_LENGTH` hexadecimal digits of the SHA-256 of :func:`design_values` as JSON.

    Two runs share a fingerprint when every setting of their design is the same; the seed does not count.
    """
    text = json.dumps(design_values(settings), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:FINGERPRINT_LENGTH]


# -------------------------------------------------------------------------------------------- the table


@dataclass(frozen=True)
class CalibrationRow:
    """One joint's parameter in the calibration run: ``n_fits`` fitted rows (``ok`` or ``not_identifiable``),
    ``n_truth_in_ci95`` of their 95 % intervals holding the truth, ``n_within_tolerance`` estimates within
    tolerance, ``n_not_identifiable`` rows ``not_identifiable``."""

    joint: str
    parameter: str
    n_fits: int
    n_truth_in_ci95: int
    n_within_tolerance: int
    n_not_identifiable: int


@dataclass(frozen=True)
class Calibration:
    """A calibration run as its table holds it.

    ``date`` (ISO, ``2026-12-01``), ``seed``, ``n_subjects``, ``n_subject_onset_fits`` (subjects × onsets),
    ``mode`` (:data:`MODES`), ``code_version`` (the package's version and commit), ``design_fingerprint``
    (:func:`design_fingerprint`), ``tolerance`` (parameter -> (relative, absolute), as counted) and ``rows``
    (:class:`CalibrationRow`, per joint K then D).
    """

    date: str
    seed: int
    n_subjects: int
    n_subject_onset_fits: int
    mode: str
    code_version: str
    design_fingerprint: str
    tolerance: Mapping[str, tuple[float, float]]
    rows: tuple[CalibrationRow, ...]

    def total(self, column: str, parameters: tuple[str, ...] = PARAMETER_KINDS) -> int:
        """A count column summed over the joints and ``parameters``."""
        return sum(getattr(r, column) for r in self.rows if r.parameter in parameters)

    def row(self, joint: str, parameter: str) -> CalibrationRow | None:
        """The row of a joint's parameter (None: the calibration has none)."""
        return next((r for r in self.rows if (r.joint, r.parameter) == (joint, parameter)), None)


def calibration_table(
    fits: pd.DataFrame,
    *,
    date: str,
    seed: int,
    mode: str,
    code_version: str,
    fingerprint: str,
    source: str = "",
) -> pd.DataFrame:
    """The calibration table (:data:`CALIBRATION_COLUMNS`) of a calibration run.

    Parameters
    ----------
    fits : pandas.DataFrame
        The run's impedance rows (:data:`loper_analysis.impedance.identification.impedance.IMPEDANCE_COLUMNS`),
        every subject with a known truth.
    date : str
        The day of the run (ISO, ``2026-12-01``).
    seed : int
        Its seed.
    mode : str
        How it fitted (:data:`MODES`).
    code_version : str
        The package's version and commit it ran.
    fingerprint : str
        The fingerprint of its design (:func:`design_fingerprint`).
    source : str
        Where the rows came from, for error messages.

    Returns
    -------
    pandas.DataFrame
        One row per joint (:data:`~loper_analysis.constants.JOINTS` order) and parameter (K, D), counted as the
        front page's truth recovery counts (:func:`loper_analysis.report.headline.truth_recovery`).
    """
    truth = truth_recovery(fits, source)
    known = fits[pd.to_numeric(fits["K_true_nm_per_rad"], errors="coerce").notna()]
    run = {
        "calibration_date": date,
        "seed": int(seed),
        "n_subjects": int(known["subject"].nunique()),
        "n_subject_onset_fits": int(known.groupby(["subject", "onset_ms"]).ngroups),
        "mode": mode,
        "code_version": code_version,
        "design_fingerprint": fingerprint,
    }
    rows = []
    for r in truth.to_dict("records"):
        n_ni = int(((known["joint"] == r["joint"]) & (known["status"] == "not_identifiable")).sum())
        for p in PARAMETER_KINDS:
            relative, floor = TRUTH_TOLERANCE[p]
            rows.append(
                {
                    "joint": r["joint"],
                    "parameter": p,
                    "n_fits": r["n_fits"],
                    "n_truth_in_ci95": r[f"{p}_n_truth_in_ci95"],
                    "n_within_tolerance": r[f"{p}_n_within_tolerance"],
                    "n_not_identifiable": n_ni,
                    "tolerance_pct": relative * 100.0,
                    **{column: (floor if q == p else math.nan) for q, column in _FLOOR.items()},
                    **run,
                }
            )
    table = pd.DataFrame(rows, columns=list(CALIBRATION_COLUMNS))
    calibration_from_table(table, source)  # what is written reads back
    return table


# ------------------------------------------------------------------------------------------------ reading


def _at(source: str, column: str, i: int, row: Mapping) -> str:
    return f"{where(source)}column {column!r}, row {i + 1} ({row.get('joint')} {row.get('parameter')})"


def _whole(value: Any, column: str, i: int, row: Mapping, source: str, minimum: int) -> int:
    """A whole number >= ``minimum`` from a cell (text or number)."""
    text = str(value).strip()
    ok = re.fullmatch(r"[+]?\d+(\.0*)?", text) is not None
    if not ok or int(float(text)) < minimum:
        raise LoperInputError(f"{_at(source, column, i, row)}: {value!r} is not a whole number >= {minimum}")
    return int(float(text))


def _real(value: Any, column: str, i: int, row: Mapping, source: str) -> float:
    try:
        number = float(str(value).strip())
    except ValueError:
        number = math.nan
    if not math.isfinite(number):
        raise LoperInputError(f"{_at(source, column, i, row)}: {value!r} is not a finite number")
    return number


def _blank(value: Any) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value)) or str(value).strip() in ("", "nan")


def _check_row(row: Mapping, i: int, source: str) -> CalibrationRow:
    """One row's joint, parameter, counts and tolerance, each checked."""
    for column, allowed in (("joint", JOINTS), ("parameter", PARAMETER_KINDS)):
        if str(row[column]) not in allowed:
            raise LoperInputError(f"{_at(source, column, i, row)}: {row[column]!r} is none of {', '.join(allowed)}")
    p = str(row["parameter"])
    counts = {c: _whole(row[c], c, i, row, source, 1 if c == "n_fits" else 0) for c in _COUNTS}
    for c in _COUNTS[1:]:
        if counts[c] > counts["n_fits"]:
            raise LoperInputError(f"{_at(source, c, i, row)}: {row[c]!r} exceeds n_fits = {counts['n_fits']}")
    relative, floor = TRUTH_TOLERANCE[p]
    told = {"tolerance_pct": relative * 100.0, _FLOOR[p]: floor}
    for column, value in told.items():
        got = _real(row[column], column, i, row, source)
        if not math.isclose(got, value, rel_tol=1e-9):
            raise LoperInputError(
                f"{_at(source, column, i, row)}: {row[column]!r}: counted with another tolerance than the page's "
                f"({value:g}): regenerate the table (python benchmarks/truth_recovery_calibration.py)"
            )
    other = next(c for q, c in _FLOOR.items() if q != p)
    if not _blank(row[other]):
        raise LoperInputError(f"{_at(source, other, i, row)}: {row[other]!r} on a {p} row: leave it blank")
    return CalibrationRow(str(row["joint"]), p, *(counts[c] for c in _COUNTS))


def _run_value(table: pd.DataFrame, column: str, source: str) -> Any:
    """The value a run column holds on every row."""
    values = table[column].tolist()
    for i, value in enumerate(values):
        if str(value).strip() != str(values[0]).strip():
            raise LoperInputError(
                f"{_at(source, column, i, table.iloc[i].to_dict())}: {value!r} differs from row 1's "
                f"{values[0]!r}: one calibration run per table"
            )
    return values[0]


def _run(table: pd.DataFrame, source: str) -> dict[str, Any]:
    """The run's columns, each checked."""
    first = table.iloc[0].to_dict()
    value = {c: _run_value(table, c, source) for c in _RUN_COLUMNS}
    date = str(value["calibration_date"]).strip()
    try:
        datetime.date.fromisoformat(date)
    except ValueError:
        raise LoperInputError(
            f"{_at(source, 'calibration_date', 0, first)}: {value['calibration_date']!r} is no date (YYYY-MM-DD)"
        ) from None
    fingerprint = str(value["design_fingerprint"]).strip()
    if not re.fullmatch(f"[0-9a-f]{{{FINGERPRINT_LENGTH}}}", fingerprint):
        raise LoperInputError(
            f"{_at(source, 'design_fingerprint', 0, first)}: {value['design_fingerprint']!r} is not "
            f"{FINGERPRINT_LENGTH} hexadecimal digits"
        )
    mode = str(value["mode"]).strip()
    if mode not in MODES:
        raise LoperInputError(f"{_at(source, 'mode', 0, first)}: {value['mode']!r} is none of {', '.join(MODES)}")
    return {
        "date": date,
        "seed": _whole(value["seed"], "seed", 0, first, source, 0),
        "n_subjects": _whole(value["n_subjects"], "n_subjects", 0, first, source, 1),
        "n_subject_onset_fits": _whole(value["n_subject_onset_fits"], "n_subject_onset_fits", 0, first, source, 1),
        "mode": mode,
        "code_version": str(value["code_version"]).strip(),
        "design_fingerprint": fingerprint,
    }


def calibration_from_table(table: pd.DataFrame, source: str = "") -> Calibration:
    """The calibration run of a calibration table (:data:`CALIBRATION_COLUMNS`), every cell checked.

    Parameters
    ----------
    table : pandas.DataFrame
        The table as read (cells as text or numbers).
    source : str
        Its file, for error messages.

    Returns
    -------
    Calibration
        The run and its rows.

    Raises
    ------
    LoperInputError
        Naming the file, the column, the row and the value: no rows or a column missing; a joint or parameter
        unknown, or given twice; a count that is not a whole number, or above ``n_fits``; a tolerance other than
        the page's (:data:`~loper_analysis.impedance.identification.across_subjects.TRUTH_TOLERANCE`); a run column
        that differs between rows; a date that is no ISO date, a fingerprint that is not
        :data:`FINGERPRINT_LENGTH` hexadecimal digits, a mode not of :data:`MODES`.
    """
    require_columns(table, CALIBRATION_COLUMNS, source, "calibration table")
    if not len(table):
        raise LoperInputError(f"{where(source)}calibration table: no rows")
    rows = [_check_row(r, i, source) for i, r in enumerate(table.to_dict("records"))]
    seen: dict[tuple[str, str], int] = {}
    for i, r in enumerate(rows):
        if (r.joint, r.parameter) in seen:
            raise LoperInputError(
                f"{where(source)}column 'joint', row {i + 1} ({r.joint} {r.parameter}): given twice (first in row "
                f"{seen[r.joint, r.parameter] + 1})"
            )
        seen[r.joint, r.parameter] = i
    return Calibration(
        **_run(table, source),
        tolerance={p: TRUTH_TOLERANCE[p] for p in PARAMETER_KINDS},
        rows=tuple(rows),
    )
