"""Recordings of the synthetic lab: the perturbation schedule, the lab's settings, its markers in the lab's
Z-up frame (against OpenSim's own marker positions), the motion-capture frames and the robot's sync clock."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.motion.model import COORDINATES, build_lower_body_model
from loper_analysis.stages.settings import stage_settings
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry
from loper_analysis.synthetic.trials import (
    LabSettings,
    PerturbationSettings,
    lab_markers,
    simulate_walking_trial,
    static_recording,
)

ROOT = Path(__file__).resolve().parents[2]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
IMPEDANCE = (55.0, 3.5, 3.0, 0.10, 8.0, 0.3)
HEIGHT_M, MASS_KG = 1.73, 64.9
DURATION_S = 12.0


@pytest.fixture(scope="module")
def params():
    return segment_parameters_from_anthropometry(HEIGHT_M, MASS_KG)


@pytest.mark.parametrize("onset_ms", CONFIG["study"]["perturbation_onsets_ms"])
def test_perturbations_start_the_configured_ms_after_a_left_toe_off(onset_ms, params):
    perturbation = PerturbationSettings(onset_s=onset_ms / 1000.0, impedance=IMPEDANCE, every_strides=(1, 1))
    trial = simulate_walking_trial(DURATION_S, LabSettings(), 7, HEIGHT_M, params, perturbation=perturbation)
    schedule, events = trial.schedule, trial.events
    left = events[events["side"] == "left"]
    toe_offs = left.loc[left["event"] == "toe_off", "time_s"].to_numpy()
    heel_strikes = left.loc[left["event"] == "heel_strike", "time_s"].to_numpy()
    np.testing.assert_allclose(schedule["onset_s"] - schedule["toe_off_s"], onset_ms / 1000.0, rtol=0, atol=1e-12)
    assert set(schedule["toe_off_s"]) <= set(toe_offs)
    for to, hs in zip(schedule["toe_off_s"], schedule["heel_strike_s"]):
        assert hs == heel_strikes[heel_strikes > to][0]  # the swing ends at the next left heel strike
    # every swing inside 0.5 .. duration - 0.5 s after the first is perturbed (one stride apart)
    swings = [to for to in toe_offs if to >= 0.5 and (heel_strikes > to).any()]
    swings = [to for to in swings if heel_strikes[heel_strikes > to][0] <= DURATION_S - 0.5]
    assert schedule["toe_off_s"].tolist() == swings[1:]
    assert len(schedule) >= 4


def test_a_trial_without_perturbation_has_an_empty_schedule_and_no_robot_log(params):
    trial = simulate_walking_trial(DURATION_S, LabSettings(), 7, HEIGHT_M, params)
    assert len(trial.schedule) == 0 and list(trial.schedule.columns) == ["toe_off_s", "onset_s", "heel_strike_s"]
    assert trial.robot is None


def test_the_same_seed_gives_the_same_trial_and_another_seed_another(params):
    a = simulate_walking_trial(4.0, LabSettings(), 11, HEIGHT_M, params)
    b = simulate_walking_trial(4.0, LabSettings(), 11, HEIGHT_M, params)
    c = simulate_walking_trial(4.0, LabSettings(), 12, HEIGHT_M, params)
    pd.testing.assert_frame_equal(a.fine, b.fine)
    pd.testing.assert_frame_equal(a.events, b.events)
    assert not np.allclose(a.events["time_s"], c.events["time_s"])


def test_motion_capture_frames_are_the_fine_samples_at_the_marker_rate(params):
    trial = simulate_walking_trial(4.0, LabSettings(), 11, HEIGHT_M, params)
    mocap = trial.mocap_coordinates(128.0)
    assert len(mocap) == 512
    np.testing.assert_array_equal(mocap["time_s"], np.arange(512) / 128.0)
    fine_t = trial.fine["time_s"].to_numpy()
    rows = [int(np.flatnonzero(np.isclose(fine_t, k / 128.0, rtol=0, atol=1e-9))[0]) for k in (0, 1, 300, 511)]
    np.testing.assert_array_equal(
        mocap.loc[[0, 1, 300, 511], "hip_flexion_l"].to_numpy(), trial.fine.loc[rows, "hip_flexion_l"].to_numpy()
    )
    events = trial.mocap_events()
    assert events["time_s"].between(0.0, 4.0).all() and len(events) < len(trial.events)


def test_sync_pulses_reach_the_motion_capture_through_the_robot_clock_s_offset_and_drift(params):
    lab = LabSettings(clock_offset_s=1.3, clock_drift_ppm=80.0)
    trial = simulate_walking_trial(4.0, lab, 11, HEIGHT_M, params)
    scale = 1.0 + 80e-6
    start = trial.sync_starts_s[trial.sync_starts_s * scale - 1.3 > 0.1][0]  # a pulse inside the capture
    t_mocap = -1.3 + scale * start  # where the motion capture sees it start, high for 10 ms of the robot's clock
    np.testing.assert_array_equal(
        trial.sync_v(t_mocap + np.array([-1e-4, 1e-4, 0.005, 0.0099, 0.0102]), lab), [0.0, 5.0, 5.0, 5.0, 0.0]
    )


def test_lab_settings_follow_the_config():
    config = copy.deepcopy(CONFIG)
    config["synthetic"].update(
        marker_noise_sd_m=0.001,
        marker_gaps_per_trial=5,
        max_gap_frames=4,
        grf_noise_sd_n=3.5,
        clock_offset_s=0.8,
        clock_drift_ppm=-20.0,
    )
    config["markers"]["lab_to_model_rotation_deg"] = [90.0, 0.0, 0.0]
    config["events"]["sync_channel"] = "loper_sync"
    assert stage_settings(config, "synthetic").lab == LabSettings(
        marker_noise_sd_m=0.001,
        n_gaps=5,
        max_gap_frames=4,
        grf_noise_sd_n=3.5,
        clock_offset_s=0.8,
        clock_drift_ppm=-20.0,
        lab_to_model_rotation_deg=(90.0, 0.0, 0.0),
        sync_channel="loper_sync",
    )


@pytest.fixture(scope="module")
def model():
    return build_lower_body_model(HEIGHT_M, MASS_KG)


POSTURE = {
    "pelvis_tilt": 0.05,
    "pelvis_tx": 0.4,
    "hip_flexion_l": 0.3,
    "knee_flexion_l": 0.6,
    "ankle_dorsiflexion_l": 0.1,
}


def _opensim_markers(model, posture: dict) -> tuple[np.ndarray, list[str]]:
    """The model's markers in its ground frame (m) at ``posture``, as OpenSim places them."""
    state = model.initSystem()
    coordinates = model.getCoordinateSet()
    for name, value in posture.items():
        coordinates.get(name).setValue(state, value, False)
    model.realizePosition(state)
    markers = model.getMarkerSet()
    labels = [markers.get(i).getName() for i in range(markers.getSize())]
    return np.array([markers.get(i).getLocationInGround(state).to_numpy() for i in range(len(labels))]), labels


