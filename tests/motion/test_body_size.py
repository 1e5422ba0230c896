"""motion/body_size.py: the subject's mass and height for scaling, from the sheet, the static trial's plates or
the file's PROCESSING values, on a standing subject of known mass built here."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from loper_analysis.constants import GRAVITY_M_PER_S2
from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import C3DRecording, read_c3d
from loper_analysis.io.force_platforms import ForcePlatform, read_force_platforms
from loper_analysis.motion.body_size import (
    HIP_HEIGHT_FRACTION,
    MASS_LIMIT_KG,
    body_height_m,
    body_mass_kg,
    model_height_m,
    require_stature,
    standing_mass_kg,
    standing_plates,
)
from loper_analysis.motion.model import build_lower_body_model

QCMAS_STATIC = Path(__file__).resolve().parents[1] / "data/c3d-parser/QCMAS/static.c3d"
#: Resting levels (N) of the same lab's plates 1, 2 and 4, measured in its walk (tests/data/c3d-parser/QCMAS/
#: walk-nodevice.c3d, loper_analysis.gait.grf.resting_level): its static trial stores these plates as exact zeros.
QCMAS_WALK_REST_N = {1: -10.27, 2: -13.74, 4: -14.84}
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


def test_a_lab_static_counts_the_loaded_plate_only():
    # QCMAS's static: both feet on plate 3 (708.4 N on average over the 3.23 s), plates 1, 2 and 4 unloaded
    rec = read_c3d(QCMAS_STATIC)
    plates = read_force_platforms(QCMAS_STATIC)
    window = (0.0, float(rec.time_s[-1]))
    mass, source = body_mass_kg(None, rec, plates, window)
    assert mass == pytest.approx(708.44 / GRAVITY_M_PER_S2, abs=0.01)  # 72.22 kg
    assert abs(mass - rec.processing["Bodymass"]) < 2.1  # the lab's 70.23 kg: within 3 %
    assert source == "force plate 3 of static.c3d (1, 2, 4 unloaded)"
    # the same plates unzeroed, at the resting levels the lab's walk shows: the unloaded plates add nothing
    # (summed in, they took 3.96 kg off: 68.26 kg)
    offset = [
        dataclasses.replace(p, force_n=p.force_n + [0.0, 0.0, QCMAS_WALK_REST_N.get(p.number, 0.0)]) for p in plates
    ]
    assert body_mass_kg(None, rec, offset, window) == (mass, source)


def test_each_plates_resting_level_comes_off_where_the_trial_shows_it():
    t = np.arange(2000) / 1000.0
    weight = 80.0 * 9.80665
    stepped_on = np.where(t < 0.4, -40.0, 0.6 * weight - 40.0)  # unzeroed at -40 N, loaded from 0.4 s
    throughout = np.full(t.size, 0.4 * weight)  # loaded from before the trial: no resting level to measure
    forces = np.column_stack([stepped_on, throughout, np.full(t.size, -71.0), np.full(t.size, 13.0)])
    rest, carrying = standing_plates(t, forces, (1.0, 2.0))
    np.testing.assert_allclose(rest, [-40.0, 0.0, -71.0, 13.0])
    assert carrying.tolist() == [True, True, False, False]
    assert standing_mass_kg(t, forces, (1.0, 2.0), 9.80665) == pytest.approx(80.0, rel=1e-12)
    # 20 N above the resting level: loaded only beyond it
    _, carrying = standing_plates(t, np.column_stack([np.where(t < 0.4, -40.0, -19.0), np.full(t.size, -15.0)]), (1, 2))
    assert carrying.tolist() == [True, False]
