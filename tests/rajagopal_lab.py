"""OpenSim's Rajagopal2016 walking subject (``tests/data/rajagopal2016/``) as a gait lab's C3D files, and
OpenSim's own scaling and inverse kinematics of it as references.

:func:`write_lab_files` writes the subject's static and walking trials the way a Vicon lab exports them;
:func:`opensim_scale_reference` and :func:`opensim_ik_reference` run OpenSim's ``ScaleTool`` and
``InverseKinematicsTool`` with the subject's own setups. ``tests/data/rajagopal2016/README.md`` describes
the source files.

Lab files (:func:`write_lab_files`)
    * Lab frame Z up: a point ``(x, y, z)`` of OpenSim's Y-up frame is ``(x, -z, y)`` in the lab
      (:data:`MODEL_TO_LAB`), so that the lab-to-model rotation ``(-90, 0, 0)``
      (:func:`loper_analysis.motion.markers.rotate_markers`) gives the TRC's coordinates back.
    * Markers: the TRC's, in mm, labelled ``<subject_prefix><TRC name>`` (``Subject11:R.ASIS``); a marker
      missing (NaN) in the TRC is missing in the file. Frames keep the TRC's clock: ``first_frame`` is
      ``round(t0 * rate)`` with ``t0`` the TRC's first time.
    * Force platforms of TYPE 2 (channels ``Fx<k> Fy<k> Fz<k>`` in N and ``Mx<k> My<k> Mz<k>`` in N·mm
      about the sensor origin :data:`SENSOR_ORIGIN_M`, 40 mm below the surface), each a rectangle on the
      floor (lab z = 0), x axis along lab +x, y along lab -y, z down, as Vicon's plates.
    * ``walk-nodevice.c3d``: the walking TRC (100 Hz) with analogs at 2000 Hz (20 per frame) from the
      GRF ``.mot``, one plate per stance phase (an overground walkway: each foot contact on its own
      plate, numbered by the time of the contact). A plate is the rectangle around its stance's
      centre-of-pressure path with ``plate_margin_m`` on every side, kept to its foot's side of the
      line (along the walking direction, lab x) midway between the right and the left feet's paths,
      :data:`PLATE_GAP_M` from it: no plate reaches under the other foot, which also stands on the
      floor off the plates (the left foot before 0.4 s and after 2.0 s, with no force in the .mot).
      During its stance a plate holds the .mot's force, centre of pressure and free torque of that
      foot; outside its stance only its unloaded level (``unloaded_force_n``, a constant vertical
      force on the body: the plates are not zeroed, as in many real files; 0 gives zeroed plates).
    * ``static.c3d``: the static TRC (100 Hz) with analogs at 1000 Hz (10 per frame); plate 1 under the
      right foot, plate 2 under the left, each the rectangle around that foot's markers (heel, ankle,
      MT5, toe over all frames, projected on the floor) with ``plate_margin_m`` (they do not overlap).
      The plates are zeroed and loaded throughout with a vertical force of :data:`STATIC_RIGHT_SHARE`
      (right) and the rest (left) of ``mass_kg`` times :data:`STANDARD_GRAVITY_M_PER_S2`, at a fixed
      centre of pressure per foot (the mean of its heel, MT5 and toe markers on the floor), no free
      moment.
    * Same inputs, same bytes (:func:`loper_analysis.io.c3d_writer.write_c3d` is deterministic).

The GRF ``.mot`` (measured; README): force on the body in N, centre of pressure in **m** (the rows where a
foot's force is 0 hold meaningless COP values such as 346), free torque about the vertical in N·m
(``ground_torque_*_y``; its x and z are 0), all in OpenSim's frame with the floor at y = 0; forces below
5 N are set to 0 in the file.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from loper_analysis.io.c3d_writer import ForcePlatform, write_c3d
from loper_analysis.io.opensim_tables import read_markers, read_mot
from loper_analysis.io.osim import quiet_opensim
from tests.force_plate_channels import plate_channels, wrench_channels

DATA = Path(__file__).resolve().parent / "data" / "rajagopal2016"
GENERIC_OSIM = DATA / "Rajagopal2016.osim"
SCALE_SETUP = DATA / "Rajagopal_scale_setup_walk.xml"
IK_SETUP = DATA / "Rajagopal_ik_setup_walk.xml"
#: The marker set of OpenSim's pipeline (TRC marker names); Rajagopal2016.osim's own markers have other names.
MARKER_SET = DATA / "Rajagopal_markerset_walk_preScale.xml"
STATIC_TRC = DATA / "Rajagopal_static_walk_2.trc"
WALK_TRC = DATA / "Rajagopal_motion_capture_walk.trc"
GRF_MOT = DATA / "Rajagopal_grf_walk.mot"

#: Lab files written by :func:`write_lab_files`, without the ``.c3d`` suffix.
STATIC_TRIAL = "static"
WALK_TRIAL = "walk-nodevice"
#: Standard gravity (m/s²) of the static plates' load (Rajagopal2016.osim's gravity).
STANDARD_GRAVITY_M_PER_S2 = 9.80665
#: The subject's mass (kg) in OpenSim's pipeline; the walking forces over a full gait cycle agree (833 N).
SUBJECT_MASS_KG = 85.0668
#: Markers missing in the first frames of the lab's static trial, as labs record them (the subject settles:
#: knee markers hidden for 10 frames, the toes for 3); the TRC itself is complete.
STATIC_GAPS = {"R.Knee": 10, "L.Knee": 10, "R.Toe": 3, "L.Toe": 3}
#: lab = MODEL_TO_LAB @ model: OpenSim's Y-up (x, y, z) is the Z-up lab's (x, -z, y).
MODEL_TO_LAB = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
WALK_ANALOG_RATE_HZ = 2000.0
STATIC_ANALOG_RATE_HZ = 1000.0
#: ``FORCE_PLATFORM:ORIGIN`` of every plate (m, plate frame): sensor origin 40 mm below the surface centre.
SENSOR_ORIGIN_M = (0.001, -0.002, -0.040)
#: Gap between the plates of the right and of the left foot on a walkway (m).
PLATE_GAP_M = 0.005
#: Share of the body weight on the right foot's plate in the static trial.
STATIC_RIGHT_SHARE = 0.52
#: Foot markers (TRC names without the side prefix) that outline a foot in the static trial.
FOOT_MARKERS = ("Heel", "Ankle", "MT5", "Toe")
#: Foot markers whose mean is the standing foot's centre of pressure.
STATIC_COP_MARKERS = ("Heel", "MT5", "Toe")
_SIDES = {"r": "R", "l": "L"}


@dataclass(frozen=True)
class Stance:
    """One foot contact of the GRF .mot, on the lab's clock and in the lab frame.

    ``start``/``stop`` index the analog samples written (``stop`` exclusive); ``force_n``, ``cop_m`` (n, 3)
    and ``free_moment_nm`` (n,) are the .mot's values over them (force on the body, N; COP on the floor,
    m; torque about lab +Z, N·m).
    """

    side: str
    start: int
    stop: int
    force_n: np.ndarray
    cop_m: np.ndarray
    free_moment_nm: np.ndarray


def model_to_lab(points) -> np.ndarray:
    """Points (..., 3) of OpenSim's Y-up frame in the Z-up lab frame (NaN stays NaN)."""
    return np.asarray(points, dtype=float) @ MODEL_TO_LAB.T


