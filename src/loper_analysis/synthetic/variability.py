"""Stride-to-stride variability and the gait adaptation to the device of the synthetic subjects.

Two models of variability exist (``synthetic.variability`` in the config):

* ``gentle``: one amplitude factor per stride, leg and joint, blended between
  heel strikes (:func:`loper_analysis.synthetic.walking.walking_kinematics`
  without a :class:`GaitVariability`); the swing variability is about a third
  of the study's;
* ``study``: :class:`GaitVariability`, smooth random modulations of each
  joint's curve in amplitude, offset and timing that reach the study's
  inter-stride variability.

A modulation is a C2 random function of the leg's continuous stride phase:
independent normal values at ``knots_per_stride`` equally spaced knots per
stride, joined by a cubic spline (:func:`smooth_noise`). It is correlated over
a fraction of a stride, continuous across heel strikes and has no velocity
steps. A joint angle becomes::

    theta(phi) = m + a(phi) · (c(phi + tau(phi)) - m) + o(phi)

with the nominal curve ``c`` and its mean ``m``, the amplitude factor
``a = 1 + noise``, the offset ``o`` (rad) and the timing shift ``tau``
(fraction of a stride) relative to the gait events. The three SDs are
those at mid-stance; toward mid-swing they grow smoothly by the joint's
``swing_gain`` (:func:`swing_envelope`).

Walking with the device (:class:`DeviceAdaptation`, :func:`device_adaptation`)
is a model choice: each subject adapts systematically to the brace's mass and
inertia on the thigh by a small change of every joint's amplitude and offset,
the same in every trial with the device. Size and sign are drawn per subject
from the seed: sign at random, size uniform between 0.7 and 1.3 times the
configured value.
"""

from __future__ import annotations

import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError

__all__ = [
    "GaitVariability",
    "DeviceAdaptation",
    "device_adaptation",
    "lab_variability",
    "smooth_noise",
    "swing_envelope",
]

#: Leg phases (fraction of the stride from heel strike) of mid-stance and mid-swing (toe-off at 0.65).
MID_STANCE, MID_SWING = 0.325, 0.825


def _three(name: str, values, low: float, high: float) -> tuple[float, float, float]:
    v = np.asarray(values, float).ravel()
    if v.size != 3 or not np.all(np.isfinite(v)) or np.any(v < low) or np.any(v > high):
        raise LoperInputError(f"{name} must be 3 values (hip, knee, ankle) in {low} .. {high}, got {list(values)}")
    return tuple(float(x) for x in v)


@dataclass(frozen=True)
class GaitVariability:
    """Study-level stride-to-stride variability of the joint angles, per joint (hip, knee, ankle).

    Attributes
    ----------
    amplitude_cv : (3,) float
        SD of the amplitude factor about 1 (0 .. 0.3).
    offset_sd_rad : (3,) float
        SD of the offset (rad, 0 .. 0.2).
    timing_sd : (3,) float
        SD of the timing shift relative to the gait events (fraction of a
        stride, 0 .. 0.05).
    swing_gain : (3,) float
        The three SDs hold at mid-stance; they grow smoothly to this multiple
        at mid-swing (1 .. 4; :func:`swing_envelope`): the foot in the air
        varies more than the foot on the ground.
    knots_per_stride : int
        Independent values per stride (2 .. 20); sets the correlation length.
    """

    amplitude_cv: Sequence[float] = (0.0, 0.0, 0.0)
    offset_sd_rad: Sequence[float] = (0.0, 0.0, 0.0)
    timing_sd: Sequence[float] = (0.0, 0.0, 0.0)
    swing_gain: Sequence[float] = (1.0, 1.0, 1.0)
    knots_per_stride: int = 4

    def __post_init__(self):
        object.__setattr__(self, "amplitude_cv", _three("amplitude_cv", self.amplitude_cv, 0.0, 0.3))
        object.__setattr__(self, "offset_sd_rad", _three("offset_sd_rad", self.offset_sd_rad, 0.0, 0.2))
        object.__setattr__(self, "timing_sd", _three("timing_sd", self.timing_sd, 0.0, 0.05))
        object.__setattr__(self, "swing_gain", _three("swing_gain", self.swing_gain, 1.0, 4.0))
        if not (isinstance(self.knots_per_stride, (int, np.integer)) and 2 <= self.knots_per_stride <= 20):
            raise LoperInputError(f"knots_per_stride must be an integer in 2 .. 20, got {self.knots_per_stride}")


@dataclass(frozen=True)
class DeviceAdaptation:
    """A subject's systematic change of gait with the device, per joint (hip, knee, ankle).

    At mid-stance ``amplitude_factor`` multiplies the curve's excursion about
    its mean and ``offset_rad`` (rad) is added; toward mid-swing the change
    (factor - 1 and offset) grows smoothly by ``swing_gain``
    (:func:`swing_envelope`): the brace's mass acts on the thigh mostly while
    the leg swings.
    """

    amplitude_factor: Sequence[float] = (1.0, 1.0, 1.0)
    offset_rad: Sequence[float] = (0.0, 0.0, 0.0)
    swing_gain: Sequence[float] = (1.0, 1.0, 1.0)

    def __post_init__(self):
        object.__setattr__(self, "amplitude_factor", _three("amplitude_factor", self.amplitude_factor, 0.5, 1.5))
        object.__setattr__(self, "offset_rad", _three("offset_rad", self.offset_rad, -0.3, 0.3))
        object.__setattr__(self, "swing_gain", _three("swing_gain", self.swing_gain, 1.0, 4.0))
        change = np.abs(np.array(self.amplitude_factor) - 1.0) * np.array(self.swing_gain)
        if np.any(change >= 0.6):
            raise LoperInputError(
                f"amplitude_factor {self.amplitude_factor} with swing_gain {self.swing_gain} "
                "changes an amplitude by 60 % or more"
            )

    def factor_and_offset(self, joint: int, leg_phase) -> tuple[np.ndarray, np.ndarray]:
        """Amplitude factor and offset (rad) of joint ``joint`` (0 hip, 1 knee, 2 ankle) at the leg phase."""
        g = swing_envelope(leg_phase, self.swing_gain[joint])
        return 1.0 + g * (self.amplitude_factor[joint] - 1.0), g * self.offset_rad[joint]


