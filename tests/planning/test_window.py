"""The planner's settings from the config, the checks naming their keys, and the planned experiment's window."""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from loper_analysis.device.controller import DeviceParameters
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.responses.response_window import ResponseWindow
from loper_analysis.planning.inputs import pulse_force_n
from loper_analysis.planning.window import PlanSettings, null_pair_arrays, planned_impedance, planning_window
from loper_analysis.stages.settings import stage_settings
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry
from loper_analysis.swing_leg.rods import ShankRod

ROOT = Path(__file__).resolve().parents[2]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


def test_from_config_reads_every_key_the_planner_follows():
    config = copy.deepcopy(CONFIG)
    config["planning"].update(pulse_force_n=35.0, pulse_duration_s=0.08)
    config["impedance"].update(
        window_before_s=0.03,
        window_after_s=0.3,
        initial_state_span_s=0.12,
        initial_state_degree=2,
        n_substeps=3,
        null_pair_components=2,
        min_null_pairs=25,
        interval_scatter="null_pairs",
        stiffness_bounds_nm_per_rad=[1.0, 150.0],
        damping_bounds_nms_per_rad=[0.5, 8.0],
    )
    settings = stage_settings(config, "planning").plan
    assert settings == PlanSettings(
        pulse_force_n=35.0,
        pulse_duration_s=0.08,
        window=ResponseWindow(before_s=0.03, after_s=0.3, initial_state_span_s=0.12),
        initial_state_degree=2,
        n_substeps=3,
        null_pair_components=2,
        min_null_pairs=25,
        interval_scatter="null_pairs",
        stiffness_bounds_nm_per_rad=(1.0, 150.0),
        damping_bounds_nms_per_rad=(0.5, 8.0),
    )
    # the bounds in the order of PARAMETERS: K_hip, D_hip, K_knee, D_knee, K_ankle, D_ankle
    np.testing.assert_array_equal(settings.lower, [1.0, 0.5, 1.0, 0.5, 1.0, 0.5])
    np.testing.assert_array_equal(settings.upper, [150.0, 8.0, 150.0, 8.0, 150.0, 8.0])


def test_the_shipped_config_plans_a_40_n_pulse_of_100_ms():
    settings = stage_settings(CONFIG, "planning").plan
    assert (settings.pulse_force_n, settings.pulse_duration_s) == (40.0, 0.1)
    assert settings == PlanSettings()


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"pulse_force_n": math.nan}, r"^pulse_force_n must be"),
        ({"force_rate_hz": 0.0}, r"^force_rate_hz must be > 0 Hz, got 0$"),
        ({"interval_scatter": "bootstrap"}, r"^impedance\.interval_scatter must be one of .*, got 'bootstrap'$"),
        (
            {"pulse_duration_s": 0.3},
            r"^pulse_duration_s = 0\.3 s is longer than the fit window after the onset "
            r"\(impedance\.window_after_s = 0\.25 s\)",
        ),
        ({"pulse_duration_s": -0.1}, r"^pulse_duration_s must be > 0 s, got -0\.1 s$"),
    ],
)
def test_bad_settings_are_refused_naming_the_key(kwargs, message):
    with pytest.raises(LoperInputError, match=message):
        PlanSettings(**kwargs)


def test_a_planned_value_outside_the_bounds_is_named_with_its_unit():
    settings = PlanSettings(stiffness_bounds_nm_per_rad=(0.0, 100.0), damping_bounds_nms_per_rad=(0.0, 5.0))
    inside = [50.0, 1.0, 3.0, 0.1, 8.0, 0.3]
    np.testing.assert_array_equal(planned_impedance(inside, settings, "P01"), inside)
    with pytest.raises(
        LoperInputError, match=r"^P01: planned D_knee = 6 N·m·s/rad lies outside the identification bounds 0 \.\. 5$"
    ):
        planned_impedance([50.0, 1.0, 3.0, 6.0, 8.0, 0.3], settings, "P01")
    with pytest.raises(LoperInputError, match=r"^P01: the planned impedance must be 6 finite values"):
        planned_impedance([50.0, 1.0, 3.0], settings, "P01")


THIGH_RAD = 0.3
REFERENCE = np.array([0.1, THIGH_RAD, -0.4, 0.05])


def _null_pairs(n_pairs: int = 6) -> dict:
    """Null pairs at 128 Hz from -0.1 to 0.297 s about the onset: each pair's unperturbed stride a constant
    posture, offset from REFERENCE by +-0.02 rad so that their mean is REFERENCE."""
    t = np.arange(-13, 39) / 128.0
    offsets = 0.02 * np.where(np.arange(n_pairs) % 2 == 0, 1.0, -1.0)
    q = np.broadcast_to(REFERENCE, (n_pairs, t.size, 4)) + offsets[:, None, None]
    return {
        "time_s": t,
        "q_perturbed": q,
        "q_unperturbed": q,
        "pelvis_angle_perturbed_rad": np.zeros((n_pairs, t.size)),
        "pelvis_angle_unperturbed_rad": np.zeros((n_pairs, t.size)),
    }


