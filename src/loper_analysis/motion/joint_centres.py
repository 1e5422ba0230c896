"""Hip, knee and ankle joint centres of a static trial, from its markers, as clinical gait models compute them.

The subject calibration (:func:`loper_analysis.motion.scaling.scaling_pose`) places the model in the static trial
through these centres: they scale the segments (hip to hip, hip to knee, knee to ankle) and fix the static pose,
so that a standing subject comes out near neutral whatever the places of the lab's markers on the model.

* **Hip**, in the pelvis frame of the anterior and posterior superior iliac spines (origin between the anterior
  spines, ``z`` from the left to the right one, ``x`` forward in the plane of the spines, ``y`` up):

  - where the file stores the lab's leg lengths (a Plug-in Gait lab measures them for its model), Plug-in Gait's
    regression (Davis et al. 1991, Hum Mov Sci 10:575): the centres the lab's own model used, from the leg length,
    the distance from the anterior spine to the greater trochanter (stored, else Plug-in Gait's ``0.1288 leg length
    - 48.56 mm``), the distance between the spines (stored, else measured) and the marker radius, so that the
    angles compare with the lab's;
  - otherwise Harrington et al. (2007, J Biomech 40:595), on pelvic width and depth alone: ``x = -0.24 PD - 9.9
    mm``, ``y = -0.30 PW - 10.9 mm``, ``z = +-(0.33 PW + 7.3 mm)``, with ``PW`` the distance between the anterior
    spines and ``PD`` from their midpoint to the posterior spines' (or the sacrum marker).
* **Knee**, the first of: the midpoint of the lateral and medial epicondyle markers; a knee alignment device's
  origin moved along its axis (away from the axis marker ``KAX``) by half the knee width plus the marker radius
  (Plug-in Gait); the lateral marker moved by the same offset in the plane of the hip centre, the thigh wand and
  the lateral marker, at a right angle to the hip centre (Plug-in Gait's chord); without a wand, along the pelvis's
  medial axis.
* **Ankle**, likewise: the midpoint of the malleoli; the chord of the knee centre, the shank wand and the lateral
  malleolus with half the ankle width plus the marker radius; without a wand, along the pelvis's medial axis.

Three segments are not oriented by their centres alone: the pelvis turns about the line of its hip centres, the
femur about its own axis, the foot about the ankle's axis. Each gets a pair of virtual markers
:data:`DIRECTION_LEVER_M` either side of its centre: ``PELVIS_FRONT`` and ``PELVIS_BACK`` ahead of and behind the hips'
midpoint along the line from the posterior spines' midpoint (or the sacrum) to the anterior spines' (the pelvis's
forward axis); ``LKNEE_LAT`` and ``LKNEE_MED`` (and the right's) along the knee's flexion axis, the line from the
knee's centre to the lateral knee marker (the medial marker's line, the device's axis or the chord's, whichever
found the centre); ``LFOOT_UP`` and ``LFOOT_DOWN`` (and the
right's) above and below the ankle centre, as a foot stands flat on the floor in a static trial whatever the heights
of its heel and toe markers (Plug-in Gait's "foot flat"; the foot's turn about the vertical is left to the leg). On
the model the same lines are the template's posterior to anterior spines and the vertical of its default pose, in
which the foot stands flat (:func:`loper_analysis.motion.centre_markers.joint_centre_places`), so the segment's
orientation in the static pose is the one its landmarks give, however far the template's places lie from the
subject's. A pair, not one marker: the model's lever scales with its body, the trial's does not, and a pair's
mismatch pulls its centre no way.

Widths and lengths are the lab's measurements (Vicon Nexus stores ``LKneeWidth``, ``RAnkleWidth``, ``LLegLength``,
``LAsisTrocanterDistance``, ``InterAsisDistance`` and ``MarkerDiameter`` in mm in the C3D's ``PROCESSING`` group:
:func:`widths_from_processing`). Without one, the offset comes from the
model's own proportions (:data:`KNEE_OFFSET_PER_THIGH`, :data:`ANKLE_OFFSET_PER_SHANK`), and the method names it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from loper_analysis.constants import SIDES
from loper_analysis.errors import LoperInputError

__all__ = [
    "ANKLE_OFFSET_PER_SHANK",
    "DIRECTION_LEVER_M",
    "FOOT_DIRECTION",
    "KNEE_AXIS",
    "PELVIS_DIRECTION",
    "KNEE_OFFSET_PER_THIGH",
    "MARKER_DIAMETER_M",
    "JointCentres",
    "Landmarks",
    "chord_centre",
    "davis_hip_centres",
    "harrington_hip_centres",
    "static_joint_centres",
    "widths_from_processing",
]

#: Marker diameter when the file states none (m): Plug-in Gait's default, 14 mm.
MARKER_DIAMETER_M: float = 0.014
#: Without a knee width: the lateral knee marker's distance from the knee centre as a fraction of the hip centre to
#: lateral knee distance, gait2392's (lateral epicondyle 50 mm from the knee's centre, plus the 7 mm marker radius,
#: over its 396 mm femur).
KNEE_OFFSET_PER_THIGH: float = 0.057 / 0.396
#: Without an ankle width: likewise for the lateral malleolus over the knee centre to lateral malleolus distance
#: (gait2392: 53 mm plus 7 mm over its 430 mm tibia).
ANKLE_OFFSET_PER_SHANK: float = 0.060 / 0.430


#: Distance of a direction marker from its centre (m): long enough that an orientation weighs like the centres.
DIRECTION_LEVER_M: float = 0.1
#: The pelvis's direction markers, ahead of and behind the hips' midpoint.
PELVIS_DIRECTION: tuple[str, str] = ("PELVIS_FRONT", "PELVIS_BACK")
#: A foot's direction markers, above and below the ankle's centre, after the side's prefix ``L``/``R``.
FOOT_DIRECTION: tuple[str, str] = ("FOOT_UP", "FOOT_DOWN")
#: A knee's axis markers, lateral and medial of the knee's centre along its flexion axis, after the side's prefix.
KNEE_AXIS: tuple[str, str] = ("KNEE_LAT", "KNEE_MED")


@dataclass(frozen=True)
class Landmarks:
    """The landmark codes of a marker set from which the centres are computed (a template's ``joint_centres``).

    A sided marker's name is the side prefix and its code (``L`` + ``KNE``); ``sacrum`` is a midline marker.
    """

    asis: str = "ASI"
    psis: str = "PSI"
    sacrum: str = "SACR"
    knee_lateral: str = "KNE"
    knee_medial: str = "MKNE"
    ankle_lateral: str = "ANK"
    ankle_medial: str = "MMAL"
    thigh_wand: str = "THI"
    shank_wand: str = "TIB"
    kad_axis: str = "KAX"
    heel: str = "HEE"
    toe: str = "TOE"
    prefix: Mapping[str, str] = field(default_factory=lambda: {"left": "L", "right": "R"})

    def name(self, side: str, code: str) -> str:
        """A sided marker's name ("" for a landmark the marker set lacks: code "")."""
        return f"{self.prefix[side]}{code}" if code else ""

    def knee_axis(self, side: str) -> tuple[str, str]:
        """The names of a knee's axis markers (lateral, medial)."""
        return tuple(f"{self.prefix[side]}{name}" for name in KNEE_AXIS)

    def foot_direction(self, side: str) -> tuple[str, str]:
        """The names of a foot's direction markers (up, down)."""
        return tuple(f"{self.prefix[side]}{name}" for name in FOOT_DIRECTION)

    def centre(self, side: str, joint: str) -> str:
        """The name of a joint centre's virtual marker (``joint``: ``HJC``, ``KJC`` or ``AJC``)."""
        return f"{self.prefix[side]}{joint}"


@dataclass(frozen=True)
class JointCentres:
    """The joint centres of a trial (:func:`static_joint_centres`).

    Attributes
    ----------
    names : tuple of str
        The centres' marker names (``LHJC``, ``RHJC``, ``LKJC``, ...).
    markers_m : numpy.ndarray
        (n_frames, n_centres, 3), m, in the frame of the markers given.
    methods : dict
        Name -> how it was computed (a line for the scale report).
    """

    names: tuple[str, ...]
    markers_m: np.ndarray
    methods: dict[str, str]


def widths_from_processing(processing: Mapping[str, float]) -> dict[str, float]:
    """The lab's measurements of a C3D's ``PROCESSING`` values (mm, as Vicon Nexus stores them), in m: keys
    ``knee_left``, ``knee_right``, ``ankle_left``, ``ankle_right`` (widths), ``leg_left``, ``leg_right`` (leg
    lengths), ``asis_trochanter_left``, ``asis_trochanter_right``, ``inter_asis`` and ``marker_diameter``; only
    those stored with a positive value."""
    keys = {
        "knee_left": "LKneeWidth",
        "knee_right": "RKneeWidth",
        "ankle_left": "LAnkleWidth",
        "ankle_right": "RAnkleWidth",
        "leg_left": "LLegLength",
        "leg_right": "RLegLength",
        "asis_trochanter_left": "LAsisTrocanterDistance",
        "asis_trochanter_right": "RAsisTrocanterDistance",
        "inter_asis": "InterAsisDistance",
        "marker_diameter": "MarkerDiameter",
    }
    out = {}
    for key, stored in keys.items():
        value = processing.get(stored)
        try:
            value = float(value)
        except (TypeError, ValueError):
            continue
        if np.isfinite(value) and value > 0:
            out[key] = value / 1000.0
    return out


def _unit(v: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore", divide="ignore"):
        return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _pelvis_frame(lasi, rasi, posterior):
    """Origin, axes (x forward, y up, z to the right; each (n, 3)), width and depth (n,) of the spines' pelvis."""
    origin = 0.5 * (lasi + rasi)
    z = _unit(rasi - lasi)
    y = _unit(np.cross(z, origin - posterior))
    x = np.cross(y, z)
    width = np.linalg.norm(rasi - lasi, axis=-1)
    depth = np.linalg.norm(origin - posterior, axis=-1)
    return origin, x, y, z, width, depth


def harrington_hip_centres(lasi, rasi, posterior) -> dict[str, np.ndarray]:
    """Left and right hip centres (Harrington et al. 2007) from the anterior spines and the posterior spines'
    midpoint (or the sacrum marker).

    Parameters
    ----------
    lasi, rasi, posterior : array-like
        (n_frames, 3), m.

    Returns
    -------
    dict
        ``{"left": (n_frames, 3), "right": (n_frames, 3)}``, m.
    """
    lasi, rasi, posterior = (np.atleast_2d(np.asarray(v, float)) for v in (lasi, rasi, posterior))
    origin, x, y, z, width, depth = _pelvis_frame(lasi, rasi, posterior)
    ax = (-0.24 * depth - 0.0099)[:, None]
    ay = (-0.30 * width - 0.0109)[:, None]
    az = (0.33 * width + 0.0073)[:, None]
    return {side: origin + ax * x + ay * y + sign * az * z for side, sign in (("left", -1.0), ("right", 1.0))}


def davis_hip_centres(
    lasi,
    rasi,
    posterior,
    leg_m: Mapping[str, float],
    asis_trochanter_m: Mapping[str, float] | None = None,
    inter_asis_m: float | None = None,
    marker_radius_m: float = MARKER_DIAMETER_M / 2,
) -> dict[str, np.ndarray]:
    """Left and right hip centres as Plug-in Gait places them (Davis et al. 1991).

    Parameters
    ----------
    lasi, rasi, posterior : array-like
        (n_frames, 3), m.
    leg_m : mapping
        ``{"left": ..., "right": ...}``: leg lengths, m (their mean is used, as Plug-in Gait does).
    asis_trochanter_m : mapping, optional
        Side -> distance from the anterior spine to the greater trochanter, m; a side missing: ``0.1288 leg length
        - 48.56 mm``.
    inter_asis_m : float, optional
        The measured distance between the anterior spines, m; None: the markers'.
    marker_radius_m : float
        m.

    Returns
    -------
    dict
        ``{"left": (n_frames, 3), "right": (n_frames, 3)}``, m.
    """
    lasi, rasi, posterior = (np.atleast_2d(np.asarray(v, float)) for v in (lasi, rasi, posterior))
    origin, x, y, z, width, _ = _pelvis_frame(lasi, rasi, posterior)
    half = (np.full_like(width, inter_asis_m) if inter_asis_m else width)[:, None] / 2.0
    mean_leg_mm = 1000.0 * float(np.mean([leg_m["left"], leg_m["right"]]))
    c = (mean_leg_mm * 0.115 - 15.3) / 1000.0
    theta, beta = 0.5, 0.314
    out = {}
    for side, sign in (("left", -1.0), ("right", 1.0)):
        at = (asis_trochanter_m or {}).get(side) or (0.1288 * 1000.0 * leg_m[side] - 48.56) / 1000.0
        forward = c * np.cos(theta) * np.sin(beta) - (at + marker_radius_m) * np.cos(beta)
        lateral = c * np.sin(theta) - half
        up = -c * np.cos(theta) * np.cos(beta) - (at + marker_radius_m) * np.sin(beta)
        out[side] = origin + forward * x + up * y - sign * lateral * z
    return out


def chord_centre(proximal, wand, lateral, offset_m) -> np.ndarray:
    """The joint centre at ``offset_m`` from the ``lateral`` marker, in the plane of the ``proximal`` joint centre,
    the segment's ``wand`` and the lateral marker, with the proximal centre seen at a right angle from it, on the
    side away from the wand (Plug-in Gait's chord function).

    Parameters
    ----------
    proximal, wand, lateral : array-like
        (n_frames, 3), m.
    offset_m : float or array-like
        Distance of the centre from the lateral marker, m (half the joint's width plus the marker radius).

    Returns
    -------
    numpy.ndarray
        (n_frames, 3), m; NaN where a marker is missing or the three points are in line.
    """
    b, a, c = (np.atleast_2d(np.asarray(v, float)) for v in (proximal, wand, lateral))
    offset = np.broadcast_to(np.asarray(offset_m, float), (b.shape[0],))[:, None]
    e1 = _unit(b - c)
    towards_wand = (a - c) - np.sum((a - c) * e1, axis=1, keepdims=True) * e1
    e2 = -_unit(towards_wand)
    cos = np.clip(offset / np.linalg.norm(b - c, axis=1, keepdims=True), -1.0, 1.0)
    return c + offset * (cos * e1 + np.sqrt(1.0 - cos**2) * e2)


def static_joint_centres(
    labels: Sequence[str],
    markers_m: np.ndarray,
    landmarks: Landmarks = Landmarks(),
    widths_m: Mapping[str, float] | None = None,
    source: str = "",
    up: Sequence[float] = (0.0, 1.0, 0.0),
) -> JointCentres:
    """Hip, knee and ankle centres of both sides of a trial (see the module's text for the methods).

    Parameters
    ----------
    labels : sequence of str
        The trial's marker names (model names, a knee alignment device's knee marker included).
    markers_m : numpy.ndarray
        (n_frames, n_markers, 3), m.
    landmarks : Landmarks
        The codes of the markers used.
    widths_m : mapping, optional
        :func:`widths_from_processing`'s values, m.
    source : str
        The file, for messages.
    up : (float, float, float)
        The vertical of the markers' frame (OpenSim's +Y): a foot's up, as it stands flat in a static trial.

    Returns
    -------
    JointCentres
        ``LHJC``, ``RHJC``, ``LKJC``, ``RKJC``, ``LAJC``, ``RAJC`` (with the landmarks' prefixes), each with its
        method.

    Raises
    ------
    LoperInputError
        A marker the centres need is missing: both anterior spines, the posterior spines or the sacrum, the lateral
        knee and ankle markers (naming them and the file).
    """
    X = np.asarray(markers_m, float)
    index = {n: i for i, n in enumerate(labels)}
    widths = dict(widths_m or {})
    radius = 0.5 * widths.get("marker_diameter", MARKER_DIAMETER_M)
    lm = landmarks

    def get(name: str) -> np.ndarray | None:
        return X[:, index[name]] if name in index else None

    lasi, rasi = get(lm.name("left", lm.asis)), get(lm.name("right", lm.asis))
    lpsi, rpsi, sacr = get(lm.name("left", lm.psis)), get(lm.name("right", lm.psis)), get(lm.sacrum)
    need = [lm.name("left", lm.asis), lm.name("right", lm.asis)]
    if lpsi is not None and rpsi is not None:
        posterior, back = 0.5 * (lpsi + rpsi), "the posterior spines"
    elif sacr is not None:
        posterior, back = sacr, "the sacrum marker"
    else:
        posterior, back = None, ""
        need.append(f"{lm.name('left', lm.psis)} and {lm.name('right', lm.psis)}, or {lm.sacrum}")
    for side in SIDES:
        need += [lm.name(side, lm.knee_lateral), lm.name(side, lm.ankle_lateral)]
    lacking = [n for n in need if n not in index]
    if lasi is None or rasi is None or posterior is None or lacking:
        raise LoperInputError(
            f"{source}: the joint centres of the static trial need the marker(s) {', '.join(lacking)}, "
            "which it lacks (markers.label_map names the lab's labels)"
        )
    if "leg_left" in widths and "leg_right" in widths:
        legs = {side: widths[f"leg_{side}"] for side in SIDES}
        troch = {side: widths[f"asis_trochanter_{side}"] for side in SIDES if f"asis_trochanter_{side}" in widths}
        hips = davis_hip_centres(lasi, rasi, posterior, legs, troch, widths.get("inter_asis"), radius)
        hip_method = (
            f"Plug-in Gait's regression (Davis et al. 1991) on the lab's leg lengths "
            f"{legs['left'] * 1000:.0f} and {legs['right'] * 1000:.0f} mm, the anterior spines and {back}"
        )
    else:
        hips = harrington_hip_centres(lasi, rasi, posterior)
        hip_method = f"Harrington et al. 2007 regression on the anterior spines and {back} (no leg length stored)"
    _, _, _, z, _, _ = _pelvis_frame(lasi, rasi, posterior)
    names, centres, methods = [], [], {}
    for side in SIDES:
        names.append(lm.centre(side, "HJC"))
        centres.append(hips[side])
        methods[names[-1]] = hip_method
    medial_axis = {"left": z, "right": -z}
    for side in SIDES:
        knee, how = _distal_centre(side, get, hips[side], medial_axis[side], widths, radius, lm, _joints(lm)["KJC"])
        names.append(lm.centre(side, "KJC"))
        centres.append(knee)
        methods[names[-1]] = how
    for side in SIDES:
        knee = centres[names.index(lm.centre(side, "KJC"))]
        ankle, how = _distal_centre(side, get, knee, medial_axis[side], widths, radius, lm, _joints(lm)["AJC"])
        names.append(lm.centre(side, "AJC"))
        centres.append(ankle)
        methods[names[-1]] = how
    forward = _unit(0.5 * (lasi + rasi) - posterior)
    _add_directions(names, centres, methods, get, lm, (forward, back, np.asarray(up, float)))
    return JointCentres(tuple(names), np.stack(centres, axis=1), methods)


def _add_directions(names: list, centres: list, methods: dict, get, lm: Landmarks, axes) -> None:
    """Append the direction pairs (see the module's text) to the centres found: ``axes`` are the pelvis's forward
    axis (n, 3), the word for its posterior landmarks and the vertical (3,)."""
    forward, back, up = axes
    hips_mid = 0.5 * (centres[names.index(lm.centre("left", "HJC"))] + centres[names.index(lm.centre("right", "HJC"))])
    for name, sign, where in zip(PELVIS_DIRECTION, (1.0, -1.0), ("ahead of", "behind")):
        names.append(name)
        centres.append(hips_mid + sign * DIRECTION_LEVER_M * forward)
        methods[name] = f"pelvis forward ({back} to the anterior spines), {where} the hips' midpoint"
    for side in SIDES:  # the knee's flexion axis: from its centre to the lateral marker, whichever way found
        knee = centres[names.index(lm.centre(side, "KJC"))]
        lateral = _unit(get(lm.name(side, lm.knee_lateral)) - knee)
        for name, sign, where in zip(lm.knee_axis(side), (1.0, -1.0), ("lateral", "medial")):
            names.append(name)
            centres.append(knee + sign * DIRECTION_LEVER_M * lateral)
            methods[name] = f"knee flexion axis: {lm.centre(side, 'KJC')} to {lm.name(side, lm.knee_lateral)}, {where}"
    vertical = up / np.linalg.norm(up)
    for side in SIDES:
        ankle = centres[names.index(lm.centre(side, "AJC"))]
        for name, sign, where in zip(lm.foot_direction(side), (1.0, -1.0), ("above", "below")):
            names.append(name)
            centres.append(ankle + sign * DIRECTION_LEVER_M * vertical)
            methods[name] = f"foot flat on the floor: the vertical {where} {lm.centre(side, 'AJC')}"


@dataclass(frozen=True)
class _Joint:
    """What finds one distal joint's centre: its markers' codes, its width's key, its proximal centre's word, the
    model's proportion without a width, and a knee alignment device's axis marker (knees only)."""

    joint: str
    lateral: str
    medial: str
    wand: str
    segment: str
    proximal: str
    proportion: float
    kad_axis: str = ""


def _joints(lm: Landmarks) -> dict[str, _Joint]:
    return {
        "KJC": _Joint("knee", lm.knee_lateral, lm.knee_medial, lm.thigh_wand, "thigh", "hip", KNEE_OFFSET_PER_THIGH,
                      lm.kad_axis),
        "AJC": _Joint("ankle", lm.ankle_lateral, lm.ankle_medial, lm.shank_wand, "shank", "knee",
                      ANKLE_OFFSET_PER_SHANK),
    }  # fmt: skip


def _distal_centre(side, get, proximal, medial_axis, widths, radius, lm: Landmarks, j: _Joint):
    """One knee's or ankle's centre (:class:`_Joint`) and how it was found."""
    lateral_name = lm.name(side, j.lateral)
    lateral, medial = get(lateral_name), get(lm.name(side, j.medial))
    if medial is not None and np.isfinite(medial).all(axis=1).any():
        return 0.5 * (lateral + medial), f"midpoint of {lateral_name} and {lm.name(side, j.medial)}"
    width = widths.get(f"{j.joint}_{side}")
    if width is not None:
        offset, said = 0.5 * width + radius, f"half the {j.joint} width {width * 1000:.1f} mm + marker radius"
    else:
        offset = j.proportion * np.linalg.norm(lateral - proximal, axis=1)
        said = f"no {j.joint} width stored: the model's proportion of the {j.proximal} to {j.joint} distance"
    axis = get(lm.name(side, j.kad_axis))
    if axis is not None and np.isfinite(axis).all(axis=1).any():
        centre = lateral + np.atleast_1d(offset)[:, None] * _unit(lateral - axis)
        return centre, f"{j.joint} alignment device: {lateral_name} along its axis by {said}"
    wand = get(lm.name(side, j.wand))
    if wand is not None and np.isfinite(wand).all(axis=1).any():
        how = f"chord of the {j.proximal} centre, {j.segment} wand and {lateral_name}, {said}"
        return chord_centre(proximal, wand, lateral, offset), how
    centre = lateral + np.atleast_1d(offset)[:, None] * medial_axis
    return centre, f"{lateral_name} along the pelvis's medial axis by {said}"