def _frame_rate_hz(time_s: np.ndarray, source: Path) -> float:
    step = np.diff(time_s)
    rate = float(round(1.0 / np.median(step)))
    if not np.allclose(step, 1.0 / rate, rtol=0, atol=1e-6):
        raise ValueError(f"{source}: frames are not evenly spaced at {rate:g} Hz")
    return rate


def _first_frame(t0: float, rate: float, source: Path) -> int:
    first = round(t0 * rate)
    if abs(first / rate - t0) > 1e-9:
        raise ValueError(f"{source}: first time {t0} s is not a whole frame at {rate:g} Hz")
    return first


def walking_stances(grf_mot=GRF_MOT, walk_trc=WALK_TRC) -> tuple[list[Stance], int]:
    """The stance phases of the GRF .mot over the walking TRC's frames, in order of their start.

    The .mot (2000 Hz, rows at ``k / 2000`` s from 0) is cropped to the TRC's frames: sample 0 is the row
    at the TRC's first time, and ``n_frames * 20`` samples are kept (the last .mot rows, after the TRC's
    last frame plus 19 samples, are dropped; in this file they carry no force). A stance is a run of
    rows where that foot's vertical force is not 0. Returns the stances and the number of samples.
    """
    time_s, markers, _ = read_markers(walk_trc)
    ratio = round(WALK_ANALOG_RATE_HZ / _frame_rate_hz(time_s, Path(walk_trc)))
    grf = read_mot(grf_mot)
    t = grf["time_s"].to_numpy()
    if not np.allclose(np.diff(t), 1.0 / WALK_ANALOG_RATE_HZ, rtol=0, atol=1e-9):
        raise ValueError(f"{grf_mot}: rows are not evenly spaced at {WALK_ANALOG_RATE_HZ:g} Hz")
    first = int(np.argmin(np.abs(t - time_s[0])))
    n = markers.shape[0] * ratio
    if abs(t[first] - time_s[0]) > 1e-9 or first + n > t.size:
        raise ValueError(f"{grf_mot}: does not cover the {markers.shape[0]} frames of {walk_trc}")
    rows = grf.iloc[first : first + n]
    stances = []
    for s in _SIDES:
        col = {q: rows[f"ground_force_{s}_{q}"].to_numpy() for q in ("vx", "vy", "vz", "px", "py", "pz")}
        torque = np.column_stack([rows[f"ground_torque_{s}_{q}"].to_numpy() for q in "xyz"])
        loaded = col["vy"] != 0.0
        edges = np.flatnonzero(np.diff(np.concatenate([[0], loaded.astype(int), [0]])))
        for a, b in zip(edges[::2], edges[1::2]):
            if np.any(torque[a:b, [0, 2]] != 0.0) or np.any(np.abs(col["py"][a:b]) > 1e-9):
                raise ValueError(f"{grf_mot}: foot {s} holds a horizontal torque or a COP off the floor y = 0")
            force = model_to_lab(np.column_stack([col["vx"], col["vy"], col["vz"]])[a:b])
            cop = model_to_lab(np.column_stack([col["px"], col["py"], col["pz"]])[a:b])
            stances.append(Stance(_SIDES[s], int(a), int(b), force, cop, torque[a:b, 1].copy()))
    return sorted(stances, key=lambda st: st.start), n


