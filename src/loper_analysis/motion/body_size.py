"""The subject's body mass and height for scaling: given, from the static trial's force plates, or from the
file's ``PROCESSING`` parameters, each with where it came from; and the scaled model's stature against them.

* :func:`body_mass_kg` - the sheet's mass, else the plates' weight (:func:`standing_mass_kg`) when both feet
  stand on loaded plates (:func:`markers_off_plates`), else ``PROCESSING:Bodymass`` with the reason, else a
  stop asking for ``mass_kg``;
* :func:`standing_mass_kg` - body mass from the force plates the subject stands on: mean total vertical force
  of the loaded plates over the window, each above its resting level, divided by gravity;
* :func:`standing_plates` - each plate's resting level (where the trial shows it) and whether it carries the
  subject in the window;
* :func:`markers_off_plates` - the foot markers (those near the floor) not over a loaded plate: a subject with
  a foot beside the plates weighs less on them than their mass;
* :func:`body_height_m` - the sheet's height, else ``PROCESSING:Height`` (mm, as Nexus writes it), else the
  scaled model's stature;
* :func:`model_height_m` - stature estimated from a scaled model: the hip joint centre's height above the
  lowest marker in the default pose, over Winter's ratio of that height to stature (0.530);
* :func:`require_stature` - a scaled model whose stature differs from a given height by more than
  :data:`loper_analysis.motion.scale_report.STOP_STATURE_CHANGE` is another subject's.

Arrays and recordings in (read by the file layer), SI units.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence

import numpy as np

from loper_analysis.checks import where
from loper_analysis.constants import GRAVITY_M_PER_S2, LOADED_THRESHOLD_N, MAX_RESTING_N, RESTING_BAND_N
from loper_analysis.errors import LoperInputError
from loper_analysis.swing_leg.anthropometry import ANKLE_HEIGHT_FRACTION, WINTER_SEGMENTS

__all__ = [
    "FOOT_MARKER_HEIGHT_M",
    "HIP_HEIGHT_FRACTION",
    "MASS_LIMIT_KG",
    "MASS_RANGE_KG",
    "PLATE_EDGE_MARGIN_M",
    "body_height_m",
    "body_mass_kg",
    "markers_off_plates",
    "model_height_m",
    "model_stature_m",
    "require_stature",
    "standing_mass_kg",
    "standing_plates",
]

#: A given or stored body mass must lie in (0, this] kg.
MASS_LIMIT_KG: float = 300.0
#: Where a height estimated from the scaled model is said to come from.
_ESTIMATED = "estimated from the scaled model"
#: Hip joint centre height over stature (Winter's table: thigh + shank + ankle height).
HIP_HEIGHT_FRACTION: float = WINTER_SEGMENTS["thigh"].length + WINTER_SEGMENTS["shank"].length + ANKLE_HEIGHT_FRACTION
#: Body masses a standing subject may have (kg): outside, the plates or their units are wrong.
MASS_RANGE_KG: tuple[float, float] = (20.0, 300.0)
#: Markers lower than this over the plates' surface (m) are taken for foot markers (heel, toe, malleoli).
FOOT_MARKER_HEIGHT_M: float = 0.15
#: A foot marker this far (m) beyond a plate's edge still counts as over the plate (a heel marker sits behind
#: the heel).
PLATE_EDGE_MARGIN_M: float = 0.03
#: Relative SD of the total vertical force above which a "standing" subject is not standing still.
_MAX_FORCE_CV = 0.1
#: Percentile of a plate's vertical force taken as its lowest level (as the grf step's resting level).
_FLOOR_PERCENTILE = 1.0


def body_mass_kg(
    mass_kg: float | None,
    recording=None,
    plates: Sequence = (),
    window: tuple[float, float] = (0.0, 0.0),
    up=(0.0, 0.0, 1.0),
    gravity_m_per_s2: float = GRAVITY_M_PER_S2,
) -> tuple[float, str]:
    """The subject's mass (kg) and where it came from.

    Parameters
    ----------
    mass_kg : float or None
        The subject sheet's mass; None: from the static trial.
    recording : loper_analysis.io.c3d.C3DRecording, optional
        The static trial (its markers in m, lab frame; its ``processing``).
    plates : sequence of loper_analysis.io.force_platforms.ForcePlatform
        Its force platforms (lab frame, N).
    window : (float, float)
        The scaling window (s).
    up : array_like
        Shape (3,): the lab's up direction.
    gravity_m_per_s2 : float
        The model's gravity.
    """
    if mass_kg is not None:
        if not 0 < mass_kg <= MASS_LIMIT_KG:
            raise LoperInputError(f"mass_kg must lie in 0 .. {MASS_LIMIT_KG:g} kg, got {mass_kg}")
        return float(mass_kg), "given"
    if recording is None:
        raise LoperInputError(
            "no body mass: give mass_kg (subject sheet), or a static trial that stands on force plates"
        )
    if not plates:
        return _file_bodymass(recording, "the static trial has no force platforms (FORCE_PLATFORM:USED 0)")
    u = np.asarray(up, float) / np.linalg.norm(up)
    vertical = np.column_stack([p.force_n @ u for p in plates])
    _, carrying = standing_plates(plates[0].time_s, vertical, window)
    loaded = [p for p, on in zip(plates, carrying, strict=True) if on]
    off = _feet_off_plates(recording, plates, loaded, window, u)
    if off:
        return _file_bodymass(recording, off)
    mass = standing_mass_kg(plates[0].time_s, vertical, window, gravity_m_per_s2, source=recording.source)
    return mass, _plates_source([p.number for p in plates], carrying, _name(recording))


def body_height_m(height_m: float | None, processing: Mapping[str, float], stature_m: float, file_name: str):
    """The subject's height (m) and where it came from: ``height_m`` given, ``processing["Height"]`` (mm) of the
    file ``file_name``, or the scaled model's ``stature_m``
    (:func:`model_height_m`)."""
    if height_m is not None:
        return float(height_m), "given"
    height_mm = processing.get("Height")
    if height_mm is not None and 500 <= height_mm <= 2500:
        return height_mm / 1000.0, f"PROCESSING:Height of {file_name}"
    return float(stature_m), _ESTIMATED


def require_stature(height: tuple[float, str], stature_m: float, source: str) -> None:
    """Refuse a scaled model whose stature (m) differs from a height given (sheet or file; ``height`` as
    :func:`body_height_m` returns it) by more than
    :data:`loper_analysis.motion.scale_report.STOP_STATURE_CHANGE`: another subject's static trial."""
    from loper_analysis.motion.scale_report import STOP_STATURE_CHANGE, stature_change

    if height[1] == _ESTIMATED:
        return
    change = stature_change(height[0], stature_m)
    if np.isfinite(change) and abs(change) > STOP_STATURE_CHANGE:
        raise LoperInputError(
            f"{source}: the model scaled to this static trial stands {stature_m:.2f} m tall where the "
            f"subject's height is {height[0]:.2f} m ({height[1]}; {100 * change:+.0f} %, more than "
            f"{100 * STOP_STATURE_CHANGE:.0f} %): is the static trial this subject's, and the height in the "
            "subject sheet (height_m) right?"
        )


