"""reference.py: every published value the pipeline compares with is the number its source table in
``docs/reference_values.md`` gives (the tables parsed here)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from loper_analysis.reference import (
    ANKLE_SWING_IMPEDANCE,
    LITERATURE,
    STUDY_DEVICE,
    STUDY_INTERACTION_FORCE_N,
    STUDY_SUBJECTS,
    STUDY_SWING_IMPEDANCE,
    STUDY_TRANSPARENCY_RAD,
    STUDY_VALIDATION_NO_NOISE,
    STUDY_VALIDATION_NOISE,
)

DOC = Path(__file__).resolve().parents[1] / "docs" / "reference_values.md"


@pytest.fixture(scope="module")
def rows() -> list[list[str]]:
    """Every table row of the page, cells stripped, the minus sign as ASCII."""
    out = []
    for line in DOC.read_text(encoding="utf-8").splitlines():
        if line.startswith("|") and not line.startswith("|---"):
            cells = re.split(r"(?<!\\)\|", line.strip()[1:-1])  # a cell may hold an escaped \|
            out.append([c.strip().replace("−", "-") for c in cells])
    return out


def _numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?", text)]


def _row(rows, *first) -> list[str]:
    matches = [r for r in rows if r[: len(first)] == list(first)]
    assert len(matches) == 1, first
    return matches[0]


def test_transparency(rows):
    assert len(STUDY_TRANSPARENCY_RAD) == 6
    for (phase, joint), (rmsd, isv) in STUDY_TRANSPARENCY_RAD.items():
        assert _numbers(" ".join(_row(rows, phase, joint)[2:])) == [rmsd, isv]


def test_validation(rows):
    assert _numbers(_row(rows, "K (every joint)")[1]) == list(STUDY_VALIDATION_NO_NOISE["K"])
    assert _numbers(_row(rows, "D (every joint)")[1]) == list(STUDY_VALIDATION_NO_NOISE["D"])
    assert len(STUDY_VALIDATION_NOISE) == 6
    for parameter, values in STUDY_VALIDATION_NOISE.items():
        assert _numbers(" ".join(_row(rows, parameter)[1:])) == list(values)


def test_subjects_device_and_interaction_force(rows):
    assert _numbers(_row(rows, "age")[1]) == list(STUDY_SUBJECTS["age_yr"])
    assert _numbers(_row(rows, "height")[1]) == list(STUDY_SUBJECTS["height_m"])
    assert _numbers(_row(rows, "mass")[1]) == list(STUDY_SUBJECTS["mass_kg"])
    assert _numbers(_row(rows, "subjects")[1]) == [9, 6, 3] and STUDY_SUBJECTS["male_fraction"] == 6 / 9
    measured = [r for r in rows if len(r) == 3 and r[0].startswith(("FRF", "step", "steady"))]
    compared_as = {" ".join(r[0].split()[:2]): _numbers(r[2])[0] for r in measured}
    assert STUDY_DEVICE == {
        "bandwidth_hz": (compared_as["FRF bandwidth"], "Hz"),
        "rise_time_ms": (compared_as["step rise"], "ms"),
        "overshoot_pct": (compared_as["step overshoot,"], "%"),
        "steady_state_40n_n": (compared_as["steady state"], "N"),
    }
    rms = _numbers(_row(rows, "RMS interaction force, minimal-impedance walking")[1])
    peak = _numbers(_row(rows, "largest \\|interaction force\\|, minimal-impedance walking")[1])
    assert STUDY_INTERACTION_FORCE_N["stance"] == (rms[0], rms[1], peak[0], peak[1])
    assert STUDY_INTERACTION_FORCE_N["swing"] == (rms[2], rms[3], peak[2], peak[3])


def test_literature_and_the_studys_swing_result(rows):
    table = [r for r in rows if len(r) == 4 and r[1] in ("hip", "knee") and r[0] not in ("stance", "swing")]
    assert len(table) == len(LITERATURE) == 7
    for (source, joint, k, d), row in zip(LITERATURE, table):
        assert [source, joint] == row[:2]
        assert _numbers(row[2]) == list(k)
        assert _numbers(row[3]) == ([] if d == (None, None) else list(d))
    for joint in ("hip", "knee"):
        study = _row(rows, "the study: swing phase, across-subject mean over onsets", joint)
        assert _numbers(study[2]) == list(STUDY_SWING_IMPEDANCE[joint]["K"])
        assert _numbers(study[3]) == list(STUDY_SWING_IMPEDANCE[joint]["D"])
    assert ANKLE_SWING_IMPEDANCE == {"K": (0.0, 20.0), "D": (0.0, 0.75)}  # the page: K 0-20, D 0-0.75
