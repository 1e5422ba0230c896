"""Plausibility of marker data: lengths a human body can have and IK marker errors a good fit can have.

These checks catch numbers in the wrong unit (a C3D declaring ``POINT:UNITS``
= ``m`` whose values are in mm reads 1000 times too large and passes every
format check) before they turn into nonsense downstream:

* :func:`require_marker_extent`: the spread of the markers in a frame (the
  largest distance between two markers present, median over the frames)
  must lie in a human range (default 0.1 .. 5 m; a walking subject's lower
  body spans about 1.0 .. 1.8 m, a full-body set up to about 2 m).
* :func:`measurement_scale_factors` and :func:`require_scale_factors`: the
  scale factors that OpenSim's ScaleTool would apply (static-trial marker
  distance over model marker distance, averaged over a measurement's pairs)
  must lie in 0.5 .. 2 by default.
* :func:`require_ik_fit`: at most a share of the frames (default 10 %) may
  have an IK marker RMS error above a limit (default 60 mm: a unit, label
  or model mistake); above a warning level (default 20 mm, where OpenSim's
  guidance puts a good fit: RMS below 10 to 20 mm, largest error below 20
  to 40 mm) the fit is reported as poor but kept.

Every refusal raises :class:`~loper_analysis.errors.LoperInputError` naming
the file, the quantity, its value and the limit.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from loper_analysis.checks import where
from loper_analysis.errors import LoperInputError

__all__ = [
    "KNEE_SIGN_MAX_RAD",
    "KNEE_SIGN_MIN_RAD",
    "inverted_knee_warnings",
    "marker_extent_m",
    "require_marker_extent",
    "measurement_scale_factors",
    "require_scale_factors",
    "require_ik_fit",
    "IK_STOP_RMS_M",
    "IK_WARN_RMS_M",
    "IK_MAX_FRACTION",
]

#: IK marker RMS error (m) above which a frame counts against the fit: a unit, label or model mistake.
IK_STOP_RMS_M = 0.06
#: IK marker RMS error (m) above which a frame counts as poorly fitted (warning only).
IK_WARN_RMS_M = 0.02
#: Share of frames above either level that stops (or warns about) a trial.
IK_MAX_FRACTION = 0.1
#: Scale factors outside this range are refused as a unit, label or model mistake
#: (config ``model.scale_factor_range``).
SCALE_FACTOR_RANGE: tuple[float, float] = (0.5, 2.0)
#: Range (m) of the largest distance between a trial's markers (config ``markers.extent_range_m``): outside
#: it the numbers are in another unit than the file declares.
EXTENT_RANGE_M: tuple[float, float] = (0.1, 5.0)

#: Frames sampled for the marker extent (evenly spaced; the median hardly moves with more).
_EXTENT_FRAMES = 200


def marker_extent_m(markers_m) -> float:
    """Median over frames of the largest distance (m) between two markers present in the frame.

    ``markers_m`` has shape (n_frames, n_markers, 3), metres, NaN where
    missing; frames with fewer than two markers present are skipped (NaN if
    no frame has two). At most :data:`_EXTENT_FRAMES` evenly spaced frames are used.
    """
    X = np.asarray(markers_m, dtype=float)
    if X.ndim != 3 or X.shape[2] != 3:
        raise LoperInputError(f"markers_m must have shape (n_frames, n_markers, 3), got {X.shape}")
    frames = np.unique(np.linspace(0, X.shape[0] - 1, min(X.shape[0], _EXTENT_FRAMES)).round().astype(int))
    spans = []
    for k in frames if X.shape[0] else []:
        P = X[k][np.all(np.isfinite(X[k]), axis=1)]
        if len(P) >= 2:
            spans.append(float(np.max(np.linalg.norm(P[:, None, :] - P[None, :, :], axis=2))))
    return float(np.median(spans)) if spans else float("nan")


def require_marker_extent(
    markers_m, source: str = "", extent_range_m: Sequence[float] = EXTENT_RANGE_M, unit_field: str = "POINT:UNITS"
) -> float:
    """Refuse markers whose spread (:func:`marker_extent_m`) lies outside ``extent_range_m`` (m); returns it.

    A spread 10 or 1000 times too large or too small means the numbers are
    in another length unit than the file declares (``unit_field``).
    """
    lo, hi = (float(v) for v in extent_range_m)
    extent = marker_extent_m(markers_m)
    if np.isfinite(extent) and not lo <= extent <= hi:
        hint = "mm or cm read as m?" if extent > hi else "m read as mm?"
        raise LoperInputError(
            f"{where(source)}marker extent (largest distance between two markers in a frame, median over frames) "
            f"is {extent:.4g} m, outside the human range {lo:g} .. {hi:g} m: the numbers do not match the declared "
            f"length unit ({unit_field}; {hint})"
        )
    return extent


def measurement_scale_factors(
    model, measurements: Mapping[str, Sequence[tuple[str, str]]], markers_m, labels: Sequence[str]
) -> dict[str, float]:
    """ScaleTool's factor of each measurement: mean over its marker pairs of data distance / model distance.

    Parameters
    ----------
    model : opensim.Model
        The generic model with the measurement markers; its distances are
        taken at the default pose (as OpenSim's ModelScaler does).
    measurements : mapping of str to sequence of (str, str)
        Measurement name -> marker pairs.
    markers_m : array_like
        Static trial, shape (n_frames, n_markers, 3), metres; the distance of
        a pair is its mean over the frames where both markers are present.
    labels : sequence of str
        One name per marker of ``markers_m``.

    Returns
    -------
    dict of str to float
        Measurement -> factor (NaN if no pair could be measured).
    """
    from loper_analysis.motion.ik import marker_positions

    labels = list(labels)
    X = np.asarray(markers_m, dtype=float)
    names = sorted({m for pairs in measurements.values() for pair in pairs for m in pair})
    if not names:  # a setup that only places markers (or scales by hand) measures nothing
        return {}
    at_default = dict(zip(names, marker_positions(model, {}, names)[0]))
    out = {}
    for name, pairs in measurements.items():
        ratios = []
        for a, b in pairs:
            d = np.linalg.norm(X[:, labels.index(a)] - X[:, labels.index(b)], axis=1)
            d_model = float(np.linalg.norm(at_default[a] - at_default[b]))
            if np.isfinite(d).any() and d_model > 0:
                ratios.append(float(np.nanmean(d)) / d_model)
        out[name] = float(np.mean(ratios)) if ratios else float("nan")
    return out


def require_scale_factors(
    factors: Mapping[str, float], source: str = "", factor_range: Sequence[float] = SCALE_FACTOR_RANGE
) -> None:
    """Refuse scale factors outside ``factor_range``: the static trial's distances are not the model's kind.

    All offending measurements are named with their factor.
    """
    lo, hi = (float(v) for v in factor_range)
    bad = {k: v for k, v in factors.items() if np.isfinite(v) and not lo <= v <= hi}
    if bad:
        listed = ", ".join(f"{k} {v:.4g}" for k, v in bad.items())
        raise LoperInputError(
            f"{where(source)}scale factor(s) outside {lo:g} .. {hi:g} (static-trial marker distance over the "
            f"model's): {listed}; are the markers in the unit the file declares?"
        )


#: A knee whose angle stays below this (rad; -20 degrees) at its most negative while its most positive stays under
#: :data:`KNEE_SIGN_MAX_RAD` flexes "negative": a sign.
KNEE_SIGN_MIN_RAD: float = float(np.radians(-20.0))
#: See :data:`KNEE_SIGN_MIN_RAD` (rad; 10 degrees).
KNEE_SIGN_MAX_RAD: float = float(np.radians(10.0))


def inverted_knee_warnings(angles, setting: str = "ik.coordinate_map") -> list[str]:
    """Warnings for knees that flex negative: a walking knee flexes to 60 degrees in swing and barely
    hyperextends, so a knee angle that reaches below -20 degrees and never above 10 degrees has the wrong sign.

    Parameters
    ----------
    angles : pandas.DataFrame
        Our angle table (``knee_left_rad``, ``knee_right_rad``; others ignored).
    setting : str
        The config key named in the warning.

    Returns
    -------
    list of str
        One warning per inverted knee (empty when none).
    """
    out = []
    for side in ("left", "right"):
        column = f"knee_{side}_rad"
        if column not in angles:
            continue
        q = np.asarray(angles[column], float)
        q = q[np.isfinite(q)]
        if q.size and q.min() < KNEE_SIGN_MIN_RAD and q.max() < KNEE_SIGN_MAX_RAD:
            out.append(
                f"knee_{side} flexes negative (from {np.degrees(q.min()):.0f} to {np.degrees(q.max()):.0f} deg): "
                f"its sign is likely wrong ({setting}.knee_{side}.sign)"
            )
    return out


def require_ik_fit(
    marker_rms_m,
    source: str = "",
    max_rms_m: float = IK_STOP_RMS_M,
    max_fraction: float = IK_MAX_FRACTION,
    warn_rms_m: float | None = IK_WARN_RMS_M,
) -> str | None:
    """Refuse an IK solution whose marker RMS error exceeds ``max_rms_m`` (m) in more than ``max_fraction`` of frames.

    ``marker_rms_m`` (n_frames,) is :attr:`loper_analysis.motion.ik.IKResult.marker_rms_m`;
    frames without a value (NaN: left out of the solve) do not count. Errors
    that large (default 60 mm in more than 10 % of the frames) come from a
    wrong unit, swapped labels or the wrong model, not from marker placement.
    Between ``warn_rms_m`` and ``max_rms_m`` the fit is poor but usable (real
    data: OpenSim's own gait2392 tutorial solves at about 22 mm mean RMS):
    the returned text says so, for the caller to log as a warning.

    Returns
    -------
    str or None
        A warning when more than ``max_fraction`` of the frames exceed
        ``warn_rms_m``; None otherwise.
    """
    rms = np.asarray(marker_rms_m, dtype=float)
    rms = rms[np.isfinite(rms)]
    if rms.size == 0:
        return None
    over = rms > float(max_rms_m)
    stats = f"mean RMS {1e3 * rms.mean():.4g} mm, largest {1e3 * rms.max():.4g} mm"
    if over.mean() > float(max_fraction):
        raise LoperInputError(
            f"{where(source)}IK marker RMS error exceeds {1e3 * max_rms_m:g} mm in {int(over.sum())} of {rms.size} "
            f"frames ({100 * over.mean():.1f} % > {100 * max_fraction:g} %); {stats}: wrong marker unit, labels or "
            "model? (limit: ik.max_marker_rms_m)"
        )
    if warn_rms_m is None:
        return None
    poor = rms > float(warn_rms_m)
    if poor.mean() > float(max_fraction):
        return (
            f"{where(source)}IK marker RMS error exceeds {1e3 * warn_rms_m:g} mm in {int(poor.sum())} of "
            f"{rms.size} frames ({100 * poor.mean():.1f} %); {stats}: check the marker placement on the model "
            "(scaling) and the IK weights (warning level: ik.warn_marker_rms_m)"
        )
    return None
