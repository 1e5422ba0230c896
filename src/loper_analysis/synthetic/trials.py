"""Recordings of a synthetic gait lab: C3D contents (markers 128 Hz, analogs 1024 Hz) and the robot log (1000 Hz).

A walking trial is recorded exactly as a lab records it:

* markers: the OpenSim model's markers at the simulated coordinates
  (:func:`loper_analysis.motion.ik.marker_positions`), turned from the model
  frame into the lab frame (the inverse of ``lab_to_model_rotation_deg``,
  Qualisys Z-up), Gaussian measurement noise, a few short gaps (NaN), stored
  in mm;
* analogs: per belt the vertical and fore-aft force and the moments
  (:func:`loper_analysis.synthetic.treadmill.treadmill_grf`), and the robot's sync
  output as the motion-capture system samples it;
* the robot log (trials with the device) on the robot's own clock, which
  starts ``clock_offset_s`` before the motion capture and runs
  ``clock_drift_ppm`` fast: the pipeline must align the two through the sync
  pulses (:mod:`loper_analysis.device.loadcell`). Its forces come from the device
  simulation in minimal-impedance mode driven by the brace motion of the
  simulated thigh (:func:`loper_analysis.device.controller.simulate_device`).

Time zero is the first motion-capture frame. Everything random derives from
the seed; the same seed gives the same recordings. The recordings are
:class:`loper_analysis.io.c3d.C3DRecording` objects and robot-log frames;
writing them is the file layer's job.
"""

from __future__ import annotations

import zlib
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from loper_analysis.constants import LAB_TO_MODEL_ROTATION_DEG, SIDE_SUFFIX, SIDES
from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import C3DRecording
from loper_analysis.study_design import PERTURBED_SIDE, PULSE_DURATION_S, PULSE_FORCE_N
from loper_analysis.swing_leg.rods import ShankRod
from loper_analysis.synthetic.shank_rod import attach_shank_rod
from loper_analysis.synthetic.walking import AMPLITUDE_CV, TIMING_CV