def device_adaptation(
    seed: int,
    subject: str,
    amplitude_change: Sequence[float],
    offset_rad: Sequence[float],
    swing_gain: Sequence[float] = (1.0, 1.0, 1.0),
) -> DeviceAdaptation:
    """Draw a subject's adaptation to the device (seeded by ``seed`` and ``subject`` only).

    Per joint the amplitude factor is ``1 ± u · amplitude_change`` and the
    offset ``± u · offset_rad`` (rad), with an independent random sign and
    ``u`` uniform in 0.7 .. 1.3 for each.

    Parameters
    ----------
    seed : int
        The configuration's seed.
    subject : str
        Subject ID.
    amplitude_change : (3,) float
        Typical relative change of the amplitudes (0 .. 0.3).
    offset_rad : (3,) float
        Typical offset (rad, 0 .. 0.2).
    swing_gain : (3,) float
        Growth of the change toward mid-swing (1 .. 4, :class:`DeviceAdaptation`).
    """
    change = np.array(_three("amplitude_change", amplitude_change, 0.0, 0.3))
    offset = np.array(_three("offset_rad", offset_rad, 0.0, 0.2))
    rng = np.random.default_rng([int(seed), zlib.crc32(str(subject).encode()), zlib.crc32(b"device adaptation")])
    sign = rng.choice([-1.0, 1.0], size=(2, 3))
    size = rng.uniform(0.7, 1.3, size=(2, 3))
    return DeviceAdaptation(tuple(1.0 + sign[0] * size[0] * change), tuple(sign[1] * size[1] * offset), swing_gain)


def swing_envelope(leg_phase, gain: float) -> np.ndarray:
    """Smooth periodic SD multiplier: 1 at mid-stance, ``gain`` at mid-swing (raised cosine over the stride)."""
    x = np.asarray(leg_phase, float)
    return 1.0 + (gain - 1.0) * 0.5 * (1.0 - np.cos(2.0 * np.pi * (x - MID_STANCE)))


def smooth_noise(
    phase, first_knot: int, last_knot: int, knots_per_stride: int, sd: float, rng: np.random.Generator
) -> np.ndarray:
    """A C2 random function of the stride phase: a cubic spline through independent normal knot values.

    Knots lie at ``m / knots_per_stride`` for integers ``first_knot <= m <=
    last_knot``; their values are drawn (in that order) from N(0, sd²) and
    clipped to ± 3 sd. ``phase`` (any shape) must lie within the knots.
    Always draws ``last_knot - first_knot + 1`` values, so the stream does not
    depend on ``phase``.
    """
    m = np.arange(first_knot, last_knot + 1)
    values = np.clip(sd * rng.standard_normal(m.size), -3.0 * sd, 3.0 * sd)
    phase = np.asarray(phase, float)
    if sd == 0.0:
        return np.zeros(phase.shape)
    x = m / knots_per_stride
    if phase.size and (phase.min() < x[0] or phase.max() > x[-1]):
        raise LoperInputError(f"smooth_noise: phase {phase.min():.3f} .. {phase.max():.3f} outside the knots")
    return CubicSpline(x, values, bc_type="natural")(phase)


def lab_variability(settings: Mapping, seed: int, subject: str, truth: Mapping):
    """The variability, device adaptation and minimal-impedance walking of one synthetic subject.

    ``settings``: the ``synthetic`` settings (``variability``, ``study_variability``,
    ``device_adaptation``); ``truth``: ``{onset_ms: {joint: {"K": .., "D": ..}}}``.
    Returns ``(variability, adaptation, minimal_impedance)`` for
    :func:`loper_analysis.synthetic.trials.simulate_walking_trial`: all None for
    the gentle lab; with ``variability: study`` a :class:`GaitVariability`, the
    subject's :class:`DeviceAdaptation` and the impedance (6,) of its
    minimal-impedance walking, the mean of its true K and D over the onsets
    (order hip K, hip D, knee K, ...).
    """
    if settings["variability"] != "study":
        return None, None, None
    v, a = settings["study_variability"], settings["device_adaptation"]
    variability = GaitVariability(
        v["amplitude_cv"], v["offset_sd_rad"], v["timing_sd_stride"], v["swing_gain"], v["knots_per_stride"]
    )
    adaptation = device_adaptation(seed, subject, a["amplitude_change"], a["offset_rad"], a["swing_gain"])
    minimal_impedance = tuple(float(np.mean([truth[o][j][name] for o in truth])) for j in JOINTS for name in ("K", "D"))
    return variability, adaptation, minimal_impedance
