"""Study-level variability and the device adaptation of the synthetic subjects (synthetic/variability.py).

Known answers: the study's inter-stride variability and RMSD (reference.py), analytic envelopes and
adaptation formulas, the knot values of the smooth modulations, and linearity of the swing response
(the pulse response riding on top of the response to the minimal-impedance force).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.resampling import cut
from loper_analysis.reference import STUDY_TRANSPARENCY_RAD
from loper_analysis.synthetic.gait_curves import CURVE_JOINTS, NominalGait
from loper_analysis.synthetic.variability import (
    DeviceAdaptation,
    GaitVariability,
    device_adaptation,
    smooth_noise,
    swing_envelope,
)
from loper_analysis.synthetic.walking import walking_kinematics

ROOT = Path(__file__).resolve().parents[2]
SYNTH = yaml.safe_load((ROOT / "config/config.yaml").read_text())["synthetic"]
FS = 128.0
GAIT = NominalGait()


def _study_variability() -> GaitVariability:
    v = SYNTH["study_variability"]
    return GaitVariability(
        v["amplitude_cv"], v["offset_sd_rad"], v["timing_sd_stride"], v["swing_gain"], v["knots_per_stride"]
    )


def _phases(coords, events):
    """Left-leg stance and swing, each normalised to 101 points: two arrays (n_strides, 101, 3) in rad."""
    t = coords["time_s"].to_numpy()
    v = coords[[f"{j}_l" for j in CURVE_JOINTS]].to_numpy()
    ev = events[events["side"] == "left"]
    hs = ev.loc[ev["event"] == "heel_strike", "time_s"].to_numpy()
    to = ev.loc[ev["event"] == "toe_off", "time_s"].to_numpy()
    spans = [
        (a, to[(to > a) & (to < b)][0], b)
        for a, b in zip(hs[:-1], hs[1:])
        if ((to > a) & (to < b)).sum() == 1 and a >= t[0] and b <= t[-1]
    ]
    s = np.array(spans)
    return cut(t, v, s[:, 0], s[:, 1]), cut(t, v, s[:, 1], s[:, 2])


def test_smooth_noise_passes_through_its_drawn_knot_values():
    n, first, last, sd = 4, -3, 20, 0.02
    values = np.clip(sd * np.random.default_rng(9).standard_normal(last - first + 1), -3 * sd, 3 * sd)
    knots = np.arange(first, last + 1) / n
    got = smooth_noise(knots, first, last, n, sd, np.random.default_rng(9))
    np.testing.assert_allclose(got, values, atol=1e-15)
    # C1: the slope just left and right of a knot agrees (no velocity step)
    h = 1e-7
    x = knots[3:-3]
    left = (
        smooth_noise(x, first, last, n, sd, np.random.default_rng(9))
        - smooth_noise(x - h, first, last, n, sd, np.random.default_rng(9))
    ) / h
    right = (
        smooth_noise(x + h, first, last, n, sd, np.random.default_rng(9))
        - smooth_noise(x, first, last, n, sd, np.random.default_rng(9))
    ) / h
    np.testing.assert_allclose(left, right, atol=1e-5)
    with pytest.raises(LoperInputError, match="outside the knots"):
        smooth_noise([10.0], first, last, n, sd, np.random.default_rng(9))


def test_swing_envelope_is_one_at_mid_stance_and_the_gain_at_mid_swing():
    np.testing.assert_allclose(swing_envelope([0.325, 1.325, 0.825, -0.175], 2.5), [1.0, 1.0, 2.5, 2.5], atol=1e-12)
    np.testing.assert_allclose(swing_envelope(np.linspace(0, 3, 50), 1.0), 1.0)


def test_device_adaptation_is_drawn_per_subject_in_its_range():
    change, offset, gain = (0.05, 0.14, 0.08), (0.009, 0.022, 0.008), (2.4, 1.0, 3.2)
    a = device_adaptation(7, "S01", change, offset, gain)
    assert a == device_adaptation(7, "S01", change, offset, gain)
    assert a != device_adaptation(7, "S02", change, offset, gain) and a != device_adaptation(
        8, "S01", change, offset, gain
    )
    ratio_amp = np.abs(np.array(a.amplitude_factor) - 1.0) / change
    ratio_off = np.abs(a.offset_rad) / np.array(offset)
    assert np.all((ratio_amp >= 0.7) & (ratio_amp <= 1.3)) and np.all((ratio_off >= 0.7) & (ratio_off <= 1.3))
    assert a.swing_gain == gain
    signs = np.sign([device_adaptation(7, f"S{i:02d}", change, offset).offset_rad for i in range(40)])
    assert 0.3 < np.mean(signs > 0) < 0.7  # random sign
    with pytest.raises(LoperInputError, match="amplitude_factor"):
        DeviceAdaptation((1.3, 1.0, 1.0), (0.0, 0.0, 0.0), (3.0, 1.0, 1.0))


def test_adaptation_changes_the_curves_as_its_formula_says():
    """Without stride variability the device changes each curve by exactly g·(f - 1)·(c - m) + g·o."""
    adaptation = DeviceAdaptation((0.9, 1.1, 1.05), (0.01, -0.02, 0.005), (2.0, 1.0, 3.0))
    zero = GaitVariability()
    rng = lambda: np.random.default_rng(4)  # noqa: E731
    base, _ = walking_kinematics(12.0, FS, GAIT, rng(), timing_cv=0.0, variability=zero, start_phase=0.1)
    dev, _ = walking_kinematics(
        12.0, FS, GAIT, rng(), timing_cv=0.0, variability=zero, adaptation=adaptation, start_phase=0.1
    )
    phase = (0.1 + base["time_s"].to_numpy() / GAIT.stride_s) % 1.0  # the right leg's stride phase
    for j, joint in enumerate(CURVE_JOINTS):
        series = GAIT.joint_series(joint)
        g = swing_envelope(phase, adaptation.swing_gain[j])
        nominal = series(phase)
        np.testing.assert_allclose(base[f"{joint}_r"], nominal, atol=1e-9)
        expected = g * (adaptation.amplitude_factor[j] - 1.0) * (nominal - series.mean) + g * adaptation.offset_rad[j]
        np.testing.assert_allclose(dev[f"{joint}_r"] - base[f"{joint}_r"], expected, atol=1e-9)


def test_study_variability_reaches_the_studys_isv():
    """ISV_ave = 2·mean σ over 4 long trials within ±20 % of the study's, per joint and phase; smooth angles."""
    sigmas = []
    for seed in range(4):
        coords, events = walking_kinematics(
            150.0, FS, GAIT, np.random.default_rng(seed), timing_cv=SYNTH["timing_cv"], variability=_study_variability()
        )
        stance, swing = _phases(coords, events)
        sigmas.append([x.std(axis=0, ddof=1).mean(axis=0) for x in (stance, swing)])
        # continuity: no jumps and no velocity steps (second differences of a smooth curve at 128 Hz are small)
        angles = coords[[f"{j}_{s}" for j in CURVE_JOINTS for s in "lr"]].to_numpy()
        assert np.abs(np.diff(angles, 2, axis=0)).max() < 0.01
    isv = 2.0 * np.mean(sigmas, axis=0)  # (2 phases, 3 joints)
    for p, phase in enumerate(("stance", "swing")):
        for j, joint in enumerate(JOINTS):
            study = STUDY_TRANSPARENCY_RAD[(phase, joint)][1]
            assert abs(isv[p, j] / study - 1.0) <= 0.2, (phase, joint, isv[p, j], study)