__all__ = [
    "LabSettings",
    "PerturbationSettings",
    "WalkingTrial",
    "lab_markers",
    "static_recording",
    "simulate_walking_trial",
    "walking_recording",
    "walking_with_margins",
    "subject_static_recording",
    "subject_walking_trial",
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
    lab_to_model_rotation_deg: tuple[float, float, float] = LAB_TO_MODEL_ROTATION_DEG
    grf_prefix: tuple[str, str] = ("_left", "_right")  # channel suffix per belt: Fz_left, Fz_right
    sync_channel: str = "sync"


def _model_to_lab(points_m: np.ndarray, rotation_deg: Sequence[float]) -> np.ndarray:
    rot = Rotation.from_euler("xyz", rotation_deg, degrees=True).inv()
    return rot.apply(points_m.reshape(-1, 3)).reshape(points_m.shape)


def lab_markers(model, coordinates: pd.DataFrame, lab: LabSettings, rng: np.random.Generator | None = None):
    """Marker trajectories (n_frames, n_markers, 3) in the lab frame (m) and their labels, with noise and gaps.

    ``model`` is an ``opensim.Model``; without ``rng`` the markers are exact.
    """
    from loper_analysis.motion.ik import marker_positions

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
            X[start : start + length, int(rng.integers(len(labels)))] = np.nan
    return X, labels


def static_recording(
    model, coordinates: pd.DataFrame, duration_s: float, lab: LabSettings, seed, source: str = "static trial"
) -> C3DRecording:
    """A static trial: the first row of ``coordinates`` held for ``duration_s``, markers only (no gaps)."""
    n = int(round(duration_s * lab.marker_rate_hz))
    if n < 2:
        raise LoperInputError(f"static trial of {duration_s} s has fewer than 2 frames")
    still = pd.DataFrame({c: np.repeat(coordinates[c].iloc[0], n) for c in coordinates.columns})
    rng = np.random.default_rng(seed)
    X, labels = lab_markers(model, still, lab.__class__(**{**lab.__dict__, "n_gaps": 0}), rng)
    return C3DRecording(source=source, marker_labels=labels, markers_m=X, point_rate_hz=lab.marker_rate_hz)


def _brace_position_m(
    coordinates: pd.DataFrame, attachment_m: float, side: str = SIDE_SUFFIX[PERTURBED_SIDE]
) -> np.ndarray:
    """Forward position (m) of the brace on the thigh: pelvis_tx + a·sin(pelvis_tilt + hip_flexion)."""
    angle = coordinates["pelvis_tilt"].to_numpy(float) + coordinates[f"hip_flexion_{side}"].to_numpy(float)
    return coordinates["pelvis_tx"].to_numpy(float) + attachment_m * np.sin(angle)


@dataclass(frozen=True)
class PerturbationSettings:
    """LOPER force pulses of an impedance trial and the impedance the subject answers with."""

    onset_s: float  # after toe-off of the perturbed (left) leg
    impedance: tuple[float, ...]  # K_hip, D_hip, K_knee, D_knee, K_ankle, D_ankle (N·m/rad, N·m·s/rad)
    force_n: float = PULSE_FORCE_N
    duration_s: float = PULSE_DURATION_S
    every_strides: tuple[int, int] = (3, 5)
    shank_force_n: float = 0.0  # a second rod's pulse just above the ankle, with the thigh's (N); 0: none


@dataclass
class WalkingTrial:
    """A simulated walking trial on the motion-capture clock (t = 0 at the first frame).

    ``fine`` holds the model coordinates at the analog rate over the robot
    log's span (perturbed where pulses hit); ``events`` the true gait events;
    ``schedule`` the perturbations (``toe_off_s``, ``onset_s``,
    ``heel_strike_s``); ``robot`` the robot-log frame (None without the device).
    """

    duration_s: float
    fine: pd.DataFrame
    events: pd.DataFrame
    schedule: pd.DataFrame
    robot: pd.DataFrame | None
    sync_starts_s: np.ndarray

    def mocap_coordinates(self, marker_rate_hz: float) -> pd.DataFrame:
        """The coordinates at the motion-capture frames 0 .. duration (marker rate)."""
        t = self.fine["time_s"].to_numpy()
        step = int(round(1.0 / (marker_rate_hz * (t[1] - t[0]))))
        first = int(np.argmin(np.abs(t)))
        n = int(round(self.duration_s * marker_rate_hz))
        out = self.fine.iloc[first : first + n * step : step].reset_index(drop=True)
        return out.assign(time_s=np.arange(n) / marker_rate_hz)

    def mocap_events(self) -> pd.DataFrame:
        e = self.events
        return e[(e["time_s"] >= 0) & (e["time_s"] <= self.duration_s)].reset_index(drop=True)

    def mocap_grf(self, body_mass_kg: float, lab: LabSettings, rng: np.random.Generator) -> pd.DataFrame:
        """Both belts' ground reactions at the analog rate over the motion capture, with the lab's noise.

        :func:`loper_analysis.synthetic.treadmill.treadmill_grf` of :meth:`mocap_events` for a body of
        ``body_mass_kg`` kg at ``lab.analog_rate_hz`` (forces in N, moments in N·m, noise SD
        ``lab.grf_noise_sd_n`` N drawn from ``rng``).
        """
        from loper_analysis.synthetic.treadmill import treadmill_grf

        return treadmill_grf(
            self.mocap_events(),
            self.duration_s,
            lab.analog_rate_hz,
            body_mass_kg,
            rng=rng,
            noise_sd_n=lab.grf_noise_sd_n,
        )

    def sync_v(self, time_s, lab: LabSettings) -> np.ndarray:
        """The robot's sync output (V) as the motion capture samples it at its times ``time_s`` (s).

        The robot clock starts ``lab.clock_offset_s`` s before the motion capture and runs
        ``lab.clock_drift_ppm`` ppm fast; the pulses start at ``sync_starts_s`` on it.
        """
        from loper_analysis.synthetic.sync import pulse_train_at

        scale = 1.0 + 1e-6 * lab.clock_drift_ppm
        return pulse_train_at((np.asarray(time_s, dtype=float) + lab.clock_offset_s) / scale, self.sync_starts_s)


def simulate_walking_trial(
    duration_s: float,
    lab: LabSettings,
    seed,
    height_m: float,
    params,
    *,
    timing_cv: float = TIMING_CV,
    amplitude_cv: float = AMPLITUDE_CV,
    device=None,
    perturbation: PerturbationSettings | None = None,
    gait=None,
    variability=None,
    adaptation=None,
    minimal_impedance=None,
    shank_rod: ShankRod | None = None,
) -> WalkingTrial:
    """Simulate kinematics, device and perturbation responses of one walking trial.

    ``params`` is the subject's :class:`~loper_analysis.swing_leg.dynamics.SegmentParameters`
    (its ``attachment_m`` places the brace); ``device`` a
    :class:`~loper_analysis.device.controller.DeviceParameters` or None (no
    device). The device runs on the robot clock (``clock_offset_s``,
    ``clock_drift_ppm``), driven by the brace motion of the unperturbed
    thigh and the desired pulses; the leg answers the difference of the
    measured force with and without the pulses (:mod:`.response`).

    ``variability`` (:class:`~loper_analysis.synthetic.variability.GaitVariability`)
    and ``adaptation`` (:class:`~loper_analysis.synthetic.variability.DeviceAdaptation`,
    trials with the device) select the study-level lab; None: the gentle one.
    With ``minimal_impedance`` (K, D per joint, as ``perturbation.impedance``)
    and the device, every left swing answers the measured force itself, the
    minimal-impedance force and any pulses
    (:func:`~loper_analysis.synthetic.response.swing_responses`), with the
    perturbation's impedance in a trial with pulses and ``minimal_impedance``
    otherwise; None: only the pulses act (their force minus that of a run
    without them).

    ``shank_rod`` (:class:`~loper_analysis.swing_leg.rods.ShankRod`; None: none) attaches a second device just
    above the ankle, driven by the motion of its point: its desired and measured force are the robot log's
    ``shank_force_desired_n`` and ``shank_force_measured_n`` and the leg answers both rods. It pushes
    ``perturbation.shank_force_n`` N with the thigh's pulses (same onsets and duration); without pulses it
    follows the leg at its minimal impedance as the thigh's does.
    """
    from loper_analysis.device.controller import simulate_device
    from loper_analysis.synthetic.response import perturbation_schedule, pulse_train
    from loper_analysis.synthetic.sync import pulse_train_at, sync_pulse_starts
    from loper_analysis.synthetic.walking import leg_length_from_height

    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    gait_seed, sync_seed, device_seed, schedule_seed = ss.spawn(4)
    fine, events = walking_with_margins(
        duration_s,
        lab,
        np.random.default_rng(gait_seed),
        timing_cv=timing_cv,
        amplitude_cv=amplitude_cv,
        leg_length_m=leg_length_from_height(height_m),
        gait=gait,
        sample_rate_hz=lab.analog_rate_hz,
        variability=variability,
        adaptation=adaptation if device is not None else None,
    )
    scale = 1.0 + 1e-6 * lab.clock_drift_ppm
    robot_duration = (duration_s + lab.robot_margin_s + lab.clock_offset_s) / scale
    starts = sync_pulse_starts(robot_duration, sync_seed)
    schedule = pd.DataFrame(columns=["toe_off_s", "onset_s", "heel_strike_s"])
    if perturbation is not None:
        schedule = perturbation_schedule(
            events,
            perturbation.onset_s,
            np.random.default_rng(schedule_seed),
            0.5,
            duration_s - 0.5,
            PERTURBED_SIDE,
            perturbation.every_strides,
        )
    if device is None:
        return WalkingTrial(duration_s, fine, events, schedule, None, starts)
    t_fine = fine["time_s"].to_numpy()
    t_robot = np.arange(int(np.floor(robot_duration * lab.robot_rate_hz))) / lab.robot_rate_hz
    t_mocap = -lab.clock_offset_s + scale * t_robot
    if t_mocap[0] < t_fine[0] - 1e-9 or t_mocap[-1] > t_fine[-1] + 1e-9:
        raise LoperInputError("simulate_walking_trial: the kinematics do not cover the robot log")
    brace = np.interp(t_mocap, t_fine, _brace_position_m(fine, params.attachment_m))
    brace -= brace.mean()
    onsets_robot = (schedule["onset_s"].to_numpy(float) + lab.clock_offset_s) / scale
    fd = (
        pulse_train(t_robot, onsets_robot, perturbation.force_n, perturbation.duration_s)
        if perturbation
        else 0 * t_robot
    )
    sim = simulate_device(fd, device, None, brace_position_m=brace, seed=device_seed)
    robot = _robot_frame(t_robot, sim, fd, pulse_train_at(t_robot, starts))
    robot, params, shank = attach_shank_rod(
        robot, fine, params, shank_rod, perturbation, ((t_robot, t_mocap), onsets_robot, device, ss)
    )
    if minimal_impedance is not None:
        impedance = perturbation.impedance if perturbation is not None else tuple(minimal_impedance)
        fine = _fine_answering_every_swing(fine, events, t_robot, robot, lab, params, impedance, shank)
    elif perturbation is not None and len(schedule):
        free = _free_run(t_robot, device, (brace, device_seed), shank)
        fine = _fine_answering_pulses(
            fine, schedule, t_robot, (robot, free), lab, params, perturbation.impedance, shank
        )
    return WalkingTrial(duration_s, fine, events, schedule, robot, starts)


def _free_run(t_robot, device, thigh, shank) -> pd.DataFrame:
    """The device run without pulses (same noise): the thigh rod's (``thigh``: its brace motion in m and seed),
    with a second rod's measured force when ``shank`` (rod, its point's motion in m, seed) is not None."""
    from loper_analysis.device.controller import simulate_device

    free = simulate_device(0 * t_robot, device, None, brace_position_m=thigh[0], seed=thigh[1])
    if shank is None:
        return free
    free_shank = simulate_device(0 * t_robot, device, None, brace_position_m=shank[1], seed=shank[2])
    return free.assign(shank_force_measured_n=free_shank["force_measured_n"].to_numpy())


def _robot_frame(t_robot: np.ndarray, sim: pd.DataFrame, fd: np.ndarray, sync_v: np.ndarray) -> pd.DataFrame:
    """The robot-log frame: time (s) on the robot clock, desired and measured force (N), motor angle (rad) and
    velocity (rad/s), sync output (V), perturbation flag and safety state (n_samples rows).

    ``sim`` is the device simulation (:func:`loper_analysis.device.controller.simulate_device`) of the desired
    force ``fd`` (N) at ``t_robot``."""
    return pd.DataFrame(
        {
            "time_s": t_robot,
            "force_desired_n": sim["force_desired_n"].to_numpy(),
            "force_measured_n": sim["force_measured_n"].to_numpy(),
            "motor_angle_rad": sim["motor_angle_rad"].to_numpy(),
            "motor_velocity_rad_s": sim["motor_velocity_rad_s"].to_numpy(),
            "sync_v": sync_v,
            "perturbation": (np.abs(fd) > 0).astype(np.int64),
            "safety_state": sim["safety_state"].to_numpy().astype(np.int64),
        }
    )


def _fine_answering_every_swing(
    fine: pd.DataFrame,
    events: pd.DataFrame,
    t_robot: np.ndarray,
    robot: pd.DataFrame,
    lab: LabSettings,
    params,
    impedance: Sequence[float],
    shank=None,
) -> pd.DataFrame:
    """The fine coordinates (rad) with every left swing within the robot log answering the measured force (N)
    with ``impedance`` (:func:`loper_analysis.synthetic.response.swing_responses`); ``t_robot`` (s) on the robot
    clock. ``shank``: None, or the second rod (its :class:`~loper_analysis.swing_leg.rods.ShankRod` first), whose
    measured force (the robot log's ``shank_force_measured_n``) the leg answers too."""
    from loper_analysis.synthetic.response import swing_responses, swing_spans

    scale = 1.0 + 1e-6 * lab.clock_drift_ppm
    t_fine = fine["time_s"].to_numpy()
    fm = np.interp((t_fine + lab.clock_offset_s) / scale, t_robot, robot["force_measured_n"].to_numpy())
    shank_options = {}
    if shank is not None:
        fs = np.interp((t_fine + lab.clock_offset_s) / scale, t_robot, robot["shank_force_measured_n"].to_numpy())
        shank_options = {"shank_rod": shank[0]}
    angles = fine[["hip_flexion_l", "knee_flexion_l", "ankle_dorsiflexion_l"]].to_numpy()
    t_span = -lab.clock_offset_s + scale * t_robot[[0, -1]]
    inside = (t_fine >= t_span[0]) & (t_fine <= t_span[1])
    delta = swing_responses(
        t_fine[inside],
        angles[inside],
        -fine["pelvis_tilt"].to_numpy()[inside],
        fine["pelvis_tx"].to_numpy()[inside],
        params,
        impedance,
        fm[inside],
        swing_spans(events, PERTURBED_SIDE),
        shank_force_n=fs[inside] if shank is not None else None,
        **shank_options,
    )
    fine = fine.copy()
    for i, c in enumerate(("hip_flexion_l", "knee_flexion_l", "ankle_dorsiflexion_l")):
        fine.loc[inside, c] = angles[inside, i] + delta[:, i]
    return fine


def _fine_answering_pulses(
    fine: pd.DataFrame,
    schedule: pd.DataFrame,
    t_robot: np.ndarray,
    runs: tuple[pd.DataFrame, pd.DataFrame],
    lab: LabSettings,
    params,
    impedance: Sequence[float],
    shank=None,
) -> pd.DataFrame:
    """The fine coordinates (rad) with the left leg answering each scheduled pulse with ``impedance``: the
    difference of the measured force (N) of the device runs with and without the pulses (``runs``, on the robot
    clock ``t_robot`` in s) around each pulse (:func:`loper_analysis.synthetic.response.swing_response`); with
    ``shank`` (its :class:`~loper_analysis.swing_leg.rods.ShankRod` first) the second rod's the same way."""
    from loper_analysis.synthetic.response import swing_response

    robot, free = runs
    scale = 1.0 + 1e-6 * lab.clock_drift_ppm
    t_fine = fine["time_s"].to_numpy()
    to_robot_fine = (t_fine + lab.clock_offset_s) / scale
    fp = np.interp(to_robot_fine, t_robot, robot["force_measured_n"].to_numpy())
    fu = np.interp(to_robot_fine, t_robot, free["force_measured_n"].to_numpy())
    if shank is not None:
        sp, su = (np.interp(to_robot_fine, t_robot, r["shank_force_measured_n"].to_numpy()) for r in runs)
    angles = fine[["hip_flexion_l", "knee_flexion_l", "ankle_dorsiflexion_l"]].to_numpy()
    pelvis_angle = -fine["pelvis_tilt"].to_numpy()
    delta = np.zeros_like(angles)
    for row in schedule.itertuples():
        sl = slice(
            int(np.searchsorted(t_fine, row.onset_s - 0.3)), int(np.searchsorted(t_fine, row.heel_strike_s + 0.35))
        )
        delta[sl] += swing_response(
            t_fine[sl],
            angles[sl],
            pelvis_angle[sl],
            fine["pelvis_tx"].to_numpy()[sl],
            params,
            impedance,
            fp[sl],
            fu[sl],
            row.onset_s,
            row.heel_strike_s,
            **({} if shank is None else {"shank_force_n": (sp[sl], su[sl]), "shank_rod": shank[0]}),
        )
    fine = fine.copy()
    for i, c in enumerate(("hip_flexion_l", "knee_flexion_l", "ankle_dorsiflexion_l")):
        fine[c] = angles[:, i] + delta[:, i]
    return fine


def walking_recording(
    model, trial: WalkingTrial, body_mass_kg: float, lab: LabSettings, seed, source: str = "walking trial"
) -> C3DRecording:
    """The C3D contents of a walking trial: markers with noise and gaps, GRF per belt and the sync channel."""
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    marker_seed, grf_seed = ss.spawn(2)
    coords = trial.mocap_coordinates(lab.marker_rate_hz)
    X, labels = lab_markers(model, coords, lab, np.random.default_rng(marker_seed))
    grf = trial.mocap_grf(body_mass_kg, lab, np.random.default_rng(grf_seed))
    names, columns, units = [], [], []
    for side, suffix in zip(SIDES, lab.grf_prefix):
        for quantity, unit in (("fx", "N"), ("fz", "N"), ("mx", "N.m"), ("my", "N.m"), ("mz", "N.m")):
            key = f"{quantity}_{side}_{'nm' if unit == 'N.m' else 'n'}"
            names.append(f"{quantity.capitalize()}{suffix}")
            columns.append(grf[key].to_numpy(float))
            units.append(unit)
    names.append(lab.sync_channel)
    columns.append(trial.sync_v(grf["time_s"].to_numpy(float), lab))
    units.append("V")
    return C3DRecording(
        source=source,
        marker_labels=labels,
        markers_m=X,
        point_rate_hz=lab.marker_rate_hz,
        analog_labels=names,
        analog_units=units,
        analogs=np.column_stack(columns),
        analog_rate_hz=lab.analog_rate_hz,
    )


def walking_with_margins(
    duration_s: float,
    lab: LabSettings,
    rng: np.random.Generator,
    *,
    timing_cv: float,
    amplitude_cv: float,
    leg_length_m: float,
    gait=None,
    sample_rate_hz: float | None = None,
    variability=None,
    adaptation=None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Kinematics and events that cover the robot log's span: from ``clock_offset_s`` (+1 s) before the
    motion capture to ``robot_margin_s`` (+1 s) after it; time 0 is the first motion-capture frame.
    ``sample_rate_hz`` defaults to the marker rate and must be a multiple of it; ``variability`` and
    ``adaptation`` as in :func:`~loper_analysis.synthetic.walking.walking_kinematics`."""
    from loper_analysis.synthetic.gait_curves import NominalGait
    from loper_analysis.synthetic.walking import walking_kinematics

    rate = lab.marker_rate_hz if sample_rate_hz is None else sample_rate_hz
    lead = np.ceil((lab.clock_offset_s + 1.0) * lab.marker_rate_hz) / lab.marker_rate_hz
    total = lead + duration_s + lab.robot_margin_s + 1.0
    coords, events = walking_kinematics(
        total,
        rate,
        gait or NominalGait(),
        rng,
        timing_cv=timing_cv,
        amplitude_cv=amplitude_cv,
        leg_length_m=leg_length_m,
        variability=variability,
        adaptation=adaptation,
    )
    coords = coords.assign(time_s=np.round((coords["time_s"] - lead) * rate) / rate)
    return coords, events.assign(time_s=events["time_s"] - lead)


def _seed(seed, *names: str) -> list[int]:
    return [int(seed), *(zlib.crc32(n.encode()) for n in names)]


def subject_static_recording(
    subject: str, height_m: float, mass_kg: float, duration_s: float, lab: LabSettings, seed: int
) -> C3DRecording:
    """The static trial of a synthetic subject: standing, joints at 0, feet on the floor (seeded by subject)."""
    from loper_analysis.motion.model import COORDINATES, build_lower_body_model
    from loper_analysis.synthetic.walking import leg_length_from_height

    model = build_lower_body_model(height_m, mass_kg)
    still = pd.DataFrame({c: [0.0] for c in COORDINATES}).assign(pelvis_ty=leg_length_from_height(height_m))
    return static_recording(model, still, duration_s, lab, _seed(seed, subject, "static"), f"{subject} static")


def subject_walking_trial(
    subject: str,
    trial: str,
    height_m: float,
    mass_kg: float,
    duration_s: float,
    *,
    timing_cv: float,
    amplitude_cv: float,
    lab: LabSettings,
    device,
    seed: int,
    perturbation: PerturbationSettings | None = None,
    variability=None,
    adaptation=None,
    minimal_impedance=None,
    shank_rod: ShankRod | None = None,
) -> tuple[WalkingTrial, C3DRecording]:
    """One walking trial of a synthetic subject (seeded by subject and trial): the simulation and its C3D contents.

    ``device`` None simulates walking without the device (no robot log);
    ``variability``, ``adaptation``, ``minimal_impedance`` and ``shank_rod`` as in
    :func:`simulate_walking_trial` (None: the gentle lab; no second rod).
    """
    from loper_analysis.motion.model import build_lower_body_model, segment_parameters_from_model

    model = build_lower_body_model(height_m, mass_kg)
    params = segment_parameters_from_model(model)
    sim_seed, file_seed = np.random.SeedSequence(_seed(seed, subject, trial)).spawn(2)
    walk = simulate_walking_trial(
        duration_s,
        lab,
        sim_seed,
        height_m,
        params,
        timing_cv=timing_cv,
        amplitude_cv=amplitude_cv,
        device=device,
        perturbation=perturbation,
        variability=variability,
        adaptation=adaptation,
        minimal_impedance=minimal_impedance,
        shank_rod=shank_rod,
    )
    return walk, walking_recording(model, walk, mass_kg, lab, file_seed, f"{subject} {trial}")
