"""Raw files of a synthetic gait lab: C3D (markers 128 Hz, analogs 1024 Hz) and the robot log (1000 Hz).

A walking trial is written exactly as a lab records it:

* markers: the OpenSim model's markers at the simulated coordinates
  (:func:`loper_analysis.kinematics.marker_positions`), turned from the model
  frame into the lab frame (the inverse of ``lab_to_model_rotation_deg``,
  Qualisys Z-up), Gaussian measurement noise, a few short gaps (NaN), stored
  in mm;
* analogs: per belt the vertical and fore-aft force and the moments
  (:func:`loper_analysis.synthetic.gait.treadmill_grf`), and the robot's sync
  output as the motion-capture system samples it;
* the robot log (trials with the device) on the robot's own clock, which
  starts ``clock_offset_s`` before the motion capture and runs
  ``clock_drift_ppm`` fast: the pipeline must align the two through the sync
  pulses (:mod:`loper_analysis.loadcell`). Its forces come from the device
  simulation in minimal-impedance mode driven by the brace motion of the
  simulated thigh (:func:`loper_analysis.device.controller.simulate_device`).

Time zero is the first motion-capture frame. Everything random derives from
the seed; the same seed gives the same bytes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from ..errors import LoperInputError

__all__ = [
    "LabSettings",
    "lab_markers",
    "write_walking_trial",
    "write_static_trial",
    "walking_with_margins",
    "synthetic_static_file",
    "synthetic_walking_files",
]


@dataclass(frozen=True)
class LabSettings:
    """Recording settings of the synthetic lab (rates in Hz, noise in m or N)."""

    marker_rate_hz: float = 128.0
    analog_rate_hz: float = 1024.0
    robot_rate_hz: float = 1000.0
    marker_noise_sd_m: float = 0.0005
    n_gaps: int = 3  # marker gaps per trial
    max_gap_frames: int = 6  # longest gap written (the pipeline fills up to its own limit)
    grf_noise_sd_n: float = 2.0
    clock_offset_s: float = 1.3  # robot log starts this long before the motion capture
    clock_drift_ppm: float = 80.0  # robot clock runs this much fast
    robot_margin_s: float = 2.0  # robot log runs this long past the motion capture
    lab_to_model_rotation_deg: tuple[float, float, float] = (-90.0, 0.0, 0.0)
    grf_prefix: tuple[str, str] = ("_left", "_right")  # channel suffix per belt: Fz_left, Fz_right
    sync_channel: str = "sync"


def _model_to_lab(points_m: np.ndarray, rotation_deg: Sequence[float]) -> np.ndarray:
    rot = Rotation.from_euler("xyz", rotation_deg, degrees=True).inv()
    return rot.apply(points_m.reshape(-1, 3)).reshape(points_m.shape)


def lab_markers(model_osim, coordinates: pd.DataFrame, lab: LabSettings, rng: np.random.Generator | None = None):
    """Marker trajectories (n_frames, n_markers, 3) in the lab frame (m) and their labels, with noise and gaps.

    ``model_osim`` is a path or an ``opensim.Model``; without ``rng`` the markers are exact.
    """
    from ..kinematics import marker_positions
    from ..model import quiet_opensim

    osim = quiet_opensim()
    model = osim.Model(str(model_osim)) if isinstance(model_osim, (str, Path)) else model_osim
    ms = model.getMarkerSet()
    labels = [ms.get(i).getName() for i in range(ms.getSize())]
    values = {c: coordinates[c].to_numpy(float) for c in coordinates.columns if c != "time_s"}
    X = _model_to_lab(marker_positions(model, values, labels), lab.lab_to_model_rotation_deg)
    if rng is not None:
        X = X + rng.normal(0.0, lab.marker_noise_sd_m, X.shape)
        n = X.shape[0]
        for _ in range(lab.n_gaps):
            length = int(rng.integers(1, lab.max_gap_frames + 1))
            start = int(rng.integers(5, max(6, n - length - 5)))
            X[start:start + length, int(rng.integers(len(labels)))] = np.nan
    return X, labels


def write_static_trial(c3d_path, model_osim, coordinates: pd.DataFrame, duration_s: float, lab: LabSettings,
                       seed) -> None:
    """A static trial: the first row of ``coordinates`` held for ``duration_s``, markers only (no gaps)."""
    from ..io.c3d import write_c3d

    n = int(round(duration_s * lab.marker_rate_hz))
    if n < 2:
        raise LoperInputError(f"static trial of {duration_s} s has fewer than 2 frames")
    still = pd.DataFrame({c: np.repeat(coordinates[c].iloc[0], n) for c in coordinates.columns})
    rng = np.random.default_rng(seed)
    X, labels = lab_markers(model_osim, still, lab.__class__(**{**lab.__dict__, "n_gaps": 0}), rng)
    write_c3d(c3d_path, labels, X, lab.marker_rate_hz)


def _brace_position_m(coordinates: pd.DataFrame, attachment_m: float, side: str = "l") -> np.ndarray:
    """Forward position (m) of the brace on the thigh: pelvis_tx + a·sin(pelvis_tilt + hip_flexion)."""
    angle = coordinates["pelvis_tilt"].to_numpy(float) + coordinates[f"hip_flexion_{side}"].to_numpy(float)
    return coordinates["pelvis_tx"].to_numpy(float) + attachment_m * np.sin(angle)


def write_walking_trial(
    c3d_path,
    model_osim,
    coordinates: pd.DataFrame,
    events: pd.DataFrame,
    body_mass_kg: float,
    lab: LabSettings,
    seed,
    log_path=None,
    device=None,
    attachment_m: float = 0.35,
    desired_force_n=None,
    duration_s: float | None = None,
) -> None:
    """Write one walking trial: the C3D and, with ``log_path``, the robot log of the device.

    ``coordinates`` (``time_s`` at ``marker_rate_hz``, model coordinates) and
    ``events`` come from :func:`loper_analysis.synthetic.gait.walking_kinematics`,
    shifted so that the motion capture runs from 0 to ``duration_s`` (default:
    to the end of ``coordinates``). With a robot log they must also cover the
    robot's span (``clock_offset_s`` before 0 to ``robot_margin_s`` after the
    end), which drives the device. ``device`` is a
    :class:`~loper_analysis.device.controller.DeviceParameters`;
    ``desired_force_n`` (robot samples) the desired interaction force, zero
    (minimal impedance) by default.
    """
    from ..io.c3d import write_c3d
    from ..io.robot_log import write_robot_log
    from ..loadcell import pulse_train_at, sync_pulse_starts
    from .gait import treadmill_grf

    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    marker_seed, grf_seed, sync_seed, device_seed = ss.spawn(4)
    t_all = coordinates["time_s"].to_numpy(float)
    duration = float(t_all[-1] + 1.0 / lab.marker_rate_hz if duration_s is None else duration_s)
    n_frames = int(round(duration * lab.marker_rate_hz))
    first = int(np.searchsorted(t_all, -1e-9))
    mocap = coordinates.iloc[first:first + n_frames].reset_index(drop=True)
    if len(mocap) != n_frames or abs(mocap["time_s"].iloc[0]) > 1e-9:
        raise LoperInputError(f"coordinates must hold the frames 0 .. {duration} s at {lab.marker_rate_hz} Hz")
    X, labels = lab_markers(model_osim, mocap, lab, np.random.default_rng(marker_seed))
    inside = events[(events["time_s"] >= 0) & (events["time_s"] <= duration)]
    grf = treadmill_grf(inside, duration, lab.analog_rate_hz, body_mass_kg, np.random.default_rng(grf_seed),
                        noise_sd_n=lab.grf_noise_sd_n)
    ta = grf["time_s"].to_numpy(float)
    scale = 1.0 + 1e-6 * lab.clock_drift_ppm

    def to_robot(tm):  # t_mocap = -offset + scale * t_robot
        return (np.asarray(tm) + lab.clock_offset_s) / scale

    robot_duration = float(to_robot(duration + lab.robot_margin_s))
    starts = sync_pulse_starts(robot_duration, sync_seed)
    names, columns, units = [], [], []
    for side, suffix in zip(("left", "right"), lab.grf_prefix):
        for quantity, unit in (("fx", "N"), ("fz", "N"), ("mx", "N.m"), ("my", "N.m"), ("mz", "N.m")):
            key = f"{quantity}_{side}_{'nm' if unit == 'N.m' else 'n'}"
            names.append(f"{quantity.capitalize()}{suffix}")
            columns.append(grf[key].to_numpy(float))
            units.append(unit)
    names.append(lab.sync_channel)
    columns.append(pulse_train_at(to_robot(ta), starts))
    units.append("V")
    write_c3d(c3d_path, labels, X, lab.marker_rate_hz, names, np.column_stack(columns), units, lab.analog_rate_hz)
    if log_path is None:
        return
    from ..device.controller import simulate_device

    n_robot = int(np.floor(robot_duration * lab.robot_rate_hz))
    t_robot = np.arange(n_robot) / lab.robot_rate_hz
    t_mocap = -lab.clock_offset_s + scale * t_robot
    if t_mocap[0] < t_all[0] - 1e-9 or t_mocap[-1] > t_all[-1] + 1e-9:
        raise LoperInputError(
            f"coordinates span {t_all[0]:.3f} .. {t_all[-1]:.3f} s; the robot log needs {t_mocap[0]:.3f} .. "
            f"{t_mocap[-1]:.3f} s (mocap clock)"
        )
    brace = np.interp(t_mocap, t_all, _brace_position_m(coordinates, attachment_m))
    fd = np.zeros(n_robot) if desired_force_n is None else np.asarray(desired_force_n, float)
    sim = simulate_device(fd, device, None, brace_position_m=brace - brace.mean(), seed=device_seed)
    frame = pd.DataFrame({
        "time_s": t_robot,
        "force_desired_n": sim["force_desired_n"].to_numpy(),
        "force_measured_n": sim["force_measured_n"].to_numpy(),
        "motor_angle_rad": sim["motor_angle_rad"].to_numpy(),
        "motor_velocity_rad_s": sim["motor_velocity_rad_s"].to_numpy(),
        "sync_v": pulse_train_at(t_robot, starts),
        "perturbation": (np.abs(fd) > 0).astype(np.int64),
        "safety_state": sim["safety_state"].to_numpy().astype(np.int64),
    })
    write_robot_log(log_path, frame, lab.robot_rate_hz, {"clock": "robot"})


def walking_with_margins(duration_s: float, lab: LabSettings, rng: np.random.Generator, timing_cv: float,
                         amplitude_cv: float, leg_length_m: float, gait=None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Kinematics and events that cover the robot log's span: from ``clock_offset_s`` (+1 s) before the
    motion capture to ``robot_margin_s`` (+1 s) after it; time 0 is the first motion-capture frame."""
    from .gait import NominalGait, walking_kinematics

    lead = np.ceil((lab.clock_offset_s + 1.0) * lab.marker_rate_hz) / lab.marker_rate_hz
    total = lead + duration_s + lab.robot_margin_s + 1.0
    coords, events = walking_kinematics(total, lab.marker_rate_hz, gait or NominalGait(), rng, timing_cv,
                                        amplitude_cv, leg_length_m)
    coords = coords.assign(time_s=np.round((coords["time_s"] - lead) * lab.marker_rate_hz) / lab.marker_rate_hz)
    return coords, events.assign(time_s=events["time_s"] - lead)


