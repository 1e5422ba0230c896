"""A simulated trial's response inputs at the coordinate level: its angle table from the model's coordinates and
the robot log's force on the motion-capture clock, through the sync pulses' clock map."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry
from loper_analysis.synthetic.coordinate_trials import BRACE_LABELS, trial_inputs
from loper_analysis.synthetic.sync import pulse_train_at
from loper_analysis.synthetic.trials import LabSettings, simulate_walking_trial

#: A 6 s trial holds three strides, fewer than the stride table's outlier rule wants: its warning is expected.
pytestmark = pytest.mark.filterwarnings("ignore::loper_analysis.errors.TooFewStridesWarning")

LAB = LabSettings(clock_offset_s=1.3, clock_drift_ppm=80.0)
DURATION_S = 6.0


def _robot_force(t_robot: np.ndarray) -> np.ndarray:
    """The load cell's force (N) on the robot's clock: slow enough to pass the 6 Hz low-pass unchanged."""
    return 3.0 + 2.0 * np.sin(2 * math.pi * 0.25 * t_robot)


@pytest.fixture(scope="module")
def walk():
    """A walking trial, and a robot log written on the robot's clock as the device would: 1.3 s ahead of the
    motion capture, 80 ppm fast, its sync output the trial's pulses."""
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    trial = simulate_walking_trial(DURATION_S, LAB, 11, 1.73, params)
    scale = 1.0 + 1e-6 * LAB.clock_drift_ppm
    t_robot = np.arange(int((DURATION_S + LAB.robot_margin_s + LAB.clock_offset_s) / scale * 1000)) / 1000.0
    force = _robot_force(t_robot)
    trial.robot = pd.DataFrame(
        {
            "time_s": t_robot,
            "force_desired_n": np.zeros_like(t_robot),
            "force_measured_n": force,
            "motor_angle_rad": np.zeros_like(t_robot),
            "motor_velocity_rad_s": np.zeros_like(t_robot),
            "sync_v": pulse_train_at(t_robot, trial.sync_starts_s),
            "perturbation": np.zeros(t_robot.size, dtype=np.int64),
            "safety_state": np.zeros(t_robot.size, dtype=np.int64),
        }
    )
    return trial


def test_angles_are_the_coordinates_with_the_pelvis_tilt_turned(walk):
    inputs = trial_inputs(walk, LAB, "walk-1")
    coords = walk.mocap_coordinates(LAB.marker_rate_hz)
    angles = inputs["angles"]
    assert len(angles) == 768  # 6 s at 128 Hz
    np.testing.assert_array_equal(angles["pelvis_angle_rad"], -coords["pelvis_tilt"])
    np.testing.assert_array_equal(angles["pelvis_x_m"], coords["pelvis_tx"])
    for joint, coordinate in (("hip", "hip_flexion"), ("knee", "knee_flexion"), ("ankle", "ankle_dorsiflexion")):
        np.testing.assert_array_equal(angles[f"{joint}_left_rad"], coords[f"{coordinate}_l"])
        np.testing.assert_array_equal(angles[f"{joint}_right_rad"], coords[f"{coordinate}_r"])
    time_s, markers, labels = inputs["markers"]
    assert labels == list(BRACE_LABELS) == ["LBRA_P", "LBRA_D"] and markers.shape == (768, 2, 3)
    np.testing.assert_allclose(np.linalg.norm(markers[:, 0] - markers[:, 1], axis=1), 0.1)  # 10 cm along the thigh


def test_force_reaches_the_motion_capture_frames_through_the_clock_map(walk):
    inputs = trial_inputs(walk, LAB, "walk-1")
    force = inputs["force"]
    t = force["time_s"].to_numpy()
    t_robot = (t + LAB.clock_offset_s) / (1.0 + 80e-6)  # a motion-capture time on the robot's clock
    np.testing.assert_allclose(force["force_measured_n"], _robot_force(t_robot), atol=2e-3)
    native = inputs["force_native"]
    t_native = native["time_s"].to_numpy()
    inside = (t_native > 0.5) & (t_native < DURATION_S - 0.5)  # away from the filter's ends
    np.testing.assert_allclose(
        native.loc[inside, "force_measured_n"], _robot_force((t_native[inside] + 1.3) / (1.0 + 80e-6)), atol=2e-3
    )


def test_a_cut_trial_keeps_the_uncut_trial_s_noisy_frames(walk):
    whole = trial_inputs(walk, LAB, "full", angle_noise_sd_rad=0.01, seed=3)
    cut = trial_inputs(walk, LAB, "first", angle_noise_sd_rad=0.01, seed=3, end_s=3.0)
    assert cut["angles"]["time_s"].iloc[-1] == 3.0 and len(cut["angles"]) == 385
    pd.testing.assert_frame_equal(cut["angles"], whole["angles"].iloc[:385])
    noise = whole["angles"]["hip_left_rad"] - trial_inputs(walk, LAB, "clean")["angles"]["hip_left_rad"]
    assert noise.std() == pytest.approx(0.01, rel=0.1)
    assert len(cut["strides"]) >= 1 and (cut["strides"]["end_s"] <= 3.0).all()


def test_a_trial_without_the_device_or_with_bad_noise_is_refused(walk):
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    without = simulate_walking_trial(2.0, LAB, 11, 1.73, params)
    with pytest.raises(LoperInputError, match=r"^walk-0: a trial without the device has no robot log$"):
        trial_inputs(without, LAB, "walk-0")
    with pytest.raises(LoperInputError, match=r"^walk-1: angle_noise_sd_rad must be finite and >= 0, got -0\.1$"):
        trial_inputs(walk, LAB, "walk-1", angle_noise_sd_rad=-0.1)
