"""A simulated trial as a Qualisys (QTM) export of an instrumented split-belt treadmill, on the study's gait2392.

Where :mod:`loper_analysis.synthetic.trials` records our own lower-body model
the way the pipeline reads it back most simply, this module makes the raw
contents a real lab would hand over, with their quirks:

* markers: the gait2392 scale markers on a given OpenSim model (gait2392 or
  a scaled copy) at the simulated coordinates mapped onto gait2392's
  (:data:`loper_analysis.synthetic.gait2392_coordinates.GAIT2392_COORDINATES`, signs checked against OpenSim's body
  positions in the tests), the pelvis lifted so that the feet reach the floor
  (:func:`floor_offset_m`), turned into the lab frame (Z up: the inverse of
  ``lab_to_model_rotation_deg``), with noise, short gaps and long gaps (in
  markers the joint-angle fits do not need) and lab labels with a subject
  prefix (``Subject:L_FCC``) from a label map;
* the treadmill: two force plates (left belt = plate 1, right belt = plate 2,
  :func:`treadmill_platforms`) of TYPE 4 with a calibration matrix whose six
  bridge channels (V) carry the synthetic ground reaction force
  (:func:`loper_analysis.synthetic.treadmill.treadmill_grf`) at a centre of
  pressure that rolls from under the heel marker towards the toe marker,
  plus a resting load (the plates are not zeroed); decoy voltage channels
  labelled like force channels (``FP1_FZ``); the robot's sync channel;
* a first frame other than 0: every time in the file (frames, analogs,
  events) is on the clock whose first frame is at ``first_frame / rate``.

Everything random derives from the seed. The functions return contents
(:class:`LabExport`); :func:`tests.lab_export_session.lab_export_session` writes them
(:func:`loper_analysis.io.c3d_writer.write_recording` with
:meth:`LabExport.writer_extras`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from loper_analysis.constants import GRAVITY_M_PER_S2, SIDES
from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import C3DRecording
from loper_analysis.io.c3d_writer import ForcePlatform
from loper_analysis.synthetic.gait2392_coordinates import GAIT2392_COORDINATES, gait2392_coordinates
from loper_analysis.synthetic.trials import LabSettings, WalkingTrial
from tests.force_plate_channels import plate_channels, plate_frame, wrench_channels

__all__ = [
    "ROBOT_LOG_MAT_VARIABLES",
    "TREADMILL_CAL_MATRIX",
    "LabExport",
    "add_brace_markers",
    "QTMExportSettings",
    "floor_offset_m",
    "qtm_static_export",
    "qtm_walking_export",
    "treadmill_platforms",
]

#: Calibration of the belts' six bridge channels (V) into Fx, Fy, Fz (N) and Mx, My, Mz (N·mm), with 1-2 % crosstalk.
TREADMILL_CAL_MATRIX: tuple[tuple[float, ...], ...] = tuple(
    map(
        tuple,
        (
            np.diag([500.0, 500.0, 1000.0, 4.0e5, 4.0e5, 2.0e5])
            @ (
                np.eye(6)
                + 0.01
                * np.array(
                    [
                        [0, 1, -1, 0, 2, 0],
                        [-1, 0, 1, 1, 0, 0],
                        [1, -1, 0, 0, 0, 1],
                        [0, 1, 0, 0, -1, 1],
                        [2, 0, -1, 1, 0, 0],
                        [0, 0, 1, -1, 1, 0],
                    ]
                )
            )
        ).tolist(),
    )
)

#: Variable names of the robot log in the lab's MATLAB export (our column -> variable; those of the default
#: ``device.mat_column_map``).
ROBOT_LOG_MAT_VARIABLES: dict[str, str] = {
    "time_s": "t",
    "force_desired_n": "Fd",
    "force_measured_n": "Fm",
    "motor_angle_rad": "theta",
    "motor_velocity_rad_s": "omega",
    "sync_v": "sync",
    "perturbation": "pert",
    "safety_state": "safety",
}

_CONTEXT = {"left": "Left", "right": "Right"}
_EVENT_LABEL = {"heel_strike": "Foot Strike", "toe_off": "Foot Off"}


@dataclass(frozen=True)
class QTMExportSettings:
    """How the lab export looks: first frame, labels, gaps, treadmill plates and channels (m, N, N·m, V)."""

    first_frame: int = 1000
    subject_prefix: str = "Subject:"
    n_short_gaps: int = 4
    max_short_gap_frames: int = 6
    long_gap_frames: int = 40
    long_gap_markers: tuple[str, ...] = ("Top.Head", "R.Thigh.Rear", "R.Shank.Rear", "R.Midfoot.Lat")
    #: heel and toe markers per side (model names) that place the centre of pressure and the floor
    foot_markers: tuple[tuple[str, str], tuple[str, str]] = (("L.Heel", "L.Toe.Tip"), ("R.Heel", "R.Toe.Tip"))
    #: heights (m) of those markers above the floor with the foot flat (gait2392's markers)
    foot_marker_heights_m: tuple[float, float] = (0.036, 0.021)
    cop_roll_fraction: float = 0.8  # the COP rolls this fraction of heel -> toe marker over stance
    belt_length_m: float = 1.6
    belt_width_m: float = 0.5
    belt_gap_m: float = 0.01
    sensor_origin_m: tuple[float, float, float] = (0.003, -0.002, -0.06)  # FORCE_PLATFORM:ORIGIN, plate frame
    resting_force_n: tuple[tuple[float, ...], tuple[float, ...]] = ((1.5, -2.0, -40.0), (-1.0, 2.5, -35.0))
    resting_moment_nm: tuple[tuple[float, ...], tuple[float, ...]] = ((3.0, -2.0, 0.5), (-2.5, 1.5, -0.4))
    plate_scale: float = 10.0 / 32768.0  # ANALOG:SCALE of the bridge channels (V per count of a 16-bit ±10 V board)
    decoy_scale: float = 5.0 / 4096.0
    decoy_offset: int = 2048
    decoy_v_per_n: float = 1.0 / 200.0
    decoy_v_per_nm: float = 1.0 / 50.0
    with_events: bool = True


@dataclass
class LabExport:
    """The contents of one exported C3D file and the truth behind them.

    ``recording`` holds markers (lab frame, m, prefixed labels), analogs and
    ``first_frame``; ``force_platforms``, ``analog_scales``, ``analog_offsets``
    and ``events`` complete the file (:meth:`writer_extras`).
    ``coordinates`` are the gait2392 coordinates at the frames (``time_s`` on
    the file's clock); ``force_n`` and ``cop_m`` per side (``"left"``,
    ``"right"``) the ground reaction force (n_samples, 3) N on the belt, lab
    frame, without the resting load, and its centre of pressure (m, NaN in
    swing), at the analog samples; ``resting_force_n`` and
    ``resting_moment_nm`` per side the plates' load at rest (lab frame, moment
    about the surface centre).
    """

    recording: C3DRecording
    force_platforms: tuple[ForcePlatform, ForcePlatform]
    analog_scales: np.ndarray
    analog_offsets: np.ndarray
    events: list[tuple[str, str, float]]
    coordinates: pd.DataFrame
    force_n: dict[str, np.ndarray] = field(default_factory=dict)
    cop_m: dict[str, np.ndarray] = field(default_factory=dict)
    resting_force_n: dict[str, np.ndarray] = field(default_factory=dict)
    resting_moment_nm: dict[str, np.ndarray] = field(default_factory=dict)

    def writer_extras(self) -> dict:
        """Keyword arguments of :func:`loper_analysis.io.c3d_writer.write_recording` beside the recording."""
        return {
            "force_platforms": self.force_platforms,
            "analog_scales": self.analog_scales,
            "analog_offsets": self.analog_offsets,
            "events": self.events,
        }


def add_brace_markers(
    model,
    attachment_m: float,
    thigh_body: str = "femur_l",
    knee_body: str = "tibia_l",
    spacing_m: float = 0.08,
    anterior_m: float = 0.07,
    lateral_m: float = -0.06,
) -> None:
    """Put the LOPER brace markers ``LBRA_P`` and ``LBRA_D`` on the left thigh of an ``opensim.Model`` (in place).

    Both lie ``anterior_m`` in front of the hip-knee line (m), ``spacing_m``
    apart along it and centred ``attachment_m`` (m) from the hip, and
    ``lateral_m`` along the body's z axis (negative: lateral on the left leg),
    as on the generated model (:data:`loper_analysis.motion.model.BRACE_MARKERS`):
    their line is parallel to the thigh and the projection of their midpoint
    on it is the rod attachment. The knee is the origin of ``knee_body`` in
    the default pose.
    """
    from loper_analysis.io.osim import quiet_opensim

    osim = quiet_opensim()
    state = model.initSystem()
    bodies = model.getBodySet()
    thigh = bodies.get(thigh_body)
    knee = bodies.get(knee_body).findStationLocationInAnotherFrame(state, osim.Vec3(0.0), thigh)
    axis = np.array([knee.get(0), knee.get(1)])
    u = axis / np.linalg.norm(axis)
    n = np.array([-u[1], u[0]])  # the forward normal of the thigh axis (u points down)
    for name, along in (("LBRA_P", attachment_m - spacing_m / 2), ("LBRA_D", attachment_m + spacing_m / 2)):
        xy = along * u + anterior_m * n
        model.addMarker(osim.Marker(name, thigh, osim.Vec3(float(xy[0]), float(xy[1]), float(lateral_m))))
    model.finalizeConnections()
    model.initSystem()


def floor_offset_m(markers_model_m: np.ndarray, labels: Sequence[str], settings: QTMExportSettings) -> float:
    """Vertical shift (m, model +y) that puts the lower foot on the floor on average over the frames.

    Per frame, the lowest of the heel and toe markers of both feet above its
    flat-foot height (``foot_marker_heights_m``); the shift makes the mean of
    that over the frames 0, as the walking simulation does for its own model.
    """
    labels = list(labels)
    heights = []
    for pair in settings.foot_markers:
        for name, flat in zip(pair, settings.foot_marker_heights_m):
            if name not in labels:
                raise LoperInputError(f"foot marker '{name}' is not among the exported markers")
            heights.append(markers_model_m[:, labels.index(name), 1] - flat)
    return float(-np.mean(np.min(heights, axis=0)))


def treadmill_platforms(
    settings: QTMExportSettings, channels: tuple[Sequence[int], Sequence[int]]
) -> tuple[ForcePlatform, ForcePlatform]:
    """The two belts (left = plate 1 at lab y > 0, right = plate 2 at y < 0), surfaces at z = 0, centred on x = 0.

    Plate axes: x forward (lab +x), y to the right (lab -y), z down; corners
    in the quadrant order +x+y, -x+y, -x-y, +x-y; TYPE 4 with
    :data:`TREADMILL_CAL_MATRIX`.
    """
    half = 0.5 * settings.belt_length_m
    plates = []
    for side_sign, chans in zip((1.0, -1.0), channels):
        inner, outer = (
            side_sign * 0.5 * settings.belt_gap_m,
            side_sign * (0.5 * settings.belt_gap_m + settings.belt_width_m),
        )
        right_edge, left_edge = min(inner, outer), max(inner, outer)
        corners = [(half, right_edge, 0.0), (-half, right_edge, 0.0), (-half, left_edge, 0.0), (half, left_edge, 0.0)]
        plates.append(ForcePlatform(4, corners, settings.sensor_origin_m, tuple(chans), TREADMILL_CAL_MATRIX))
    return plates[0], plates[1]


def _channel_layout(settings: QTMExportSettings, sync_label: str):
    """Labels, units, scales, offsets of the 25 channels; plate channel numbers (1-based)."""
    labels, units, scales, offsets = [], [], [], []
    plate_channels_1based = []
    for k, belt in enumerate(("L", "R"), start=1):
        plate_channels_1based.append(tuple(range(len(labels) + 1, len(labels) + 7)))
        labels += [f"Belt_{belt}_Ch{j}" for j in range(1, 7)]
        scales += [settings.plate_scale] * 6
        offsets += [0] * 6
        labels += [f"FP{k}_{q}" for q in ("FX", "FY", "FZ", "MX", "MY", "MZ")]
        scales += [settings.decoy_scale] * 6
        offsets += [settings.decoy_offset] * 6
    labels.append(sync_label)
    scales.append(1.0)
    offsets.append(0)
    units = ["V"] * len(labels)
    return labels, units, np.array(scales), np.array(offsets, dtype=np.int64), tuple(plate_channels_1based)


def _lab_markers(
    model, coords2392: pd.DataFrame, label_map: Mapping[str, str], lab: LabSettings, settings: QTMExportSettings
) -> tuple[np.ndarray, list[str], float]:
    """Exact lab-frame markers (n, m, 3), their model names, and the floor offset applied (m)."""
    from loper_analysis.motion.ik import marker_positions

    names = list(label_map)
    values = {c: coords2392[c].to_numpy(float) for c in GAIT2392_COORDINATES}
    X = marker_positions(model, values, names)
    offset = floor_offset_m(X, names, settings)
    X[:, :, 1] += offset
    rot = Rotation.from_euler("xyz", lab.lab_to_model_rotation_deg, degrees=True).inv()
    return rot.apply(X.reshape(-1, 3)).reshape(X.shape), names, offset


def _noise_and_gaps(
    X: np.ndarray, names: list[str], lab: LabSettings, settings: QTMExportSettings, rng: np.random.Generator, gaps: bool
) -> np.ndarray:
    X = X + rng.normal(0.0, lab.marker_noise_sd_m, X.shape)
    n = X.shape[0]
    if not gaps:
        return X
    for _ in range(settings.n_short_gaps):
        length = int(rng.integers(1, settings.max_short_gap_frames + 1))
        start = int(rng.integers(5, max(6, n - length - 5)))
        X[start : start + length, int(rng.integers(len(names)))] = np.nan
    for name in settings.long_gap_markers:
        if name in names and n > settings.long_gap_frames + 20:
            start = int(rng.integers(10, n - settings.long_gap_frames - 10))
            X[start : start + settings.long_gap_frames, names.index(name)] = np.nan
    return X


def _stance_fraction(stance: np.ndarray) -> np.ndarray:
    """Fraction of the stance run (0 at its first sample, -> 1 at its end) per sample; 0 outside stance."""
    u = np.zeros(stance.size)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], stance.astype(np.int8), [0]])))
    for start, stop in zip(edges[::2], edges[1::2]):
        u[start:stop] = np.arange(stop - start) / (stop - start)
    return u


def _belt_channels(plates, X_exact, names, frame_t, analog_t, force_by_side, settings, rng, noise_sd_n):
    """Per side: bridge channels (n, 6), decoy channels (n, 6), true force (n, 3), COP (n, 3, NaN in swing)."""
    out = {}
    for i, (side, plate) in enumerate(zip(SIDES, plates)):
        fx, fz, stance = force_by_side[side]
        heel, toe = (X_exact[:, names.index(m)] for m in settings.foot_markers[i])
        at = [np.column_stack([np.interp(analog_t, frame_t, p[:, k]) for k in range(2)]) for p in (heel, toe)]
        u = _stance_fraction(stance)
        _, centre = plate_frame(plate)
        cop = np.tile(centre, (analog_t.size, 1))
        xy = at[0] + settings.cop_roll_fraction * u[:, None] * (at[1] - at[0])
        cop[stance, :2] = xy[stance]
        cop[:, 2] = centre[2]
        fy = rng.normal(0.0, noise_sd_n, analog_t.size) if noise_sd_n > 0 else np.zeros(analog_t.size)
        force = np.column_stack([fx, fy, fz])
        rest_f = np.asarray(settings.resting_force_n[i], float)
        rest_m = np.asarray(settings.resting_moment_nm[i], float)
        bridge = plate_channels(plate, force, cop) + wrench_channels(plate, rest_f, rest_m)
        moment = np.cross(cop - centre, force) + rest_m
        decoy = np.column_stack([(force + rest_f) * settings.decoy_v_per_n, moment * settings.decoy_v_per_nm])
        out[side] = (bridge, decoy, force, np.where(stance[:, None], cop, np.nan), rest_f, rest_m)
    return out


def _assemble(
    model_names, X, X_exact, coords, trial_force, sync_v, label_map, lab, settings, rng, source, events
) -> LabExport:
    rate = lab.marker_rate_hz
    n = X.shape[0]
    frame_t = np.arange(n) / rate
    n_a = n * round(lab.analog_rate_hz / rate)
    analog_t = np.arange(n_a) / lab.analog_rate_hz
    labels, units, scales, offsets, chans = _channel_layout(settings, lab.sync_channel)
    plates = treadmill_platforms(settings, chans)
    belts = _belt_channels(
        plates, X_exact, model_names, frame_t, analog_t, trial_force, settings, rng, lab.grf_noise_sd_n
    )
    columns = [np.column_stack([belts[s][0], belts[s][1]]) for s in SIDES]
    analogs = np.column_stack([*columns, sync_v[:n_a]])
    t0 = settings.first_frame / rate
    recording = C3DRecording(
        source=source,
        marker_labels=[settings.subject_prefix + label_map[m] for m in model_names],
        markers_m=X,
        point_rate_hz=rate,
        first_frame=settings.first_frame,
        analog_labels=labels,
        analog_units=units,
        analogs=analogs,
        analog_rate_hz=lab.analog_rate_hz,
    )
    return LabExport(
        recording=recording,
        force_platforms=plates,
        analog_scales=scales,
        analog_offsets=offsets,
        events=events,
        coordinates=coords.assign(time_s=t0 + frame_t),
        force_n={s: belts[s][2] for s in SIDES},
        cop_m={s: belts[s][3] for s in SIDES},
        resting_force_n={s: belts[s][4] for s in SIDES},
        resting_moment_nm={s: belts[s][5] for s in SIDES},
    )


def qtm_walking_export(
    model,
    trial: WalkingTrial,
    label_map: Mapping[str, str],
    body_mass_kg: float,
    lab: LabSettings,
    seed,
    settings: QTMExportSettings = QTMExportSettings(),
    source: str = "walking trial",
) -> LabExport:
    """The QTM-style C3D contents of a simulated walking trial (module docstring).

    Parameters
    ----------
    model : opensim.Model
        gait2392 (or a scaled copy) carrying the markers of ``label_map``.
    trial : WalkingTrial
        From :func:`loper_analysis.synthetic.trials.simulate_walking_trial`.
    label_map : mapping of str to str
        Model marker -> lab label (without prefix); the markers exported, in order.
    body_mass_kg : float
        Sets the ground reaction force (:func:`~loper_analysis.synthetic.treadmill.treadmill_grf`).
    lab : LabSettings
        Rates, noise, the robot clock (sync channel) and the lab rotation.
    seed : int or numpy.random.SeedSequence
    settings : QTMExportSettings
    """
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    marker_seed, grf_seed, plate_seed = ss.spawn(3)
    coords = gait2392_coordinates(trial.mocap_coordinates(lab.marker_rate_hz))
    X_exact, names, offset = _lab_markers(model, coords, label_map, lab, settings)
    coords["pelvis_ty"] += offset
    X = _noise_and_gaps(X_exact, names, lab, settings, np.random.default_rng(marker_seed), gaps=True)
    grf = trial.mocap_grf(body_mass_kg, lab, np.random.default_rng(grf_seed))
    n_a = X.shape[0] * round(lab.analog_rate_hz / lab.marker_rate_hz)
    if len(grf) < n_a:
        raise LoperInputError(
            f"{source}: {len(grf)} force samples for {X.shape[0]} frames; choose a duration that is "
            f"a whole number of frames"
        )
    grf = grf.iloc[:n_a]
    forces = {
        s: (
            grf[f"fx_{s}_n"].to_numpy(float),
            grf[f"fz_{s}_n"].to_numpy(float),
            ~np.isnan(grf[f"cop_x_{s}_m"].to_numpy(float)),
        )
        for s in SIDES
    }
    sync_v = trial.sync_v(grf["time_s"].to_numpy(float), lab)
    t0 = settings.first_frame / lab.marker_rate_hz
    events = []
    if settings.with_events:
        events = [
            (_CONTEXT[r.side], _EVENT_LABEL[r.event], t0 + float(r.time_s)) for r in trial.mocap_events().itertuples()
        ]
    return _assemble(
        names,
        X,
        X_exact,
        coords,
        forces,
        sync_v,
        label_map,
        lab,
        settings,
        np.random.default_rng(plate_seed),
        source,
        events,
    )


def qtm_static_export(
    model,
    label_map: Mapping[str, str],
    body_mass_kg: float,
    duration_s: float,
    lab: LabSettings,
    seed,
    *,
    settings: QTMExportSettings = QTMExportSettings(),
    pelvis_ty_m: float = 0.95,
    source: str = "static trial",
) -> LabExport:
    """A static trial: standing with every joint at 0, half the body weight on each belt under mid-foot,
    markers with noise and no gaps, the sync channel flat at 0, no events."""
    n = round(duration_s * lab.marker_rate_hz)
    if n < 2:
        raise LoperInputError(f"static trial of {duration_s} s has fewer than 2 frames")
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    marker_seed, plate_seed = ss.spawn(2)
    still = pd.DataFrame({ours: np.zeros(n) for ours, _ in GAIT2392_COORDINATES.values()})
    coords = gait2392_coordinates(still.assign(pelvis_ty=pelvis_ty_m))
    X_exact, names, offset = _lab_markers(model, coords.iloc[:1], label_map, lab, settings)
    X_exact = np.repeat(X_exact, n, axis=0)
    coords["pelvis_ty"] += offset
    X = _noise_and_gaps(X_exact, names, lab, settings, np.random.default_rng(marker_seed), gaps=False)
    n_a = n * round(lab.analog_rate_hz / lab.marker_rate_hz)
    rng = np.random.default_rng(plate_seed)
    half_weight = 0.5 * body_mass_kg * GRAVITY_M_PER_S2
    forces = {
        s: (
            rng.normal(0.0, lab.grf_noise_sd_n, n_a),
            half_weight + rng.normal(0.0, lab.grf_noise_sd_n, n_a),
            np.ones(n_a, dtype=bool),
        )
        for s in SIDES
    }
    return _assemble(
        names,
        X,
        _mid_foot(X_exact, names, settings),
        coords,
        forces,
        np.zeros(n_a),
        label_map,
        lab,
        replace(settings, cop_roll_fraction=0.0),
        rng,
        source,
        [],
    )


def _mid_foot(X_exact: np.ndarray, names: list[str], settings: QTMExportSettings) -> np.ndarray:
    """Markers with each heel marker moved halfway to its toe marker (the COP of a standing foot)."""
    X = X_exact.copy()
    for heel, toe in settings.foot_markers:
        X[:, names.index(heel)] = 0.5 * (X_exact[:, names.index(heel)] + X_exact[:, names.index(toe)])
    return X
