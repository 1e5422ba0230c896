"""motion/body_size.py: the subject's mass and height for scaling, from the sheet, the static trial's plates or
the file's PROCESSING values, on a standing subject of known mass built here."""

from __future__ import annotations

import re

import numpy as np
import pytest

from loper_analysis.constants import GRAVITY_M_PER_S2
from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import C3DRecording
from loper_analysis.io.force_platforms import ForcePlatform
from loper_analysis.motion.body_size import (
    HIP_HEIGHT_FRACTION,
    MASS_LIMIT_KG,
    body_height_m,
    body_mass_kg,
    model_height_m,
    require_stature,
    standing_mass_kg,
)
from loper_analysis.motion.model import build_lower_body_model

MASS_KG = 70.0
RATE_HZ, PLATE_HZ = 100.0, 1000.0
LABELS = ["LASI", "RASI", "LHEE", "LTOE", "RHEE", "RTOE"]


def _plate(number: int, x0: float, force_n: float) -> ForcePlatform:
    """A 0.5 x 0.5 m plate at x0 .. x0 + 0.5, y -0.25 .. 0.25 in a Z-up lab, carrying ``force_n`` up for 2 s."""
    t = np.arange(int(2 * PLATE_HZ)) / PLATE_HZ
    force = np.zeros((t.size, 3))
    force[:, 2] = force_n
    corners = np.array([(x0 + 0.5, -0.25, 0), (x0, -0.25, 0), (x0, 0.25, 0), (x0 + 0.5, 0.25, 0)], dtype=float)
    return ForcePlatform(
        number, 2, (1, 2, 3, 4, 5, 6), PLATE_HZ, t, force, np.zeros_like(force), corners, corners.mean(0)
    )


def _standing(left_foot_x: float = 0.25, processing: dict | None = None) -> C3DRecording:
    """2 s of a subject standing with the right foot on plate 2 (x 0.5 .. 1.0) and the left foot at ``left_foot_x``."""
    pose = np.array(
        [
            (left_foot_x, 0.1, 0.95),
            (0.75, -0.1, 0.95),
            (left_foot_x - 0.1, 0.1, 0.05),
            (left_foot_x + 0.1, 0.1, 0.03),
            (0.65, -0.1, 0.05),
            (0.85, -0.1, 0.03),
        ]
    )
    return C3DRecording(
        "lab/static.c3d", LABELS, np.broadcast_to(pose, (200, 6, 3)).copy(), RATE_HZ, processing=processing or {}
    )


def test_both_feet_on_loaded_plates_weigh_the_subject():
    half = 0.5 * MASS_KG * GRAVITY_M_PER_S2
    plates = [_plate(1, 0.0, half), _plate(2, 0.5, half)]
    mass, source = body_mass_kg(None, _standing(), plates, (0.5, 1.5))
    assert mass == pytest.approx(MASS_KG, rel=1e-12) and source == "force plates 1, 2 of static.c3d"
    mass, _ = body_mass_kg(None, _standing(), plates, (0.5, 1.5), gravity_m_per_s2=9.80665)
    assert mass == pytest.approx(MASS_KG * GRAVITY_M_PER_S2 / 9.80665, rel=1e-12)


def test_a_foot_beside_the_plates_falls_back_on_the_files_bodymass():
    plates = [_plate(1, 0.0, 0.0), _plate(2, 0.5, 0.5 * MASS_KG * GRAVITY_M_PER_S2)]  # left foot on the floor
    beside = _standing(left_foot_x=-0.6, processing={"Bodymass": 71.5})
    mass, source = body_mass_kg(None, beside, plates, (0.5, 1.5))
    assert mass == 71.5
    assert source == (
        "PROCESSING:Bodymass of static.c3d (the plates do not carry the whole subject: foot markers LHEE, LTOE "
        "(lower than 0.15 m) stand beside the loaded plates (2) in the scaling window)"
    )
    with pytest.raises(LoperInputError, match=r"^lab/static\.c3d: no body mass: the plates do not carry the whole"):
        body_mass_kg(None, _standing(left_foot_x=-0.6), plates, (0.5, 1.5))