def _seed(seed, *names: str) -> list[int]:
    import zlib

    return [int(seed), *(zlib.crc32(n.encode()) for n in names)]


def synthetic_static_file(c3d_path, subject: str, height_m: float, mass_kg: float, duration_s: float,
                          lab: LabSettings, seed: int) -> None:
    """The static trial of a synthetic subject: standing, joints at 0, feet on the floor."""
    from ..model import COORDINATES, build_lower_body_model
    from .gait import leg_length_from_height

    model = build_lower_body_model(height_m, mass_kg)
    still = pd.DataFrame({c: [0.0] for c in COORDINATES}).assign(pelvis_ty=leg_length_from_height(height_m))
    write_static_trial(c3d_path, model, still, duration_s, lab, _seed(seed, subject, "static"))


def synthetic_walking_files(c3d_path, log_path, subject: str, trial: str, height_m: float, mass_kg: float,
                            duration_s: float, timing_cv: float, amplitude_cv: float, lab: LabSettings,
                            device, attachment_fraction: float, seed: int) -> pd.DataFrame:
    """One walking trial of a synthetic subject (C3D and, with ``log_path``, the robot log); returns the true events."""
    from ..model import build_lower_body_model, segment_parameters_from_model
    from .gait import leg_length_from_height

    model = build_lower_body_model(height_m, mass_kg)
    ss = np.random.SeedSequence(_seed(seed, subject, trial))
    gait_seed, file_seed = ss.spawn(2)
    coords, events = walking_with_margins(duration_s, lab, np.random.default_rng(gait_seed), timing_cv, amplitude_cv,
                                          leg_length_from_height(height_m))
    thigh_m = segment_parameters_from_model(model).length_m[0]
    write_walking_trial(c3d_path, model, coords, events, mass_kg, lab, file_seed, log_path, device,
                        attachment_fraction * thigh_m, duration_s=duration_s)
    return events[(events["time_s"] >= 0) & (events["time_s"] <= duration_s)].reset_index(drop=True)