def test_lab_markers_are_opensim_s_turned_into_the_z_up_lab(model):
    posture = {c: 0.0 for c in COORDINATES} | {"pelvis_ty": 0.93} | POSTURE
    ground, labels = _opensim_markers(model, posture)
    X, lab_labels = lab_markers(model, pd.DataFrame({c: [v] for c, v in posture.items()}), LabSettings())
    assert lab_labels == labels
    # the inverse of -90 deg about X: the model's (x, y, z) is the lab's (x, -z, y), its height the lab's Z
    np.testing.assert_allclose(X[0], np.column_stack([ground[:, 0], -ground[:, 2], ground[:, 1]]), atol=1e-9)


def test_a_static_recording_holds_the_first_posture_with_the_lab_s_noise_and_no_gap(model):
    still = pd.DataFrame({c: [0.0, 0.2] for c in COORDINATES}).assign(pelvis_ty=[0.93, 0.5])
    lab = LabSettings(marker_noise_sd_m=0.0005, n_gaps=3)
    rec = static_recording(model, still, 2.0, lab, 5)
    assert rec.markers_m.shape == (256, len(rec.marker_labels), 3) and rec.point_rate_hz == 128.0
    assert not np.isnan(rec.markers_m).any()
    exact, _ = lab_markers(model, still.iloc[:1], lab)
    residual = rec.markers_m - exact
    assert np.abs(residual.mean(axis=0)).max() < 4 * 0.0005 / np.sqrt(256)
    assert residual.std() == pytest.approx(0.0005, rel=0.05)
