"""The study's inputs checked before any job runs (study_checks): each refusal names the sheet or config file,
the subject, the column or key and the value; raw folders warn of files that match no trial."""

from __future__ import annotations

from pathlib import Path

import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.study_checks import check_subjects, raw_file_warnings
from tests.study_files import CONFIG, study_on, touch

ROOT = Path(__file__).resolve().parents[1]


def _source(*keys: str) -> str:
    return "config/mine.yaml"


def test_the_checks_name_the_sheet_subject_and_file(tmp_path):
    study = study_on(tmp_path, {"R01": {"source": "recorded", "height_m": 1.7}}, device={"subject": "R01"})
    with pytest.raises(
        LoperInputError, match=r"subjects.tsv: recorded subject 'R01' has no static trial .*raw/R01/static.c3d"
    ):
        check_subjects(study, "subjects.tsv", lambda *keys: "config/config.yaml")
    touch(tmp_path / "raw" / "R01" / "static.c3d")
    touch(tmp_path / "raw" / "R01" / "walk-fast.c3d")
    check_subjects(study, "subjects.tsv", lambda *keys: "config/config.yaml")
    (warning,) = raw_file_warnings(study)
    assert warning.startswith(f"warning: {tmp_path / 'raw' / 'R01'}: walk-fast.c3d: no trial of the design")


def test_a_scaled_model_must_exist_and_a_generated_model_needs_the_height(tmp_path):
    """model_osim not on disk: named with its column; no height_m for the generated model: the key's file."""
    missing = tmp_path / "R01.osim"
    study = study_on(tmp_path, {"R01": {"source": "recorded", "model_osim": str(missing)}}, device={"subject": None})
    with pytest.raises(
        LoperInputError, match=rf"^subjects.tsv: subject 'R01', column model_osim: file '{missing}' not found$"
    ):
        check_subjects(study, "subjects.tsv", _source)
    touch(missing)
    check_subjects(study, "subjects.tsv", _source)
    touch(tmp_path / "raw" / "R02" / "static.c3d")
    study = study_on(tmp_path, {"R02": {"source": "recorded"}}, device={"subject": None})
    with pytest.raises(
        LoperInputError,
        match=r"^subjects.tsv: recorded subject 'R02' needs height_m: the generated model \(config/mine.yaml: "
        r"model.generic_model null\)",
    ):
        check_subjects(study, "subjects.tsv", _source)
    lab_model = {**CONFIG["model"], "generic_model": "gait2392.osim"}
    check_subjects(study_on(tmp_path, {"R02": {"source": "recorded"}}, device={"subject": None}, model=lab_model),
                   "subjects.tsv", _source)  # fmt: skip


def test_synthetic_subjects_need_a_truth_for_every_onset_inside_the_bounds(tmp_path):
    """An onset without a true K: the key and the onset; a true K above the bounds: subject, onset, joint."""
    synth = CONFIG["synthetic"]
    rows = {"S01": {"source": "synthetic"}}
    check_subjects(study_on(tmp_path, rows, device={"subject": None}), "subjects.tsv", _source)
    stiffness = {k: v for k, v in synth["stiffness_nm_per_rad"].items() if int(k) != 300}
    damping = {k: v for k, v in synth["damping_nms_per_rad"].items() if int(k) != 300}
    fewer = {**synth, "stiffness_nm_per_rad": stiffness, "damping_nms_per_rad": damping}
    with pytest.raises(
        LoperInputError,
        match=r"^config/mine.yaml: key 'synthetic.stiffness_nm_per_rad': no truth for onset\(s\) \[300\] ms of "
        r"study.perturbation_onsets_ms$",
    ):
        check_subjects(study_on(tmp_path, rows, device={"subject": None}, synthetic=fewer), "subjects.tsv", _source)
    ident = {**CONFIG["impedance"], "stiffness_bounds_nm_per_rad": [0.0, 0.5]}
    with pytest.raises(
        LoperInputError, match=r"^subject S01, onset \d+ ms, hip: true .* lies outside the identification"
    ):
        check_subjects(study_on(tmp_path, rows, device={"subject": None}, impedance=ident), "subjects.tsv", _source)


def test_the_device_subject_must_be_in_the_sheet(tmp_path):
    study = study_on(tmp_path, {"S01": {"source": "synthetic"}}, device={"subject": "S09"})
    with pytest.raises(
        LoperInputError, match=r"^config/mine.yaml: key 'device.subject': subject 'S09' is not in subjects.tsv$"
    ):
        check_subjects(study, "subjects.tsv", _source)


def test_raw_folders_refuse_a_miscased_file_and_list_strangers(tmp_path):
    """A trial's file in upper case stops the run naming the name it must have; unknown raw files (not
    notes) give one warning per folder listing them, a synthetic subject's folder is not looked at."""
    raw = tmp_path / "raw" / "R01"
    for name in ("static.c3d", "walk-fast.c3d", "walk-slow.mat", "notes.txt"):
        touch(raw / name)
    touch(tmp_path / "raw" / "S01" / "stray.c3d")
    study = study_on(tmp_path, {"R01": {"source": "recorded"}, "S01": {"source": "synthetic"}})
    (warning,) = raw_file_warnings(study)
    assert warning.startswith(f"warning: {raw}: walk-fast.c3d, walk-slow.mat: no trial of the design has this name")
    assert "study.perturbation_onsets_ms [50, 175, 300] and study.perturbation_repeats 2)" in warning
    touch(raw / "pert175-2.C3D")
    with pytest.raises(
        LoperInputError,
        match=rf"^{raw / 'pert175-2.C3D'}: the raw file of trial 'pert175-2' is named 'pert175-2.C3D'; .* rename it "
        r"'pert175-2.c3d'",
    ):
        raw_file_warnings(study)
