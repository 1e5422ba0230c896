"""The subject's body mass and height for scaling: given, from the static trial's force plates, or from the
file's ``PROCESSING`` parameters, each with where it came from; and the scaled model's stature against them.

* :func:`body_mass_kg` - the sheet's mass, else the plates' weight when both feet stand on loaded plates
  (:func:`loper_analysis.motion.static_trial.markers_off_plates`), else ``PROCESSING:Bodymass`` with the
  reason, else a stop asking for ``mass_kg``;
* :func:`body_height_m` - the sheet's height, else ``PROCESSING:Height`` (mm, as Nexus writes it), else the
  scaled model's stature;
* :func:`require_stature` - a scaled model whose stature differs from a given height by more than
  :data:`loper_analysis.motion.scale_report.STOP_STATURE_CHANGE` is another subject's.

Arrays and recordings in (read by the file layer), SI units.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence

import numpy as np

from loper_analysis.constants import GRAVITY_M_PER_S2, LOADED_THRESHOLD_N
from loper_analysis.errors import LoperInputError

__all__ = ["MASS_LIMIT_KG", "body_height_m", "body_mass_kg", "model_stature_m", "require_stature"]

#: A given or stored body mass must lie in (0, this] kg.
MASS_LIMIT_KG: float = 300.0
#: Where a height estimated from the scaled model is said to come from.
_ESTIMATED = "estimated from the scaled model"


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
    from loper_analysis.motion.static_trial import standing_mass_kg

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
    off = _feet_off_plates(recording, plates, vertical, window, u)
    if off:
        return _file_bodymass(recording, off)
    mass = standing_mass_kg(plates[0].time_s, vertical, window, gravity_m_per_s2, source=recording.source)
    return mass, f"force plates {', '.join(str(p.number) for p in plates)} of {_name(recording)}"


def body_height_m(height_m: float | None, processing: Mapping[str, float], stature_m: float, file_name: str):
    """The subject's height (m) and where it came from: ``height_m`` given, ``processing["Height"]`` (mm) of the
    file ``file_name``, or the scaled model's ``stature_m``
    (:func:`loper_analysis.motion.static_trial.model_height_m`)."""
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
    """A scaled model's stature (m; :func:`loper_analysis.motion.static_trial.model_height_m` of its right thigh,
    the bodies named by ``segment_bodies`` as :func:`loper_analysis.motion.segments.segment_body_names` takes
    them)."""
    from loper_analysis.motion.segments import segment_body_names
    from loper_analysis.motion.static_trial import model_height_m

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


def _feet_off_plates(recording, plates, vertical_n: np.ndarray, window, up: np.ndarray) -> str:
    """Why the plates do not weigh the whole subject ('' when they do): foot markers of the static trial's mean
    pose over no loaded plate (:func:`loper_analysis.motion.static_trial.markers_off_plates`)."""
    from loper_analysis.motion.static_trial import FOOT_MARKER_HEIGHT_M, markers_off_plates

    t = plates[0].time_s
    in_window = (t >= window[0] - 1e-9) & (t <= window[1] + 1e-9)
    loaded = [p for j, p in enumerate(plates) if np.nanmean(vertical_n[in_window, j]) > LOADED_THRESHOLD_N]
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