def test_walking_with_the_device_differs_as_in_the_study():
    """Mean over 5 subjects of the RMSD with vs without the device (adaptation + minimal-impedance force on the
    swing leg, true kinematics): in the study's 0.017-0.071 rad, below ISV_ave and within a factor 1.5 of the
    study's value per joint and phase."""
    from loper_analysis.device.controller import DeviceParameters
    from loper_analysis.motion.model import build_lower_body_model, segment_parameters_from_model
    from loper_analysis.synthetic.trials import LabSettings, simulate_walking_trial

    a = SYNTH["device_adaptation"]
    params = segment_parameters_from_model(build_lower_body_model(1.73, 65.0))
    impedance = (50.0, 3.3, 2.0, 0.09, 8.0, 0.3)
    rmsd, sigma = [], []
    for i in range(5):
        adaptation = device_adaptation(3, f"S{i:02d}", a["amplitude_change"], a["offset_rad"], a["swing_gain"])
        trials = []
        for k, device in enumerate((None, DeviceParameters())):
            walk = simulate_walking_trial(
                45.0,
                LabSettings(),
                [i, k],
                1.73,
                params,
                timing_cv=SYNTH["timing_cv"],
                amplitude_cv=0.05,
                device=device,
                variability=_study_variability(),
                adaptation=adaptation,
                minimal_impedance=impedance,
            )
            trials.append(_phases(walk.mocap_coordinates(FS), walk.mocap_events()))
        rmsd.append([np.sqrt(np.mean((trials[1][p].mean(0) - trials[0][p].mean(0)) ** 2, axis=0)) for p in (0, 1)])
        sigma.append([trials[0][p].std(axis=0, ddof=1).mean(axis=0) for p in (0, 1)])
    rmsd, isv = np.mean(rmsd, axis=0), 2.0 * np.mean(sigma, axis=0)
    for p, phase in enumerate(("stance", "swing")):
        for j, joint in enumerate(JOINTS):
            study = STUDY_TRANSPARENCY_RAD[(phase, joint)][0]
            assert 0.017 <= rmsd[p, j] <= 0.071 and rmsd[p, j] < isv[p, j], (phase, joint, rmsd[p, j], isv[p, j])
            assert 1 / 1.5 <= rmsd[p, j] / study <= 1.5, (phase, joint, rmsd[p, j], study)


