"""The calibration table of the truth verdicts (loper_analysis.report.calibration): counted as the front page counts,
read back and refused when malformed (naming the file, the column and the value), and the design fingerprint."""

from __future__ import annotations

import copy
from pathlib import Path

import pandas as pd
import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.io.readers import read_tsv
from loper_analysis.report.calibration import (
    CALIBRATED_STAGES,
    CALIBRATION_COLUMNS,
    Calibration,
    CalibrationRow,
    calibration_from_table,
    calibration_table,
    design_fingerprint,
    design_values,
)
from loper_analysis.stages.settings import stage_settings
from tests.headline_tables import impedance_row
from tests.test_config_readers import _changed

ROOT = Path(__file__).resolve().parents[2]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
RUN = dict(date="2026-12-01", seed=2024, mode="coordinates", code_version="loper-analysis 0.1.0, commit abc1234")
FINGERPRINT = "0123456789abcdef"


def _fits() -> pd.DataFrame:
    """Two synthetic subjects, onsets 50 and 175 ms, with known counts (K in N·m/rad, D in N·m·s/rad):

    hip K: errors -2 (within 10 % of 52; CI holds the truth), 15 (outside; CI misses), 0 (within; CI holds),
    one fit failed; hip D: -0.1 (within 15 % of 3.6; CI holds), 1.0 (outside; CI holds), 0.5 (outside; CI misses);
    knee, both not identifiable: K -2 (at the 2 N·m/rad floor: within; holds), 4 (outside; holds); D -0.05 (at the
    0.05 floor: within; holds), 0.2 (outside; misses). A recorded subject has no truth and does not count.
    """
    nan = float("nan")
    return pd.DataFrame(
        [
            impedance_row("C001", 50, "hip", 50.0, 3.5, (40.0, 60.0), (3.0, 4.0), 52.0, 3.6),
            impedance_row("C002", 50, "hip", 70.0, 5.2, (60.0, 80.0), (3.0, 6.0), 55.0, 4.2),
            impedance_row("C001", 175, "hip", 40.0, 2.5, (30.0, 50.0), (2.1, 2.9), 40.0, 2.0),
            impedance_row("C002", 175, "hip", nan, nan, (nan, nan), (nan, nan), 40.0, 2.0, status="failed"),
            impedance_row("C001", 50, "knee", 1.0, 0.05, (0.0, 4.0), (0.0, 0.3), 3.0, 0.1, status="not_identifiable"),
            impedance_row("C002", 50, "knee", 5.0, 0.3, (0.0, 9.0), (0.2, 0.4), 1.0, 0.1, status="not_identifiable"),
            impedance_row("R1", 50, "hip", 45.0, 3.3, (30.0, 60.0), (2.0, 4.6)),
        ]
    )


def test_the_table_counts_as_the_front_page_and_reads_back():
    table = calibration_table(_fits(), fingerprint=FINGERPRINT, **RUN)
    assert list(table.columns) == list(CALIBRATION_COLUMNS)
    counts = ["joint", "parameter", "n_fits", "n_truth_in_ci95", "n_within_tolerance", "n_not_identifiable"]
    assert table[counts].to_dict("records") == [
        {"joint": "hip", "parameter": "K", "n_fits": 3, "n_truth_in_ci95": 2, "n_within_tolerance": 2,
         "n_not_identifiable": 0},
        {"joint": "hip", "parameter": "D", "n_fits": 3, "n_truth_in_ci95": 2, "n_within_tolerance": 1,
         "n_not_identifiable": 0},
        {"joint": "knee", "parameter": "K", "n_fits": 2, "n_truth_in_ci95": 2, "n_within_tolerance": 1,
         "n_not_identifiable": 2},
        {"joint": "knee", "parameter": "D", "n_fits": 2, "n_truth_in_ci95": 1, "n_within_tolerance": 1,
         "n_not_identifiable": 2},
    ]  # fmt: skip
    assert table["tolerance_pct"].tolist() == [10.0, 15.0, 10.0, 15.0]
    assert table["tolerance_floor_nm_per_rad"].tolist()[::2] == [2.0, 2.0]
    assert table["tolerance_floor_nms_per_rad"].tolist()[1::2] == [0.05, 0.05]
    assert set(table["n_subjects"]) == {2} and set(table["n_subject_onset_fits"]) == {4}  # the recorded one left out
    calibration = calibration_from_table(table)
    assert calibration == Calibration(
        date="2026-12-01",
        seed=2024,
        n_subjects=2,
        n_subject_onset_fits=4,
        mode="coordinates",
        code_version="loper-analysis 0.1.0, commit abc1234",
        design_fingerprint=FINGERPRINT,
        tolerance={"K": (0.10, 2.0), "D": (0.15, 0.05)},
        rows=(
            CalibrationRow("hip", "K", 3, 2, 2, 0),
            CalibrationRow("hip", "D", 3, 2, 1, 0),
            CalibrationRow("knee", "K", 2, 2, 1, 2),
            CalibrationRow("knee", "D", 2, 1, 1, 2),
        ),
    )
    assert calibration.total("n_fits") == 10 and calibration.total("n_truth_in_ci95") == 7
    assert calibration.total("n_within_tolerance", ("K",)) == 3 and calibration.row("ankle", "K") is None