def _floor_plates(boxes: list[np.ndarray]) -> list[ForcePlatform]:
    """TYPE-2 plates on the floor (z = 0) over the rectangles ``[[xmin, ymin], [xmax, ymax]]`` (lab, m), channels
    numbered on from 1 (six per plate); refuses rectangles that overlap."""
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            if np.all(boxes[i][0] < boxes[j][1]) and np.all(boxes[j][0] < boxes[i][1]):
                raise ValueError(f"plates {i + 1} and {j + 1} would overlap")
    plates = []
    for k, ((x0, y0), (x1, y1)) in enumerate(boxes):
        corners = ((x1, y0, 0.0), (x0, y0, 0.0), (x0, y1, 0.0), (x1, y1, 0.0))  # plate x = lab +x, y = lab -y
        plates.append(ForcePlatform(2, corners, SENSOR_ORIGIN_M, tuple(range(6 * k + 1, 6 * k + 7))))
    return plates


def _channel_names(n_plates: int) -> tuple[list[str], list[str]]:
    labels = [f"{q}{k}" for k in range(1, n_plates + 1) for q in ("Fx", "Fy", "Fz", "Mx", "My", "Mz")]
    units = ["N", "N", "N", "Nmm", "Nmm", "Nmm"] * n_plates
    return labels, units