def model_stature_m(scaled, segment_bodies=None) -> float:
    """A scaled model's stature (m; :func:`model_height_m` of its right thigh,
    the bodies named by ``segment_bodies`` as :func:`loper_analysis.motion.segments.segment_body_names` takes
    them)."""
    from loper_analysis.motion.segments import segment_body_names

    return model_height_m(scaled, segment_body_names(scaled, "r", segment_bodies)["thigh"][0])


def _name(recording) -> str:
    return str(recording.source).replace("\\", "/").rsplit("/", 1)[-1]


def _file_bodymass(recording, why: str) -> tuple[float, str]:
    """The file's ``PROCESSING:Bodymass`` (kg) when its plates cannot weigh the subject (``why``), with where it
    came from; a stop asking for ``mass_kg`` without it."""
    bodymass = recording.processing.get("Bodymass")
    if bodymass is not None and 0 < bodymass <= MASS_LIMIT_KG:
        return float(bodymass), f"PROCESSING:Bodymass of {_name(recording)} ({why})"
    raise LoperInputError(
        f"{recording.source}: no body mass: {why}, and the file has no PROCESSING:Bodymass; give mass_kg in the "
        "subject sheet"
    )


def _plates_source(numbers, carrying, file_name: str) -> str:
    """Where a mass from the plates came from: the loaded plates (``carrying``) of the file, the others left out."""
    on = [str(n) for n, c in zip(numbers, carrying, strict=True) if c]
    off = [str(n) for n, c in zip(numbers, carrying, strict=True) if not c]
    source = f"force plate{'s' if len(on) > 1 else ''} {', '.join(on)} of {file_name}"
    return f"{source} ({', '.join(off)} unloaded)" if off else source