def _written(tmp_path: Path, **changes) -> Path:
    """The calibration table of :func:`_fits` as a file, with cells changed: ``column=(row, value)`` (row 0-based),
    ``drop=column``."""
    table = calibration_table(_fits(), fingerprint=FINGERPRINT, **RUN).astype(object)
    drop = changes.pop("drop", None)
    for column, (row, value) in changes.items():
        table.loc[row, column] = value
    if drop:
        table = table.drop(columns=drop)
    path = tmp_path / "truth_recovery.tsv"
    table.to_csv(path, sep="\t", index=False)
    return path


def _read(path: Path) -> Calibration:
    """Read as the report's file step reads it: every cell as text."""
    return calibration_from_table(read_tsv(path, "calibration table", dtype=str, keep_default_na=False), str(path))


def test_the_written_file_reads_back_the_same(tmp_path):
    assert _read(_written(tmp_path)) == calibration_from_table(
        calibration_table(_fits(), fingerprint=FINGERPRINT, **RUN)
    )


@pytest.mark.parametrize(
    "changes, message",
    [
        (
            {"n_truth_in_ci95": (1, "abc")},
            "column 'n_truth_in_ci95', row 2 (hip D): 'abc' is not a whole number >= 0",
        ),
        ({"n_fits": (0, "2.5")}, "column 'n_fits', row 1 (hip K): '2.5' is not a whole number >= 1"),
        ({"n_within_tolerance": (2, "-1")}, "column 'n_within_tolerance', row 3 (knee K): '-1' is not a whole number "
         ">= 0"),
        ({"n_truth_in_ci95": (3, "7")}, "column 'n_truth_in_ci95', row 4 (knee D): '7' exceeds n_fits = 2"),
        ({"joint": (2, "elbow")}, "column 'joint', row 3 (elbow K): 'elbow' is none of hip, knee, ankle"),
        ({"parameter": (1, "B")}, "column 'parameter', row 2 (hip B): 'B' is none of K, D"),
        ({"joint": (2, "hip")}, "column 'joint', row 3 (hip K): given twice (first in row 1)"),
        (
            {"tolerance_pct": (0, "20")},
            "column 'tolerance_pct', row 1 (hip K): '20': counted with another tolerance than the page's (10): "
            "regenerate the table (python benchmarks/truth_recovery_calibration.py)",
        ),
        (
            {"tolerance_floor_nm_per_rad": (1, "2")},
            "column 'tolerance_floor_nm_per_rad', row 2 (hip D): '2' on a D row: leave it blank",
        ),
        (
            {"calibration_date": (2, "2026-12-02")},
            "column 'calibration_date', row 3 (knee K): '2026-12-02' differs from row 1's '2026-12-01': one "
            "calibration run per table",
        ),
        ({"calibration_date": (slice(None), "1 Dec 2026")}, "column 'calibration_date', row 1 (hip K): '1 Dec 2026' is "
         "no date (YYYY-MM-DD)"),
        ({"design_fingerprint": (slice(None), "xyz")}, "column 'design_fingerprint', row 1 (hip K): 'xyz' is not 16 "
         "hexadecimal digits"),
        ({"mode": (slice(None), "guess")}, "column 'mode', row 1 (hip K): 'guess' is none of coordinates, chain"),
        ({"seed": (slice(None), "x")}, "column 'seed', row 1 (hip K): 'x' is not a whole number >= 0"),
        ({"drop": "n_within_tolerance"}, "calibration table: column(s) ['n_within_tolerance'] missing"),
    ],
)  # fmt: skip
def test_a_malformed_table_is_refused_naming_file_column_and_value(tmp_path, changes, message):
    path = _written(tmp_path, **changes)
    with pytest.raises(LoperInputError) as err:
        _read(path)
    assert str(err.value) == f"{path}: {message}"