def walking_plates(stances: list[Stance], margin_m: float = 0.1) -> list[ForcePlatform]:
    """One TYPE-2 floor plate per stance: its centre-of-pressure path with ``margin_m`` on every side, kept to its
    foot's side of the line midway between the right and the left feet's paths (module notes)."""
    cops = {side: np.vstack([s.cop_m[:, :2] for s in stances if s.side == side]) for side in ("R", "L")}
    low, high = sorted(("R", "L"), key=lambda side: cops[side][:, 1].mean())  # the foot at the lower lab y first
    if cops[low][:, 1].max() >= cops[high][:, 1].min():
        raise ValueError("the right and left centre-of-pressure paths are not apart across the walking direction")
    mid = 0.5 * (cops[low][:, 1].max() + cops[high][:, 1].min())
    boxes = []
    for s in stances:
        box = np.array([s.cop_m[:, :2].min(axis=0) - margin_m, s.cop_m[:, :2].max(axis=0) + margin_m])
        if s.side == low:
            box[1, 1] = min(box[1, 1], mid - 0.5 * PLATE_GAP_M)
        else:
            box[0, 1] = max(box[0, 1], mid + 0.5 * PLATE_GAP_M)
        boxes.append(box)
    return _floor_plates(boxes)


def _write_walk(path: Path, prefix: str, margin_m: float, unloaded_force_n: float) -> Path:
    time_s, markers, names = read_markers(WALK_TRC)
    rate = _frame_rate_hz(time_s, WALK_TRC)
    stances, n = walking_stances()
    plates = walking_plates(stances, margin_m)
    columns = []
    for plate, st in zip(plates, stances):
        centre = np.mean(plate.corners_m, axis=0)
        force, cop, free = np.zeros((n, 3)), np.tile(centre, (n, 1)), np.zeros(n)
        stance = slice(st.start, st.stop)
        force[stance], cop[stance], free[stance] = st.force_n, st.cop_m, st.free_moment_nm
        rest = wrench_channels(plate, [0.0, 0.0, unloaded_force_n], [0.0, 0.0, 0.0])
        columns.append(plate_channels(plate, force, cop, free) + rest)
    labels, units = _channel_names(len(plates))
    return write_c3d(
        path,
        [prefix + m for m in names],
        model_to_lab(markers),
        rate,
        labels,
        np.hstack(columns),
        units,
        WALK_ANALOG_RATE_HZ,
        point_unit="mm",
        first_frame=_first_frame(float(time_s[0]), rate, WALK_TRC),
        force_platforms=plates,
    )