def _feet_off_plates(recording, plates, loaded, window, up: np.ndarray) -> str:
    """Why the plates do not weigh the whole subject ('' when they do): foot markers of the static trial's mean
    pose over none of the ``loaded`` plates (:func:`markers_off_plates`)."""
    floor = float(np.mean([p.corners_m @ up for p in plates]))
    frames = (recording.time_s >= window[0] - 1e-9) & (recording.time_s <= window[1] + 1e-9)
    if not frames.any() or not len(recording.marker_labels):
        return ""
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a marker missing throughout: NaN, skipped
        pose = np.nanmean(recording.markers_m[frames], axis=0)
    _, off = markers_off_plates(pose, recording.marker_labels, [p.corners_m for p in loaded], up, floor)
    if not off:
        return ""
    numbers = ", ".join(str(p.number) for p in loaded) or "none"
    return (
        f"the plates do not carry the whole subject: foot markers {', '.join(off)} (lower than "
        f"{FOOT_MARKER_HEIGHT_M} m) stand beside the loaded plates ({numbers}) in the scaling window"
    )


def standing_mass_kg(
    time_s,
    vertical_force_n,
    window_s: tuple[float, float],
    gravity_m_per_s2: float = GRAVITY_M_PER_S2,
    source: str = "",
) -> float:
    """Body mass (kg) of a subject standing on force plates: mean total vertical force over the window / g, the
    total over the plates that carry the subject, each above its resting level (:func:`standing_plates`).

    Parameters
    ----------
    time_s : array_like
        Shape (n_samples,), s: the plates' sample times.
    vertical_force_n : array_like
        Shape (n_samples,) or (n_samples, n_plates), N: vertical ground
        reaction of each plate (up positive), summed over the loaded plates.
    window_s : (float, float)
        The span averaged (s).
    gravity_m_per_s2 : float
        Gravity (m/s^2).

    Raises
    ------
    LoperInputError
        No sample in the window, a mass outside :data:`MASS_RANGE_KG` (plates
        not under the subject, or in another unit), or a force that varies by
        more than 10 % (SD over mean: the subject does not stand still on the
        plates).
    """
    t = np.asarray(time_s, dtype=float)
    F = np.asarray(vertical_force_n, dtype=float)
    F = F[:, None] if F.ndim == 1 else F
    rest, carrying = standing_plates(t, F, window_s)
    total = (F[:, carrying] - rest[carrying]).sum(axis=1)
    sel = (t >= window_s[0] - 1e-9) & (t <= window_s[1] + 1e-9) & np.isfinite(total)
    if not sel.any():
        raise LoperInputError(
            f"{where(source)}no force-plate sample in the window {window_s[0]:.4f} .. "
            f"{window_s[1]:.4f} s of the static trial"
        )
    mean = float(total[sel].mean())
    mass = mean / float(gravity_m_per_s2)
    lo, hi = MASS_RANGE_KG
    if not lo <= mass <= hi:
        raise LoperInputError(
            f"{where(source)}the force plates carry {mean:.1f} N on average in the static trial's window "
            f"({mass:.1f} kg), outside {lo:g} .. {hi:g} kg: does the subject stand on the plates? Give mass_kg in the "
            "subject sheet instead"
        )
    cv = float(total[sel].std()) / mean
    if cv > _MAX_FORCE_CV:
        raise LoperInputError(
            f"{where(source)}the total vertical force varies by {100 * cv:.0f} % (SD over mean) in the static trial's "
            f"window: the subject does not stand still on the plates; give mass_kg in the subject sheet instead"
        )
    return mass


def standing_plates(
    time_s, vertical_force_n, window_s: tuple[float, float], threshold_n: float = LOADED_THRESHOLD_N
) -> tuple[np.ndarray, np.ndarray]:
    """Each plate's resting level and whether it carries the subject over a static trial's window.

    Unloaded plates do not read zero (unzeroed plates read -14 .. -71 N at rest in real files): summed in, such
    a plate would change the mass by kilograms. A plate's resting level is measured where the trial shows the
    plate unloaded: its lowest level (1st percentile of its vertical force over the trial) within
    :data:`loper_analysis.constants.MAX_RESTING_N` (100 N, the default of the grf step's limit
    ``grf.max_resting_n``), the median of the samples within ``RESTING_BAND_N`` (10 N) of it, as
    :func:`loper_analysis.gait.grf.resting_level` takes it. A plate whose force stays above that
    level throughout is loaded throughout: its resting level cannot be measured and is taken as 0 (a plate
    zeroed before the trial). A plate carries the subject when its mean vertical force over the window exceeds
    its resting level by more than ``threshold_n``: the contact detection's 20 N, five times less than one foot
    of the lightest subject accepted (half of 20 kg, 98 N); a foot carrying less than 100 N throughout is taken
    for an unloaded plate (the feet-beside-the-plates check then names it).

    Parameters
    ----------
    time_s : array_like
        Shape (n_samples,), s: the plates' sample times.
    vertical_force_n : array_like
        Shape (n_samples, n_plates), N: each plate's vertical ground reaction (up positive).
    window_s : (float, float)
        The span averaged (s).
    threshold_n : float
        Load above the resting level from which a plate carries the subject (N).

    Returns
    -------
    rest_n : numpy.ndarray
        Shape (n_plates,), N: each plate's resting level (0 where not measurable).
    carrying : numpy.ndarray
        Shape (n_plates,), bool: the plates loaded over the window.
    """
    t = np.asarray(time_s, dtype=float)
    F = np.asarray(vertical_force_n, dtype=float).reshape(t.size, -1)
    in_window = (t >= window_s[0] - 1e-9) & (t <= window_s[1] + 1e-9)
    rest = np.zeros(F.shape[1])
    carrying = np.zeros(F.shape[1], dtype=bool)
    for j, v in enumerate(F.T):
        finite = np.isfinite(v)
        if not finite.any():
            continue
        floor = float(np.percentile(v[finite], _FLOOR_PERCENTILE))
        if abs(floor) <= MAX_RESTING_N:
            rest[j] = float(np.median(v[finite & (v <= floor + RESTING_BAND_N)]))
        window = v[in_window & finite]
        carrying[j] = window.size > 0 and float(window.mean()) - rest[j] > threshold_n
    return rest, carrying