def test_an_empty_table_is_refused(tmp_path):
    path = tmp_path / "truth_recovery.tsv"
    path.write_text("\t".join(CALIBRATION_COLUMNS) + "\n")
    with pytest.raises(LoperInputError, match=f"^{path}: calibration table: no rows$"):
        _read(path)


def _stages(config: dict) -> dict:
    return {name: stage_settings(config, name) for name in CALIBRATED_STAGES}


#: Text settings and empty mappings of the fingerprinted sections, changed to another valid value.
TEXT_CHANGES = {
    ("synthetic", "variability"): "gentle",
    ("markers", "walking_direction"): "fixed",
    ("markers", "label_map"): {"LASI": "LASI"},
    ("markers", "trial_label_maps"): {"walking": {"LASI": "LASI"}},
    ("markers", "trial_spans_s"): {"S01/pert050-1": [1.0, 20.0]},
    ("impedance", "noise_model"): "white",
    ("impedance", "counterfactual"): "matched_stride",
    ("impedance", "interval_scatter"): "perturbed_pairs",
}


def _leaves(node: dict, path: tuple = ()):
    for key, value in node.items():
        if isinstance(value, dict) and value and (*path, key) not in TEXT_CHANGES:
            yield from _leaves(value, (*path, key))
        else:
            yield (*path, key), value


#: Every key of the fingerprinted sections, with its shipped value.
FINGERPRINTED = [(path, value) for section in CALIBRATED_STAGES for path, value in _leaves(CONFIG[section], (section,))]


@pytest.mark.parametrize(
    "path, value", FINGERPRINTED, ids=lambda x: ".".join(map(str, x)) if isinstance(x, tuple) else ""
)
def test_every_setting_of_the_lab_the_markers_and_the_fit_changes_the_fingerprint(path, value):
    """The design is every field of the stages' settings: each key of their sections changes it."""
    config = copy.deepcopy(CONFIG)
    node = config
    for key in path[:-1]:
        node = node[key]
    changed = TEXT_CHANGES.get(path) or _changed(path, value)
    assert changed is not None and changed != value, path
    node[path[-1]] = changed
    assert design_fingerprint(_stages(config)) != design_fingerprint(_stages(CONFIG)), path


def test_the_fingerprint_leaves_the_seed_out_and_reads_45_as_45_0():
    base = design_fingerprint(_stages(CONFIG))
    assert len(base) == 16 and int(base, 16) >= 0
    config = copy.deepcopy(CONFIG)
    config["seed"] = 7
    config["synthetic"]["walking_duration_s"] = int(CONFIG["synthetic"]["walking_duration_s"])
    config["planning"]["strides"] = [5]  # the planner's: no setting of the fits
    assert design_fingerprint(_stages(config)) == base
    values = design_values(_stages(CONFIG))
    assert "synthetic.seed" not in values and "impedance.identification.seed" not in values
    assert values["synthetic.walking_duration_s"] == 45.0 and values["impedance.identification.n_starts"] == 10.0
    assert values["synthetic.design.perturbation_onsets_ms"] == [50.0, 175.0, 300.0]
    assert values["markers.cutoff_hz"] == 40.0 and values["synthetic.truth.stiffness_nm_per_rad.50"] == [55.0, 3.0, 8.0]
    # the report's settings carry the same fingerprint
    assert stage_settings(CONFIG, "report").design_fingerprint == base


def test_the_shipped_calibration_is_of_the_shipped_design():
    """``report.calibration`` of the shipped config names a calibration of at least 100 subject × onset fits whose
    design is the shipped config's: the default study's verdicts rest on it. After a change to a setting of the
    synthetic lab, the markers or the fit, regenerate it: python benchmarks/truth_recovery_calibration.py"""
    report = stage_settings(CONFIG, "report")
    calibration = _read(ROOT / report.calibration)
    assert calibration.design_fingerprint == report.design_fingerprint, (
        "the shipped calibration is of another design: regenerate it (python benchmarks/truth_recovery_calibration.py)"
    )
    assert calibration.n_subject_onset_fits >= 100 and calibration.mode == "coordinates"
    assert [(r.joint, r.parameter) for r in calibration.rows] == [
        (j, p) for j in ("hip", "knee", "ankle") for p in "KD"
    ]