def test_the_sheets_mass_wins_and_no_plates_take_the_files():
    assert body_mass_kg(64.9) == (64.9, "given")
    assert body_mass_kg(MASS_LIMIT_KG) == (300.0, "given")
    mass, source = body_mass_kg(None, _standing(processing={"Bodymass": 58.0}))
    assert mass == 58.0
    assert (
        source == "PROCESSING:Bodymass of static.c3d (the static trial has no force platforms (FORCE_PLATFORM:USED 0))"
    )
    for bad in (0.0, -70.0, 300.5):
        with pytest.raises(LoperInputError, match=re.escape(f"mass_kg must lie in 0 .. 300 kg, got {bad}")):
            body_mass_kg(bad)
    with pytest.raises(LoperInputError, match=r"^no body mass: give mass_kg \(subject sheet\), or a static trial"):
        body_mass_kg(None)


def test_height_from_the_sheet_the_file_in_mm_or_the_model():
    assert body_height_m(1.73, {"Height": 1800.0}, 1.69, "static.c3d") == (1.73, "given")
    assert body_height_m(None, {"Height": 1800.0}, 1.69, "static.c3d") == (1.8, "PROCESSING:Height of static.c3d")
    for stored in ({}, {"Height": 1.8}, {"Height": 3000.0}):  # none, in m (not Nexus's mm), beyond a person's
        assert body_height_m(None, stored, 1.69, "static.c3d") == (1.69, "estimated from the scaled model")


def test_a_model_a_quarter_off_the_height_is_another_subjects():
    require_stature((1.60, "given"), 2.0, "s.osim")  # +25 %: at the limit, accepted
    with pytest.raises(
        LoperInputError,
        match=re.escape(
            "s.osim: the model scaled to this static trial stands 2.10 m tall where the subject's height is 1.60 m "
            "(given; +31 %, more than 25 %)"
        ),
    ):
        require_stature((1.60, "given"), 2.10, "s.osim")
    with pytest.raises(LoperInputError, match=re.escape("(PROCESSING:Height of a.c3d; -26 %, more than 25 %)")):
        require_stature((1.80, "PROCESSING:Height of a.c3d"), 1.33, "s.osim")
    require_stature((2.10, "estimated from the scaled model"), 1.0, "s.osim")  # nothing to hold it to


def test_standing_mass_is_the_weight_over_gravity():
    t = np.arange(1000) / 1000.0
    rng = np.random.default_rng(1)
    plates = np.column_stack([0.52 * 80.0 * 9.80665 + rng.normal(0, 2, t.size), 0.48 * 80.0 * 9.80665 + 0 * t])
    plates[:100] = 0.0  # stepping on: outside the window
    assert standing_mass_kg(t, plates, (0.2, 0.999), 9.80665) == pytest.approx(80.0, abs=0.02)  # 2 N noise
    with pytest.raises(
        LoperInputError, match=r"s\.c3d: the force plates carry 0\.0 N on average .*outside 20 \.\. 300 kg"
    ):
        standing_mass_kg(t, plates, (0.0, 0.05), source="s.c3d")
    with pytest.raises(LoperInputError, match=r"varies by 71 % .*does not stand still"):
        standing_mass_kg(t, plates, (0.0, 0.3))  # a third of the window on no plate: SD over mean 0.71


def test_height_of_the_generated_model_comes_back():
    # Winter's proportions: the hip joint centre stands at 0.530 of the height above the metatarsal markers
    assert HIP_HEIGHT_FRACTION == pytest.approx(0.530, abs=1e-12)
    for height in (1.55, 1.73, 1.95):
        assert model_height_m(build_lower_body_model(height, 70.0), "thigh_r") == pytest.approx(height, rel=1e-9)