def static_feet(static_trc=STATIC_TRC) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per foot (``"R"``, ``"L"``) of the static trial: the floor rectangle of its markers
    ``[[xmin, ymin], [xmax, ymax]]`` and its centre of pressure (3,), lab frame, m (module notes)."""
    _, markers, names = read_markers(static_trc)
    lab = model_to_lab(markers)
    feet = {}
    for side in ("R", "L"):
        outline = lab[:, [names.index(f"{side}.{m}") for m in FOOT_MARKERS], :2].reshape(-1, 2)
        cop = np.nanmean(lab[:, [names.index(f"{side}.{m}") for m in STATIC_COP_MARKERS], :2].reshape(-1, 2), axis=0)
        feet[side] = (np.array([np.nanmin(outline, axis=0), np.nanmax(outline, axis=0)]), np.append(cop, 0.0))
    return feet


def static_markers(static_trc=STATIC_TRC, gaps=STATIC_GAPS) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """The static trial's markers (OpenSim's frame, m) with each marker of ``gaps`` missing in its first frames."""
    time_s, markers, names = read_markers(static_trc)
    for name, n in (gaps or {}).items():
        markers[:n, names.index(name)] = np.nan
    return time_s, markers, names


def _write_static(path: Path, prefix: str, margin_m: float, mass_kg: float, static_trc: Path, gaps) -> Path:
    time_s, markers, names = static_markers(static_trc, gaps)
    rate = _frame_rate_hz(time_s, static_trc)
    n = markers.shape[0] * round(STATIC_ANALOG_RATE_HZ / rate)
    feet = static_feet(static_trc)
    plates = _floor_plates([feet[side][0] + [[-margin_m], [margin_m]] for side in ("R", "L")])
    weight_n = mass_kg * STANDARD_GRAVITY_M_PER_S2
    columns = []
    for plate, side, share in zip(plates, ("R", "L"), (STATIC_RIGHT_SHARE, 1.0 - STATIC_RIGHT_SHARE)):
        force = np.tile([0.0, 0.0, share * weight_n], (n, 1))
        columns.append(plate_channels(plate, force, feet[side][1]))
    labels, units = _channel_names(len(plates))
    return write_c3d(
        path,
        [prefix + m for m in names],
        model_to_lab(markers),
        rate,
        labels,
        np.hstack(columns),
        units,
        STATIC_ANALOG_RATE_HZ,
        point_unit="mm",
        first_frame=_first_frame(float(time_s[0]), rate, static_trc),
        force_platforms=plates,
    )


def write_lab_files(
    out_dir: str | os.PathLike,
    *,
    subject_prefix: str = "Subject11:",
    mass_kg: float = SUBJECT_MASS_KG,
    plate_margin_m: float = 0.1,
    unloaded_force_n: float = -6.0,
    static_trc: str | os.PathLike = STATIC_TRC,
    static_gaps=STATIC_GAPS,
) -> dict[str, Path]:
    """Write ``static.c3d`` and ``walk-nodevice.c3d`` of the Rajagopal2016 subject into ``out_dir`` (module notes).

    Parameters
    ----------
    out_dir : path
        Folder of the two files (created if missing).
    subject_prefix : str
        Put before every marker name (``""``: the TRC's names).
    mass_kg : float
        Subject mass whose weight the static plates carry, kg.
    plate_margin_m : float
        Plate edges beyond a stance's centre-of-pressure path (walking) or a foot's markers (static), m.
    unloaded_force_n : float
        Vertical force (lab Z, on the body) every walking plate reads at rest, N; 0: zeroed plates.
    static_trc : path
        The static trial's markers (default: the subject's); another TRC of the same subject, e.g. one
        with gaps, to test the gap policy.
    static_gaps : mapping of str to int
        Marker -> number of first frames of the static trial in which it is missing (:data:`STATIC_GAPS`;
        empty: as in the TRC).

    Returns
    -------
    dict
        ``{"static": path, "walk-nodevice": path}``.
    """
    out = Path(out_dir)
    return {
        STATIC_TRIAL: _write_static(
            out / f"{STATIC_TRIAL}.c3d", subject_prefix, plate_margin_m, mass_kg, Path(static_trc), static_gaps
        ),
        WALK_TRIAL: _write_walk(out / f"{WALK_TRIAL}.c3d", subject_prefix, plate_margin_m, unloaded_force_n),
    }


# ---------------------------------------------------------------- OpenSim's own tools


def opensim_scale_reference(
    generic_osim, setup_xml, static_trc, mass_kg: float, out_osim, *, marker_set_xml=None
) -> Path:
    """Run OpenSim's ``ScaleTool(setup_xml)`` as the setup stands; returns ``out_osim``.

    Kept from the setup: the scaling order, measurements and scale set, the time ranges, the marker
    placer's tasks and settings, its marker set file unless ``marker_set_xml`` is given. Set: the
    generic model, the static trial (model scaler and marker placer), the subject mass and the output
    model (the marker placer's when it applies, else the model scaler's); no other output file is
    written. All paths are made absolute (``setPathToSubject("")``).

    ``marker_set_xml`` replaces the setup's ``marker_set_file``: Rajagopal2016.osim's own markers
    (``RASI``, ...) are not the TRC's (``R.ASIS``, ...), and the setup names no marker set, so OpenSim's
    marker placer fails ("Model has no markers") unless :data:`MARKER_SET` is given here.

    Raises
    ------
    RuntimeError
        The tool fails or writes no model.
    """
    osim = quiet_opensim()
    out = Path(out_osim).resolve()
    tool = osim.ScaleTool(str(Path(setup_xml).resolve()))
    tool.setPathToSubject("")
    tool.setSubjectMass(float(mass_kg))
    maker = tool.getGenericModelMaker()
    maker.setModelFileName(str(Path(generic_osim).resolve()))
    if marker_set_xml is not None:
        maker.setMarkerSetFileName(str(Path(marker_set_xml).resolve()))
    scaler, placer = tool.getModelScaler(), tool.getMarkerPlacer()
    trc = str(Path(static_trc).resolve())
    scaler.setMarkerFileName(trc)
    placer.setMarkerFileName(trc)
    scaler.setOutputScaleFileName("Unassigned")
    placer.setOutputMotionFileName("Unassigned")
    placer.setOutputMarkerFileName("Unassigned")
    final, other = (placer, scaler) if placer.getApply() else (scaler, placer)
    final.setOutputModelFileName(str(out))
    other.setOutputModelFileName("Unassigned")
    try:
        ok = tool.run()
    except Exception as exc:  # OpenSim raises its own exception types
        raise RuntimeError(f"{setup_xml}: ScaleTool failed: {exc}") from exc
    if not ok or not out.is_file():
        raise RuntimeError(f"{setup_xml}: ScaleTool wrote no model {out}")
    return out


def ik_marker_errors_path(out_mot) -> Path:
    """The marker-error file :func:`opensim_ik_reference` leaves beside ``out_mot``."""
    out = Path(out_mot)
    return out.with_name(f"{out.stem}_ik_marker_errors.sto")


def opensim_ik_reference(model_osim, ik_setup_xml, trc, out_mot) -> pd.DataFrame:
    """Run OpenSim's ``InverseKinematicsTool(ik_setup_xml)`` on ``model_osim`` and the markers of ``trc``.

    Kept from the setup: its marker (and coordinate) tasks, time range, accuracy and constraint weight,
    error reporting. Set: the model, the marker file, the output motion ``out_mot`` and the results
    folder (``out_mot``'s; the per-frame marker errors go to :func:`ik_marker_errors_path`).

    Returns
    -------
    pandas.DataFrame
        ``time_s`` and one column per coordinate of the .mot, in file order: rad for the model's
        rotational coordinates (the file holds degrees, ``inDegrees=yes``), m for translational ones,
        and as written for the others. OpenSim writes in degrees only the coordinates of motion type
        ``Rotational``: Rajagopal2016's ``knee_angle_r_beta`` and ``knee_angle_l_beta`` (type
        ``Coupled``, equal to the knee angles through a coupler constraint) are in rad in that file,
        which :func:`loper_analysis.io.opensim_tables.read_mot` (degrees for every column but
        ``*_tx``, ``*_ty``, ``*_tz``) would divide by 57.3 once more.

    Raises
    ------
    RuntimeError
        The tool fails or writes no motion, the file does not declare ``inDegrees``, or a column is
        not a coordinate of the model.
    """
    osim = quiet_opensim()
    out = Path(out_mot).resolve()
    model = osim.Model(str(Path(model_osim).resolve()))  # kept alive while the tool runs
    tool = osim.InverseKinematicsTool(str(Path(ik_setup_xml).resolve()))
    tool.setName(out.stem)
    tool.setModel(model)
    tool.setMarkerDataFileName(str(Path(trc).resolve()))
    tool.setOutputMotionFileName(str(out))
    tool.setResultsDir(str(out.parent))
    try:
        ok = tool.run()
    except Exception as exc:  # OpenSim raises its own exception types
        raise RuntimeError(f"{ik_setup_xml}: InverseKinematicsTool failed: {exc}") from exc
    if not ok or not out.is_file():
        raise RuntimeError(f"{ik_setup_xml}: InverseKinematicsTool wrote no motion {out}")
    table = osim.TimeSeriesTable(str(out))
    if not table.hasTableMetaDataKey("inDegrees"):
        raise RuntimeError(f"{out}: the header does not declare inDegrees")
    in_degrees = table.getTableMetaDataAsString("inDegrees").strip().lower() == "yes"
    names = list(table.getColumnLabels())
    coordinates = model.getCoordinateSet()
    unknown = [n for n in names if not coordinates.contains(n)]
    if unknown:
        raise RuntimeError(f"{out}: columns {unknown} are not coordinates of {model_osim}")
    time_s = np.array(table.getIndependentColumn(), dtype=float)
    matrix = table.getMatrix()
    values = np.array(matrix.to_numpy(), dtype=float, copy=True).reshape(time_s.size, len(names))
    frame = {"time_s": time_s}
    for j, name in enumerate(names):
        rotational = coordinates.get(name).getMotionType() == osim.Coordinate.Rotational
        frame[name] = np.radians(values[:, j]) if in_degrees and rotational else values[:, j]
    return pd.DataFrame(frame)