def model_height_m(model, thigh_body: str) -> float:
    """Stature (m) of a scaled model: its hip joint centre's height over its lowest marker /
    :data:`HIP_HEIGHT_FRACTION`.

    ``model`` is an ``opensim.Model`` in its default pose; ``thigh_body``
    the thigh (femur) body, whose origin is the hip joint centre (gait2392,
    Rajagopal2016 and the generated model). The vertical is the model's Y.
    NaN for a model without markers.
    """
    state = model.initSystem()
    hip = model.getBodySet().get(thigh_body).getPositionInGround(state).to_numpy()
    markers = model.getMarkerSet()
    heights = [markers.get(i).getLocationInGround(state).to_numpy()[1] for i in range(markers.getSize())]
    if not heights:
        return float("nan")
    return float((hip[1] - min(heights)) / HIP_HEIGHT_FRACTION)


def markers_off_plates(
    markers_m,
    labels: Sequence[str],
    corners_m: Sequence,
    up,
    floor_m: float,
    max_height_m: float = FOOT_MARKER_HEIGHT_M,
    margin_m: float = PLATE_EDGE_MARGIN_M,
) -> tuple[list[str], list[str]]:
    """The foot markers of a standing pose and those of them that are over none of the given plates.

    Parameters
    ----------
    markers_m : array_like
        Shape (n_markers, 3), m, lab frame: the pose (NaN: marker missing).
    labels : sequence of str
        The markers' names.
    corners_m : sequence of array_like
        Each loaded plate's four corners, shape (4, 3), m, lab frame, around its outline.
    up : array_like
        Shape (3,): the lab's up direction.
    floor_m : float
        Height of the plates' surface along ``up`` (m).
    max_height_m, margin_m : float
        Height over the plates' surface below which a marker is a foot marker (m); distance beyond a plate's
        edge still counted as over it (m).

    Returns
    -------
    (list of str, list of str)
        The foot markers; those over no plate (empty: the subject stands on the plates with both feet).
    """
    X = np.asarray(markers_m, float)
    u = np.asarray(up, float) / np.linalg.norm(up)
    plates = [np.asarray(c, float) for c in corners_m]
    e1 = np.cross(u, [1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.cross(u, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u, e1)

    def flat(p):
        return np.stack([p @ e1, p @ e2], axis=-1)

    feet, off = [], []
    for name, x in zip(labels, X, strict=True):
        if not np.all(np.isfinite(x)) or x @ u - floor_m > max_height_m:
            continue
        feet.append(name)
        if not any(_inside(flat(x), flat(c), margin_m) for c in plates):
            off.append(name)
    return feet, off


def _inside(point, polygon, margin: float) -> bool:
    """Whether a 2-D point lies inside a convex polygon (either winding) or within ``margin`` of its edges."""
    n = len(polygon)
    edges = [(polygon[i], polygon[(i + 1) % n]) for i in range(n)]
    sides = []
    for a, b in edges:
        d = b - a
        sides.append((d[0] * (point[1] - a[1]) - d[1] * (point[0] - a[0])) / np.linalg.norm(d))
    sides = np.asarray(sides)
    centre = polygon.mean(axis=0)
    inward = np.sign([(b - a)[0] * (centre[1] - a[1]) - (b - a)[1] * (centre[0] - a[0]) for a, b in edges])
    return bool(np.all(sides * inward >= -margin))
