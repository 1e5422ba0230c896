"""Perturbation responses of the synthetic lab: schedule, pulses, size and timing like the study's, and the truth comes
back."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.device.controller import DeviceParameters
from loper_analysis.motion.model import build_lower_body_model, segment_parameters_from_model
from loper_analysis.synthetic.response import (
    perturbation_schedule,
    pulse_train,
    swing_response,
    thigh_normal,
)
from loper_analysis.synthetic.trials import (
    LabSettings,
    PerturbationSettings,
    simulate_walking_trial,
)

LAB = LabSettings()
# a study-like subject at the 50 ms onset: hip K 55, D 3.5; knee K 3, D 0.1; ankle K 8, D 0.3
IMPEDANCE = (55.0, 3.5, 3.0, 0.1, 8.0, 0.3)


@pytest.fixture(scope="module")
def params():
    return segment_parameters_from_model(build_lower_body_model(1.73, 64.9))


@pytest.fixture(scope="module")
def trial(params):
    return simulate_walking_trial(
        40.0,
        LAB,
        5,
        1.73,
        params,
        timing_cv=0.03,
        amplitude_cv=0.05,
        device=DeviceParameters(),
        perturbation=PerturbationSettings(onset_s=0.05, impedance=IMPEDANCE),
    )


def test_schedule_every_three_to_five_strides():
    hs = np.arange(0.0, 60.0, 1.6)
    events = pd.concat(
        [
            pd.DataFrame({"side": "left", "event": "heel_strike", "time_s": hs}),
            pd.DataFrame({"side": "left", "event": "toe_off", "time_s": hs + 1.0}),
        ]
    )
    sched = perturbation_schedule(events, 0.175, np.random.default_rng(1), 0.5, 59.5)
    gaps = np.diff(np.round((sched.toe_off_s.to_numpy() - 1.0) / 1.6))
    assert len(sched) >= 8 and set(gaps) <= {3, 4, 5} and len(set(gaps)) > 1
    np.testing.assert_allclose(sched.onset_s - sched.toe_off_s, 0.175)
    np.testing.assert_allclose(sched.heel_strike_s - sched.toe_off_s, 0.6)
    assert (sched.heel_strike_s <= 59.5).all()


def test_pulse_and_force_direction():
    t = np.arange(0, 1, 0.001)
    f = pulse_train(t, [0.2], 40.0, 0.1)
    assert f.sum() * 0.001 == pytest.approx(4.0)  # 40 N for 100 ms
    np.testing.assert_allclose(thigh_normal([0.0, np.pi / 2]), [[1.0, 0.0], [0.0, -1.0]], atol=1e-15)


def test_no_force_no_response(params):
    t = np.arange(0, 0.8, 1 / 1024)
    th = np.stack([0.2 + 0.3 * t, 0.6 - 0.2 * t, -0.1 + 0 * t], axis=-1)
    zero = np.zeros_like(t)
    d = swing_response(t, th, 0.1 + zero, zero, params, IMPEDANCE, zero, zero, 0.2, 0.7)
    assert np.abs(d).max() < 1e-12


def test_responses_look_like_the_study(trial):
    """Hip ~0.1 rad and knee ~0.2 rad, peaking ~150 ms after onset, as the study reports."""
    fine = trial.fine
    t = fine.time_s.to_numpy()
    assert len(trial.schedule) >= 5
    assert trial.robot.perturbation.sum() / LAB.robot_rate_hz == pytest.approx(0.1 * len(trial.schedule), rel=0.02)
    free = simulate_walking_trial(
        40.0,
        LAB,
        5,
        1.73,
        segment_parameters_from_model(build_lower_body_model(1.73, 64.9)),
        timing_cv=0.03,
        amplitude_cv=0.05,
        device=None,
        perturbation=None,
    ).fine
    peaks = []
    for row in trial.schedule.itertuples():
        sel = (t >= row.onset_s) & (t <= row.onset_s + 0.4)
        d = (
            fine.loc[sel, ["hip_flexion_l", "knee_flexion_l"]].to_numpy()
            - free.loc[sel, ["hip_flexion_l", "knee_flexion_l"]].to_numpy()
        )
        i = np.abs(d).argmax(axis=0)
        peaks.append([d[i[0], 0], d[i[1], 1], t[sel][i[0]] - row.onset_s, t[sel][i[1]] - row.onset_s])
    hip, knee, t_hip, t_knee = np.mean(peaks, axis=0)
    assert 0.05 < hip < 0.2, hip  # forward push: more hip flexion
    assert 0.1 < abs(knee) < 0.4, knee
    assert 0.08 < t_hip < 0.25 and 0.08 < t_knee < 0.25, (t_hip, t_knee)
    # outside the perturbed swings the trial is the unperturbed one
    quiet = np.ones_like(t, bool)
    for row in trial.schedule.itertuples():
        quiet &= ~((t > row.onset_s - 0.06) & (t < row.heel_strike_s + 0.21))
    np.testing.assert_allclose(fine.loc[quiet, "hip_flexion_l"], free.loc[quiet, "hip_flexion_l"], atol=1e-12)


def test_identification_recovers_the_truth_from_the_simulated_swing(trial, params):
    """The response at the 128 Hz frames, identified with the measured forces: the lab and the fit agree."""
    from loper_analysis.impedance.identification import identify_impedance, prepare_window
    from loper_analysis.swing_leg.dynamics import segment_coordinates

    free = simulate_walking_trial(
        40.0, LAB, 5, 1.73, params, timing_cv=0.03, amplitude_cv=0.05, device=DeviceParameters(), perturbation=None
    )
    row = trial.schedule.iloc[2]
    t = trial.fine.time_s.to_numpy()
    sel = (t >= row.onset_s - 0.2) & (t <= row.onset_s + 0.3)
    sel &= (np.round(t * 1024).astype(int) % 8) == 0  # the motion-capture frames

    def coords(f):
        th = f.loc[sel, ["hip_flexion_l", "knee_flexion_l", "ankle_dorsiflexion_l"]].to_numpy()
        return segment_coordinates(th, -f.loc[sel, "pelvis_tilt"].to_numpy(), f.loc[sel, "pelvis_tx"].to_numpy())

    qp, qu = coords(trial.fine), coords(free.fine)
    scale = 1 + 1e-6 * LAB.clock_drift_ppm
    tr = (t[sel] + LAB.clock_offset_s) / scale
    fp = np.interp(tr, trial.robot.time_s, trial.robot.force_measured_n)
    fu = np.interp(tr, free.robot.time_s, free.robot.force_measured_n)
    window = prepare_window(
        t[sel],
        qu,
        qp,
        params,
        row.onset_s,
        force_unperturbed_n=fu[:, None] * thigh_normal(qu[:, 1]),
        force_perturbed_n=fp[:, None] * thigh_normal(qp[:, 1]),
        pelvis_angle_unperturbed_rad=-free.fine.loc[sel, "pelvis_tilt"].to_numpy(),
        pelvis_angle_perturbed_rad=-trial.fine.loc[sel, "pelvis_tilt"].to_numpy(),
        n_substeps=4,
    )
    fit = identify_impedance(window, n_starts=10, seed=0)
    est = dict(zip(("K_hip", "D_hip", "K_knee", "D_knee"), fit.estimate[:4]))
    # the force is seen at 128 Hz (linear between frames) while the truth felt it at 1024 Hz
    assert est["K_hip"] == pytest.approx(IMPEDANCE[0], rel=0.1)
    assert est["D_hip"] == pytest.approx(IMPEDANCE[1], rel=0.15)
    assert est["K_knee"] == pytest.approx(IMPEDANCE[2], abs=2.0)
    assert est["D_knee"] == pytest.approx(IMPEDANCE[3], abs=0.05)
    assert fit.vaf_pct[0] > 98 and fit.vaf_pct[1] > 95
