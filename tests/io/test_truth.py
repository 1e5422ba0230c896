"""A synthetic subject's truth file (io.truth): document and file round trips of a drawn truth, the document's
keys against a hand-written one, and an unreadable file named."""

from __future__ import annotations

import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import write_yaml
from loper_analysis.io.truth import TRUTH_HEADER, read_truth, truth_document, truth_from_document, write_truth
from loper_analysis.synthetic.subjects import subject_anthropometry, true_impedance

K = {50: [55, 3, 8], 175: [38, 0.5, 8]}
D = {50: [3.5, 0.1, 0.3], 175: [2.2, 0.04, 0.3]}


@pytest.fixture(scope="module")
def anthropometry():
    return subject_anthropometry({"subject": "S07"}, 2024)


@pytest.fixture(scope="module")
def truth():
    return true_impedance("S07", 2024, K, D, 0.15)


def test_truth_document_round_trip(anthropometry, truth):
    assert truth_from_document(truth_document(anthropometry, truth)) == truth


def test_truth_file_round_trip(tmp_path, anthropometry, truth):
    path = tmp_path / "truth.yaml"
    write_truth(path, anthropometry, truth)
    assert read_truth(path) == truth
    # the header line, then the document: the bytes the step wrote before the writer moved to io.truth
    write_yaml(tmp_path / "by_hand.yaml", truth_document(anthropometry, truth), TRUTH_HEADER)
    assert path.read_bytes() == (tmp_path / "by_hand.yaml").read_bytes()
    assert path.read_text().startswith(f"# {TRUTH_HEADER}\n")


def test_document_keys_carry_onset_and_units():
    """One onset and joint written by hand: ``onset_050_ms``, stiffness and damping under their unit keys."""
    anthropometry = {"subject": "S01", "sex": "female", "age_yr": 31, "height_m": 1.68, "mass_kg": 59.5, "extra": 1}
    doc = truth_document(anthropometry, {50: {"knee": {"K": 3.25, "D": 0.125}}})
    assert doc == {
        "subject": "S01",
        "sex": "female",
        "age_yr": 31,
        "height_m": 1.68,
        "mass_kg": 59.5,
        "impedance": {"onset_050_ms": {"knee": {"stiffness_nm_per_rad": 3.25, "damping_nms_per_rad": 0.125}}},
    }
    assert truth_from_document(doc) == {50: {"knee": {"K": 3.25, "D": 0.125}}}


def test_unreadable_truth_files_are_named(tmp_path):
    """A document without impedance, a joint without damping and a missing file each name the file."""
    with pytest.raises(LoperInputError, match=r"^S01/truth.yaml: not a readable truth file \(.*impedance"):
        truth_from_document({"subject": "S01"}, "S01/truth.yaml")
    doc = {"impedance": {"onset_050_ms": {"hip": {"stiffness_nm_per_rad": 50.0}}}}
    with pytest.raises(LoperInputError, match=r"^truth file: not a readable truth file \(.*damping_nms_per_rad"):
        truth_from_document(doc)
    path = write_yaml(tmp_path / "truth.yaml", doc, TRUTH_HEADER)
    with pytest.raises(LoperInputError, match=rf"^{path}: not a readable truth file"):
        read_truth(path)
    with pytest.raises(LoperInputError, match=rf"{tmp_path / 'none.yaml'}"):
        read_truth(tmp_path / "none.yaml")