def test_pulse_response_rides_on_top_of_the_minimal_impedance_response():
    """Superposition: the swing's answer to the whole force (minimal impedance + pulse) equals the answer to the
    minimal-impedance force plus the pulse response of the gentle lab, within 3 % of the pulse response."""
    from loper_analysis.device.controller import DeviceParameters
    from loper_analysis.motion.model import build_lower_body_model, segment_parameters_from_model
    from loper_analysis.synthetic.response import pulse_train, swing_response, swing_responses, swing_spans
    from loper_analysis.synthetic.trials import LabSettings, simulate_walking_trial

    params = segment_parameters_from_model(build_lower_body_model(1.73, 65.0))
    impedance = (55.0, 3.5, 3.0, 0.1, 8.0, 0.3)
    walk = simulate_walking_trial(
        12.0,
        LabSettings(),
        11,
        1.73,
        params,
        timing_cv=0.03,
        amplitude_cv=0.05,
        device=DeviceParameters(),
        variability=_study_variability(),
    )
    fine = walk.fine
    t = fine["time_s"].to_numpy()
    angles = fine[[f"{j}_l" for j in CURVE_JOINTS]].to_numpy()
    pelvis, x = -fine["pelvis_tilt"].to_numpy(), fine["pelvis_tx"].to_numpy()
    rt = walk.robot["time_s"].to_numpy()
    fu = np.interp((t + 1.3) / (1 + 80e-6), rt, walk.robot["force_measured_n"].to_numpy())
    swing = swing_spans(walk.mocap_events(), "left").iloc[[2]]
    onset = float(swing["toe_off_s"].iloc[0]) + 0.175
    fp = fu + pulse_train(t, [onset], 40.0, 0.1)
    whole = swing_responses(t, angles, pelvis, x, params, impedance, fp, swing)
    minimal = swing_responses(t, angles, pelvis, x, params, impedance, fu, swing)
    assert 0.003 < np.abs(minimal).max() < 0.1  # the ~2 N force moves the leg by milliradians to centiradians
    sl = slice(int(np.searchsorted(t, onset - 0.3)), int(np.searchsorted(t, swing["heel_strike_s"].iloc[0] + 0.35)))
    pulse = np.zeros_like(angles)
    pulse[sl] = swing_response(
        t[sl],
        angles[sl],
        pelvis[sl],
        x[sl],
        params,
        impedance,
        fp[sl],
        fu[sl],
        onset,
        float(swing["heel_strike_s"].iloc[0]),
    )
    assert np.abs(pulse).max() > 0.05
    assert np.abs(whole - minimal - pulse).max() < 0.03 * np.abs(pulse).max()


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"variability": "wild"}, ["synthetic.variability", "wild"]),
        ({"study_variability": {**SYNTH["study_variability"], "swing_gain": [1.0, 1.0, 9.0]}}, ["swing_gain", "9.0"]),
        ({"device_adaptation": {**SYNTH["device_adaptation"], "mass_kg": 2.0}}, ["device_adaptation", "mass_kg"]),
    ],
)
def test_config_schema_checks_the_variability_settings(change, words):
    from loper_analysis.schema import check_config

    cfg = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    assert cfg["synthetic"]["variability"] == "study"  # the default
    check_config(cfg, ROOT / "workflow/schemas/config.schema.yaml")
    cfg["synthetic"]["variability"] = "gentle"
    check_config(cfg, ROOT / "workflow/schemas/config.schema.yaml")
    cfg["synthetic"].update(change)
    with pytest.raises(LoperInputError) as info:
        check_config(cfg, ROOT / "workflow/schemas/config.schema.yaml")
    assert all(w in str(info.value) for w in words), str(info.value)