def test_null_pair_arrays_count_the_pairs_and_name_a_missing_array():
    t, arrays, n = null_pair_arrays(_null_pairs(6), "pilot")
    assert n == 6 and t.size == 52 and arrays["q_unperturbed"].shape == (6, 52, 4)
    missing = _null_pairs()
    del missing["pelvis_angle_unperturbed_rad"]
    with pytest.raises(LoperInputError, match=r"^pilot: null pairs lack \['pelvis_angle_unperturbed_rad'\]$"):
        null_pair_arrays(missing, "pilot")


def test_planning_window_starts_from_the_mean_swing_and_pushes_along_the_thigh_normal():
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    window = planning_window(_null_pairs(), params)
    np.testing.assert_allclose(window.time_s[[0, -1]], [-0.0234375, 0.25])  # samples within -0.025 .. 0.25 s
    np.testing.assert_allclose(window.reference_q, np.broadcast_to(REFERENCE, window.reference_q.shape), atol=1e-12)
    np.testing.assert_array_equal(window.measured, 0.0)
    force = window.force_perturbed_n  # (n_steps, 4, 2): world x/y at the RK4 stages
    normal = np.array([math.cos(THIGH_RAD), -math.sin(THIGH_RAD)])  # forward, perpendicular to the thigh
    np.testing.assert_allclose(force[..., 0] * normal[1] - force[..., 1] * normal[0], 0.0, atol=1e-9)
    along = force @ normal
    rate = DeviceParameters.sample_rate_hz
    t_force = np.arange(math.ceil(-0.1015625 * rate), math.floor(0.296875 * rate) + 1) / rate
    peak = pulse_force_n(t_force, 40.0, 0.1).max()
    assert along.max() == pytest.approx(peak, rel=0.05)  # forward, the delivered pulse's peak
    assert peak > 40.0  # the device overshoots the desired 40 N


def test_planning_window_refuses_a_pilot_without_null_pairs():
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    with pytest.raises(LoperInputError, match=r"^pilot: no null pairs: the pilot needs unperturbed strides"):
        planning_window(_null_pairs(0), params)


def test_a_planned_second_rod_pushes_the_shank_along_its_normal_beside_the_thigh_rod():
    """With ``shank_pulse_force_n`` the window holds a second rod's pulse at 85 % of the shank (the same device's
    response, along the shank's forward normal); the thigh rod's pulse is the one planned without it."""
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    one = planning_window(_null_pairs(), params)
    two = planning_window(_null_pairs(), params, PlanSettings(shank_pulse_force_n=30.0))
    assert one.shank_force_perturbed_n is None and one.params.shank_attachment_m is None
    assert two.params.shank_attachment_m == pytest.approx(0.85 * params.length_m[1], rel=1e-12)
    np.testing.assert_array_equal(two.force_perturbed_n, one.force_perturbed_n)
    shank = two.shank_force_perturbed_n
    q_shank = REFERENCE[2]
    normal = np.array([math.cos(q_shank), -math.sin(q_shank)])
    np.testing.assert_allclose(shank[..., 0] * normal[1] - shank[..., 1] * normal[0], 0.0, atol=1e-9)
    rate = DeviceParameters.sample_rate_hz
    t_force = np.arange(math.ceil(-0.1015625 * rate), math.floor(0.296875 * rate) + 1) / rate
    assert (shank @ normal).max() == pytest.approx(pulse_force_n(t_force, 30.0, 0.1).max(), rel=0.05)


@pytest.mark.parametrize("fraction", [0.0, 1.5, float("nan")])
def test_a_shank_point_off_the_shank_is_refused_naming_its_key(fraction):
    with pytest.raises(LoperInputError, match=r"device\.shank_rod\.attachment_fraction"):
        ShankRod(attachment_fraction=fraction)


@pytest.mark.parametrize("angle_deg", [90.0, -95.0, float("inf")])
def test_a_shank_push_along_the_shank_or_backwards_is_refused_naming_its_key(angle_deg):
    with pytest.raises(LoperInputError, match=r"device\.shank_rod\.direction_deg"):
        ShankRod(direction_rad=math.radians(angle_deg))


def test_a_tilted_shank_rod_pushes_along_the_normal_turned_toward_the_ankle():
    """At 30 degrees toward the ankle the planned shank force is the normal's turned by 30 degrees: its component
    along the shank's distal axis is sin 30 of its size (analytic)."""
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    tilted = planning_window(
        _null_pairs(), params, PlanSettings(shank_pulse_force_n=30.0, shank_rod=ShankRod(direction_rad=math.pi / 6))
    )
    q_shank = REFERENCE[2]
    distal = np.array([-math.sin(q_shank), -math.cos(q_shank)])
    shank = tilted.shank_force_perturbed_n
    size = np.linalg.norm(shank, axis=-1)
    big = size > 0.5 * size.max()
    np.testing.assert_allclose((shank @ distal)[big] / size[big], 0.5, atol=1e-6)
