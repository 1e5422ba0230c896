"""Stride-variable walking trials: model coordinates and true gait events of the synthetic subjects.

Trial simulation
----------------
:func:`walking_kinematics` builds a stride phase ``Phi(t)`` that is integer
at every right heel strike. Stride durations are drawn from a normal
distribution (CV ``timing_cv``) and ``Phi`` is the monotone piecewise-cubic
(PCHIP, C1) interpolant through (heel-strike time, stride number), so the
strides have exactly the drawn durations and the angles have no jumps and no
velocity steps. In the gentle model every leg and joint has one amplitude
factor per stride (normal, mean 1, CV ``amplitude_cv``) that scales the curve
about its mean; the factors are blended between heel strikes with a
raised-cosine (C1) weight. The study-level model (a
:class:`~loper_analysis.synthetic.variability.GaitVariability`) modulates
amplitude, offset and timing of each curve smoothly instead, and a
:class:`~loper_analysis.synthetic.variability.DeviceAdaptation` changes the
curves of a trial with the device.
Gait events are the times at which the phase of a leg passes 0 (heel strike)
or the stance fraction (toe-off).

The pelvis height is the mean hip height that puts the lowest point of the feet
on the floor (:func:`pelvis_height_m`), plus the bob of the nominal gait.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.interpolate import PchipInterpolator

from loper_analysis.checks import generator
from loper_analysis.errors import LoperInputError
from loper_analysis.motion.model import COORDINATES
from loper_analysis.swing_leg.anthropometry import ANKLE_HEIGHT_FRACTION, WINTER_SEGMENTS
from loper_analysis.swing_leg.anthropometry import leg_length_m as standing_leg_length_m
from loper_analysis.synthetic.gait_curves import CURVE_JOINTS, NominalGait
from loper_analysis.synthetic.variability import DeviceAdaptation, GaitVariability, smooth_noise, swing_envelope

__all__ = [
    "AMPLITUDE_CV",
    "TIMING_CV",
    "TRUE_EVENT_COLUMNS",
    "leg_length_from_height",
    "pelvis_height_m",
    "walking_kinematics",
]

#: Stride-to-stride CV of the stride duration (config ``synthetic.timing_cv``).
TIMING_CV: float = 0.03
#: Gentle lab: CV of the joint-angle amplitudes per stride, leg and joint (config ``synthetic.amplitude_cv``).
AMPLITUDE_CV: float = 0.05

#: Columns of the true events of a simulated trial.
TRUE_EVENT_COLUMNS: tuple[str, ...] = ("side", "event", "time_s")


def leg_length_from_height(height_m: float) -> float:
    """Standing hip-joint height (m) of the model for a body height (m): thigh + shank + ankle height."""
    if not 1.0 <= height_m <= 2.5:
        raise LoperInputError(f"height_m must lie in 1 .. 2.5 m, got {height_m}")
    return float(standing_leg_length_m(height_m))


def _leg_geometry(leg_length_m: float) -> dict[str, float]:
    """Segment lengths (m) of the model whose standing hip height is ``leg_length_m``."""
    height = leg_length_m / leg_length_from_height(1.0)
    return {
        "thigh": WINTER_SEGMENTS["thigh"].length * height,
        "shank": WINTER_SEGMENTS["shank"].length * height,
        "foot": WINTER_SEGMENTS["foot"].length * height,
        "ankle_height": ANKLE_HEIGHT_FRACTION * height,
    }


def _foot_points_y(geo: dict[str, float], tilt, hip, knee, ankle) -> np.ndarray:
    """Heights (m) of the heel and toe sole points relative to the hip joint, shape (2, n).

    Planar chain of the model: thigh angle ``tilt + hip``, shank ``- knee``,
    foot ``+ ankle``; sole points at (-0.2, +0.8) foot lengths from the ankle,
    one ankle height below it (the model's heel and MT markers lie there).
    """
    thigh = tilt + hip
    shank = thigh - knee
    foot = shank + ankle
    ankle_y = -geo["thigh"] * np.cos(thigh) - geo["shank"] * np.cos(shank)
    out = []
    for x in (-0.2 * geo["foot"], 0.8 * geo["foot"]):
        out.append(ankle_y + x * np.sin(foot) - geo["ankle_height"] * np.cos(foot))
    return np.array(out)


def _check_leg_length(leg_length_m) -> float:
    if leg_length_m is None:
        return leg_length_from_height(1.75)
    if not 0.5 <= leg_length_m <= 1.35:
        raise LoperInputError(f"leg_length_m must lie in 0.5 .. 1.35 m, got {leg_length_m}")
    return float(leg_length_m)


def pelvis_height_m(gait: NominalGait, leg_length_m: float | None = None, n_samples: int = 1000) -> float:
    """Mean ``pelvis_ty`` (m) that keeps the lower foot on the floor over a nominal stride.

    At every phase the hip height needed for the lowest sole point of either
    foot to touch the floor (y = 0) is computed with the model's planar leg
    chain; the mean over the stride is returned (the bob of the gait is added
    on top by :func:`walking_kinematics`).

    Parameters
    ----------
    gait : NominalGait
    leg_length_m : float or None
        Standing hip-joint height (m), thigh + shank + ankle height of the
        model (:func:`leg_length_from_height`); None = a 1.75 m subject.
    n_samples : int
        Phase samples per stride.
    """
    geo = _leg_geometry(_check_leg_length(leg_length_m))
    phase = np.arange(n_samples) / n_samples
    tilt = gait.pelvis_tilt_rad(phase)
    lowest = []
    for offset in (0.0, 0.5):
        a = gait.joint_angles(phase - offset)
        y = _foot_points_y(geo, tilt, a["hip_flexion"], a["knee_flexion"], a["ankle_dorsiflexion"])
        lowest.append(y.min(axis=0))
    return float(np.mean(-np.minimum(*lowest)))


def _modulations(
    variability: GaitVariability,
    joint: int,
    leg_phase: np.ndarray,
    first_phase: float,
    last_phase: float,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Amplitude factor, offset (rad) and timing shift (strides) of one leg and joint at ``leg_phase``.

    The knots cover the leg phases ``first_phase .. last_phase`` (the span of
    the trial's stride knots), so the number of draws depends only on the
    trial's strides.
    """
    n = variability.knots_per_stride
    first, last = int(np.floor(first_phase * n)) - 1, int(np.ceil(last_phase * n)) + 1
    g = swing_envelope(leg_phase, variability.swing_gain[joint])
    a = 1.0 + g * smooth_noise(leg_phase, first, last, n, variability.amplitude_cv[joint], rng)
    o = g * smooth_noise(leg_phase, first, last, n, variability.offset_sd_rad[joint], rng)
    tau = g * smooth_noise(leg_phase, first, last, n, variability.timing_sd[joint], rng)
    return a, o, tau


def _solve_phase(
    phase_of_t: PchipInterpolator, knot_t: np.ndarray, knot_phase0: int, targets: np.ndarray
) -> np.ndarray:
    """Times at which the monotone phase reaches ``targets`` (bisection inside the bracketing stride)."""
    k = np.floor(targets).astype(int) - knot_phase0
    lo, hi = knot_t[k].copy(), knot_t[k + 1].copy()
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        below = phase_of_t(mid) < targets
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    return 0.5 * (lo + hi)


def _checked_arguments(
    duration_s: float,
    sample_rate_hz: float,
    gait: NominalGait,
    rng,
    timing_cv: float,
    amplitude_cv: float,
    leg_length_m: float | None,
    start_phase: float | None,
    variability: GaitVariability | None,
    adaptation: DeviceAdaptation | None,
) -> tuple[np.random.Generator, int, float]:
    """The random generator, the number of samples and the standing hip height (m) of
    :func:`walking_kinematics`'s arguments, each checked (LoperInputError naming a bad one)."""
    if not isinstance(gait, NominalGait):
        raise LoperInputError(f"gait must be a NominalGait, got {type(gait).__name__}")
    rng = generator(rng)
    if not (np.isfinite(duration_s) and duration_s > 0):
        raise LoperInputError(f"duration_s must be > 0, got {duration_s}")
    if not (np.isfinite(sample_rate_hz) and sample_rate_hz > 0):
        raise LoperInputError(f"sample_rate_hz must be > 0, got {sample_rate_hz}")
    n = int(round(duration_s * sample_rate_hz))
    if n < 2:
        raise LoperInputError(f"duration_s * sample_rate_hz must give >= 2 samples, got {n}")
    if not 0 <= timing_cv <= 0.2:
        raise LoperInputError(f"timing_cv must lie in 0 .. 0.2, got {timing_cv}")
    if not 0 <= amplitude_cv <= 0.3:
        raise LoperInputError(f"amplitude_cv must lie in 0 .. 0.3, got {amplitude_cv}")
    leg = _check_leg_length(leg_length_m)
    if start_phase is not None and not 0 <= start_phase < 1:
        raise LoperInputError(f"start_phase must lie in [0, 1), got {start_phase}")
    if variability is not None and not isinstance(variability, GaitVariability):
        raise LoperInputError(f"variability must be a GaitVariability or None, got {type(variability).__name__}")
    if adaptation is not None and not isinstance(adaptation, DeviceAdaptation):
        raise LoperInputError(f"adaptation must be a DeviceAdaptation or None, got {type(adaptation).__name__}")
    return rng, n, leg


def _true_events(
    gait: NominalGait,
    duration_s: float,
    first_phase: float,
    phase_of_t: PchipInterpolator,
    knot_t: np.ndarray,
    knot_phase0: int,
) -> pd.DataFrame:
    """The true gait events (``side``, ``event``, ``time_s`` in s) with 0 <= time_s <= ``duration_s``, sorted by
    time: where each leg's phase passes a whole stride (heel strike) or the stance fraction (toe-off).

    ``first_phase`` is the right leg's phase at t = 0; the stride knots (right heel strikes) lie at ``knot_t``
    (s) with phases ``knot_phase0``, ``knot_phase0 + 1``, ...
    """
    knot_phase = np.arange(knot_t.size, dtype=float) + knot_phase0
    s = gait.stance_fraction
    first, last = int(np.floor(first_phase)) - 1, int(np.ceil(phase_of_t(duration_s))) + 1
    ints = np.arange(first, last + 1, dtype=float)
    rows = []
    for side, offset in (("right", 0.0), ("left", 0.5)):
        for event, shift in (("heel_strike", 0.0), ("toe_off", s)):
            targets = ints + offset + shift
            targets = targets[(targets >= knot_phase[0]) & (targets < knot_phase[-1])]
            times = _solve_phase(phase_of_t, knot_t, knot_phase0, targets)
            if side == "right" and event == "heel_strike":  # exact at the knots
                times = knot_t[targets.astype(int) - knot_phase0]
            rows += [(side, event, float(tt)) for tt in times if 0.0 <= tt <= duration_s]
    return (
        pd.DataFrame(rows, columns=list(TRUE_EVENT_COLUMNS)).sort_values("time_s", kind="stable").reset_index(drop=True)
    )


def walking_kinematics(
    duration_s: float,
    sample_rate_hz: float,
    gait: NominalGait,
    rng: np.random.Generator,
    *,
    timing_cv: float = TIMING_CV,
    amplitude_cv: float = AMPLITUDE_CV,
    leg_length_m: float | None = None,
    start_phase: float | None = None,
    variability: GaitVariability | None = None,
    adaptation: DeviceAdaptation | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Simulate a treadmill walking trial: model coordinates and the true gait events.

    Parameters
    ----------
    duration_s : float
        Trial duration (s); ``round(duration_s * sample_rate_hz)`` samples from t = 0.
    sample_rate_hz : float
        Sample rate of the coordinates (Hz).
    gait : NominalGait
        Nominal stride (cadence, stance fraction, curves).
    rng : numpy.random.Generator
        Source of all randomness (start phase, stride durations, amplitudes);
        the same seed gives identical frames.
    timing_cv : float
        Coefficient of variation of the stride duration (0 .. 0.2); durations
        are clipped to 0.5 .. 1.5 nominal strides.
    amplitude_cv : float
        Coefficient of variation of the per-stride amplitude factors (0 .. 0.3),
        one per leg, joint and stride; clipped to 0.5 .. 1.5.
    leg_length_m : float or None
        Standing hip-joint height of the subject's model (m,
        :func:`leg_length_from_height`); sets the mean ``pelvis_ty``. None = a
        1.75 m subject (0.9275 m).
    start_phase : float or None
        Right-leg stride phase at t = 0 in [0, 1); None = drawn uniformly from
        ``rng``.
    variability : GaitVariability or None
        None: the gentle model (per-stride amplitude factors of CV
        ``amplitude_cv``). Otherwise the study-level model of
        :mod:`loper_analysis.synthetic.variability` (smooth amplitude, offset
        and timing modulations; ``amplitude_cv`` is then unused). Either way
        the stride durations are the same for the same ``rng``.
    adaptation : DeviceAdaptation or None
        Systematic change of the joint curves with the device (both legs); None:
        none.

    Returns
    -------
    coordinates : pandas.DataFrame, shape (n_samples, 10)
        ``time_s`` and the model coordinates :data:`loper_analysis.motion.model.COORDINATES`
        (rad; ``pelvis_tx``, ``pelvis_ty`` in m).
    events : pandas.DataFrame
        ``side`` (left | right), ``event`` (heel_strike | toe_off), ``time_s``:
        every true event with 0 <= time_s <= duration_s, sorted by time.

    Raises
    ------
    LoperInputError
        Non-positive duration or rate, fewer than 2 samples, a CV out of range,
        a bad ``gait``, ``rng``, ``leg_length_m`` or ``start_phase``.
    """
    rng, n, leg = _checked_arguments(
        duration_s,
        sample_rate_hz,
        gait,
        rng,
        timing_cv,
        amplitude_cv,
        leg_length_m,
        start_phase,
        variability,
        adaptation,
    )

    T0 = gait.stride_s
    phi0 = float(rng.uniform()) if start_phase is None else float(start_phase)
    n_strides = int(np.ceil(duration_s / (0.5 * T0))) + 4
    T = np.clip(T0 * (1.0 + timing_cv * rng.standard_normal(n_strides)), 0.5 * T0, 1.5 * T0)
    # knots: right heel strikes; knot j has phase j - 1 (the first lies a stride before phase 0)
    knot_t = -phi0 * T[1] - T[0] + np.concatenate([[0.0], np.cumsum(T)])
    knot_phase0 = -1
    knot_phase = np.arange(knot_t.size, dtype=float) + knot_phase0
    phase_of_t = PchipInterpolator(knot_t, knot_phase, extrapolate=False)
    # amplitude factors, one per (leg, joint, leg stride); leg phases start at -1.5
    amp_first = -2
    amps = np.clip(1.0 + amplitude_cv * rng.standard_normal((2, len(CURVE_JOINTS), knot_t.size + 2)), 0.5, 1.5)

    t = np.arange(n) / sample_rate_hz
    Phi = phase_of_t(t)
    out = {"time_s": t}
    out["pelvis_tilt"] = gait.pelvis_tilt_rad(Phi)
    out["pelvis_tx"] = gait.pelvis_tx_m(Phi)
    out["pelvis_ty"] = pelvis_height_m(gait, leg) + gait.pelvis_ty_bob_m(Phi)
    for i_leg, (side, offset) in enumerate((("r", 0.0), ("l", 0.5))):
        leg_phase = Phi - offset
        k = np.floor(leg_phase)
        frac = leg_phase - k
        w = 0.5 * (1.0 - np.cos(np.pi * frac))
        idx = k.astype(int) - amp_first
        psi = gait.curve_phase(frac)
        for j, joint in enumerate(CURVE_JOINTS):
            series = gait.joint_series(joint)
            if variability is None:
                a = amps[i_leg, j, idx] * (1.0 - w) + amps[i_leg, j, idx + 1] * w
                excursion = series(psi) - series.mean
                o = 0.0
            else:
                a, o, tau = _modulations(
                    variability, j, leg_phase, knot_phase[0] - offset, knot_phase[-1] - offset, rng
                )
                excursion = series(gait.curve_phase(leg_phase + tau)) - series.mean
            if adaptation is not None:
                dev_amp, dev_off = adaptation.factor_and_offset(j, leg_phase)
                a, o = dev_amp * a, o + dev_off
            out[f"{joint}_{side}"] = series.mean + a * excursion + o
    coordinates = pd.DataFrame({c: out[c] for c in ("time_s", *COORDINATES)})

    return coordinates, _true_events(gait, duration_s, Phi[0], phase_of_t, knot_t, knot_phase0)
