"""Nominal slow treadmill walking, stride-variable trials and split-belt ground reaction forces.

Joint-angle curves
------------------
One stride of the right leg, phase ``0`` = heel strike, ``1`` = the next
heel strike, toe-off at :data:`CURVE_STANCE_FRACTION` (0.65, slow walking).
The curves are **not a data set**: they are smooth approximations shaped
after the textbook normal-gait curves (D. A. Winter, *Biomechanics and Motor
Control of Human Movement*, 4th ed., 2009, ch. 4 and appendix; J. Perry and
J. M. Burnfield, *Gait Analysis*, 2nd ed., 2010) with amplitudes somewhat
reduced for slow walking. A handful of key points per joint
(:data:`CURVE_KEYPOINTS_DEG`, read off the general shape, not digitised) is
interpolated by a periodic cubic spline and truncated to
:data:`N_HARMONICS` harmonics (:func:`fourier_from_keypoints`); the
resulting coefficients are the defaults of :class:`NominalGait` (in rad) and
reproduce the key points within 0.4 degrees:

* hip flexion: +25 deg at heel strike, -10 deg in late stance (58 %),
  +27.6 deg peak in late swing (86 %), range 37.6 deg;
* knee flexion: 5 deg at heel strike, 15 deg loading peak (15 %), 5 deg in
  mid-stance (40 %), 60 deg swing peak (76 %), extended to 6 deg by 97 %;
* ankle dorsiflexion: 0 at heel strike, -5 deg at foot flat (7 %), +10 deg
  in late stance (48 %), -12 deg just after toe-off (68 %), back to neutral
  by 79 %, +3 deg in mid-swing.

The timing in swing (knee extended and ankle neutral early enough) was tuned
so that the planar stick figure of the model keeps its feet on the floor:
over the stance phase the lowest sole point of the stance foot stays within
-0.4 .. +0.9 cm of the floor; the swing foot dips at most 0.6 cm below it
(a sagittal model has no pelvic obliquity to lift it).

The pelvis has a mean anterior tilt of 10 deg (``pelvis_tilt`` = -10 deg;
positive ``pelvis_tilt`` turns X toward Y, i.e. the front of the pelvis up)
with a +-2 deg oscillation, a +-1 cm vertical bob and a +-1 cm fore-aft
oscillation, all at twice the stride frequency. The hip angles are relative
to the pelvis (as in the textbooks), so the tilt matters for the feet:
without it the stance foot would leave the floor by up to 5 cm. The pelvis
height is the mean hip height that puts the lowest point of the feet on the
floor (:func:`pelvis_height_m`), plus the bob, which is highest in
mid-stance (32 % of the stride).

Known limitation: the curves are those of a longer stride than 0.5 m/s x
1.667 s = 0.83 m; the stance foot moves backward relative to the pelvis at
about 0.7 m/s in mid-stance (1.75 m model), not at the belt speed.

The left leg follows the same curves half a stride later.

Trial simulation
----------------
:func:`walking_kinematics` builds a stride phase ``Phi(t)`` that is integer
at every right heel strike. Stride durations are drawn from a normal
distribution (CV ``timing_cv``) and ``Phi`` is the monotone piecewise-cubic
(PCHIP, C1) interpolant through (heel-strike time, stride number), so the
strides have exactly the drawn durations and the angles have no jumps and no
velocity steps. Every leg and joint has one amplitude factor per stride
(normal, mean 1, CV ``amplitude_cv``) that scales the curve about its mean; the
factors are blended between heel strikes with a raised-cosine (C1) weight.
Gait events are the times at which the phase of a leg passes 0 (heel strike)
or the stance fraction (toe-off).

Treadmill forces
----------------
:func:`treadmill_grf` gives each belt (left foot on the left belt) a vertical
force that is zero in swing and, in stance, a step of ``edge_n`` at heel
strike followed by a smooth double hump (peaks about 1.1 body weight at the
end of the loading double support and at the start of push-off, valley about
0.8 body weight at mid-stance), back to ``edge_n`` just before toe-off and
zero from toe-off on. The step is the "rise time": it happens between two
analog samples (0 -> ``edge_n`` in less than one sample period), so a
threshold below ``edge_n`` minus a few noise SDs finds heel strike at the
first sample at or after the true event and toe-off at the first sample at or
after the true toe-off, i.e. always within one sample period. The shape is
scaled so that both belts together average body weight over the strides of
the events. Belt coordinates: x forward, y to the left, z up (right-handed,
Z-up like the motion-capture lab); each belt's origin is under the centre of
pressure at mid-stance.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.interpolate import CubicHermiteSpline, CubicSpline, PchipInterpolator

from ..constants import GRAVITY_M_PER_S2
from ..errors import LoperInputError
from ..model import COORDINATES, _anthropometry

__all__ = [
    "CURVE_KEYPOINTS_DEG",
    "CURVE_STANCE_FRACTION",
    "N_HARMONICS",
    "EVENT_COLUMNS",
    "GRF_COLUMNS",
    "HIP_FLEXION_RAD",
    "KNEE_FLEXION_RAD",
    "ANKLE_DORSIFLEXION_RAD",
    "FourierSeries",
    "NominalGait",
    "fourier_from_keypoints",
    "leg_length_from_height",
    "pelvis_height_m",
    "walking_kinematics",
    "treadmill_grf",
]

#: Toe-off of the key-point curves, fraction of the stride (slow walking).
CURVE_STANCE_FRACTION: float = 0.65
#: Harmonics kept in the joint-angle Fourier series.
N_HARMONICS: int = 8
#: Key points of the joint-angle curves: (stride fraction, degrees); heel strike at 0, toe-off at 0.65.
CURVE_KEYPOINTS_DEG: dict[str, tuple[tuple[float, float], ...]] = {
    "hip_flexion": (
        (0.00, 25.0), (0.10, 24.0), (0.30, 10.0), (0.50, -5.0), (0.58, -10.0),
        (0.65, -3.0), (0.73, 15.0), (0.83, 27.0), (0.92, 26.5),
    ),
    "knee_flexion": (
        (0.00, 5.0), (0.06, 10.0), (0.15, 15.0), (0.26, 10.0), (0.40, 5.0), (0.48, 7.0),
        (0.56, 16.0), (0.65, 38.0), (0.71, 55.0), (0.76, 60.0), (0.80, 57.0), (0.86, 35.0),
        (0.92, 14.0), (0.97, 6.0),
    ),
    "ankle_dorsiflexion": (
        (0.00, 0.0), (0.07, -5.0), (0.16, -1.0), (0.30, 5.0), (0.47, 10.0), (0.55, 7.0),
        (0.61, -3.0), (0.68, -12.0), (0.73, -6.0), (0.79, 1.0), (0.87, 3.0), (0.94, 1.0),
    ),
}
#: Columns of the events frame.
EVENT_COLUMNS: tuple[str, ...] = ("side", "event", "time_s")
#: Columns of the treadmill force frame (N, N·m, m; belt frame x forward, y left, z up).
GRF_COLUMNS: tuple[str, ...] = (
    "time_s",
    "fz_left_n", "fz_right_n",
    "fx_left_n", "fx_right_n",
    "mx_left_nm", "mx_right_nm",
    "my_left_nm", "my_right_nm",
    "mz_left_nm", "mz_right_nm",
    "cop_x_left_m", "cop_x_right_m",
    "cop_y_left_m", "cop_y_right_m",
)

_SIDES = {"right": "r", "left": "l"}
_JOINTS = ("hip_flexion", "knee_flexion", "ankle_dorsiflexion")


@dataclass(frozen=True)
class FourierSeries:
    """A stride-periodic curve ``mean + sum_n cos[n-1]·cos(2πnφ) + sin[n-1]·sin(2πnφ)``.

    ``φ`` is the stride phase (1 = one stride); the unit of the coefficients is
    that of the curve (rad or m, named by the field that holds the series).
    """

    mean: float
    cos: tuple[float, ...] = ()
    sin: tuple[float, ...] = ()

    def __post_init__(self):
        cos = tuple(float(c) for c in self.cos)
        sin = tuple(float(s) for s in self.sin)
        if len(cos) != len(sin):
            raise LoperInputError(f"FourierSeries: cos and sin need the same length, got {len(cos)} and {len(sin)}")
        if not np.all(np.isfinite([self.mean, *cos, *sin])):
            raise LoperInputError("FourierSeries: coefficients must be finite")
        object.__setattr__(self, "mean", float(self.mean))
        object.__setattr__(self, "cos", cos)
        object.__setattr__(self, "sin", sin)

    def __call__(self, phase) -> np.ndarray:
        """Curve values at stride phase ``phase`` (any shape; periodic with period 1)."""
        phase = np.asarray(phase, float)
        out = np.full(phase.shape, self.mean)
        for n, (a, b) in enumerate(zip(self.cos, self.sin), start=1):
            w = 2.0 * np.pi * n * phase
            out = out + a * np.cos(w) + b * np.sin(w)
        return out

    def derivative(self, phase) -> np.ndarray:
        """d(curve)/d(phase) at ``phase`` (unit per stride)."""
        phase = np.asarray(phase, float)
        out = np.zeros(phase.shape)
        for n, (a, b) in enumerate(zip(self.cos, self.sin), start=1):
            w = 2.0 * np.pi * n
            out = out + w * (b * np.cos(w * phase) - a * np.sin(w * phase))
        return out


def _second_harmonic(mean: float, amplitude: float, peak_phase: float) -> FourierSeries:
    """``mean + amplitude·cos(4π(φ - peak_phase))`` as a :class:`FourierSeries`."""
    w = 4.0 * np.pi * peak_phase
    return FourierSeries(mean, (0.0, amplitude * np.cos(w)), (0.0, amplitude * np.sin(w)))


def fourier_from_keypoints(phase, values, n_harmonics: int = N_HARMONICS, n_samples: int = 1000) -> FourierSeries:
    """Fourier series of the periodic cubic spline through key points.

    Parameters
    ----------
    phase : array_like, shape (k,)
        Stride fractions in [0, 1), strictly increasing; the curve closes at 1
        with the value at ``phase[0]`` (which must be 0).
    values : array_like, shape (k,)
        Curve values at the key points (any unit; the series has the same).
    n_harmonics : int
        Harmonics kept (>= 1, < n_samples / 2).
    n_samples : int
        Samples of the spline per stride for the discrete Fourier transform.

    Returns
    -------
    FourierSeries

    Raises
    ------
    LoperInputError
        Fewer than 3 key points, phases not strictly increasing in [0, 1) or
        not starting at 0, non-finite values, bad ``n_harmonics``.
    """
    p = np.asarray(phase, float)
    v = np.asarray(values, float)
    if p.ndim != 1 or p.shape != v.shape or p.size < 3:
        raise LoperInputError(f"phase and values must be 1-D of equal length >= 3, got {p.shape} and {v.shape}")
    if not (np.all(np.isfinite(p)) and np.all(np.isfinite(v))):
        raise LoperInputError("phase and values must be finite")
    if p[0] != 0.0 or p[-1] >= 1.0 or np.any(np.diff(p) <= 0):
        raise LoperInputError(f"phase must start at 0 and increase strictly below 1, got {p.tolist()}")
    if not 1 <= n_harmonics < n_samples // 2:
        raise LoperInputError(f"n_harmonics must lie in 1 .. {n_samples // 2 - 1}, got {n_harmonics}")
    spline = CubicSpline(np.append(p, 1.0), np.append(v, v[0]), bc_type="periodic")
    y = spline(np.arange(n_samples) / n_samples)
    F = np.fft.rfft(y) / n_samples
    return FourierSeries(
        float(F[0].real),
        tuple(float(c) for c in 2.0 * F[1 : n_harmonics + 1].real),
        tuple(float(s) for s in -2.0 * F[1 : n_harmonics + 1].imag),
    )


# Generated by fourier_from_keypoints(phase, radians(degrees)) from CURVE_KEYPOINTS_DEG
# (tests/test_synthetic_gait.py checks that they still agree).
HIP_FLEXION_RAD = FourierSeries(
    0.219964,
    (0.294783, -0.056611, -0.028353, 0.010437, -0.004039, 0.000187, -0.000035, 0.000464),
    (0.001651, -0.068507, 0.040565, -0.001134, -0.001554, 0.000996, -0.000051, -0.000532),
)
KNEE_FLEXION_RAD = FourierSeries(
    0.360020,
    (0.010811, -0.251256, -0.042372, 0.010269, 0.004685, 0.001852, -0.001570, -0.004019),
    (-0.342672, 0.045845, 0.091863, 0.018056, -0.001030, -0.002695, -0.003805, -0.000676),
)
ANKLE_DORSIFLEXION_RAD = FourierSeries(
    0.021188,
    (-0.055061, 0.043433, -0.052052, 0.019619, 0.015239, -0.001208, 0.004500, 0.003469),
    (0.054925, -0.087798, -0.018857, 0.019173, -0.013384, 0.000576, 0.003719, -0.000573),
)


@dataclass(frozen=True)
class NominalGait:
    """Nominal slow treadmill walking of one stride (DESIGN.md section 2).

    Attributes
    ----------
    treadmill_speed_m_per_s : float
        Belt speed (m/s); moves the centre of pressure in :func:`treadmill_grf`.
    cadence_strides_per_min : float
        Metronome cadence (strides/min); the stride lasts ``60 / cadence`` s.
    stance_fraction : float
        Toe-off as a fraction of the stride (0.5 .. 0.85). When it differs from
        ``curve_stance_fraction`` the curves are time-warped (monotone C1 cubic)
        so that their toe-off lands here.
    curve_stance_fraction : float
        Toe-off of the joint-angle curves below.
    hip_flexion_rad, knee_flexion_rad, ankle_dorsiflexion_rad : FourierSeries
        Right-leg joint angles over one stride from heel strike (rad).
    pelvis_tilt_rad : FourierSeries
        Pelvis tilt (rad, positive = front up), over the right stride.
    pelvis_ty_bob_m : FourierSeries
        Vertical pelvis excursion about its mean height (m, mean 0).
    pelvis_tx_m : FourierSeries
        Fore-aft pelvis position on the treadmill (m).
    """

    treadmill_speed_m_per_s: float = 0.5
    cadence_strides_per_min: float = 36.0
    stance_fraction: float = CURVE_STANCE_FRACTION
    curve_stance_fraction: float = CURVE_STANCE_FRACTION
    hip_flexion_rad: FourierSeries = HIP_FLEXION_RAD
    knee_flexion_rad: FourierSeries = KNEE_FLEXION_RAD
    ankle_dorsiflexion_rad: FourierSeries = ANKLE_DORSIFLEXION_RAD
    pelvis_tilt_rad: FourierSeries = field(
        default_factory=lambda: _second_harmonic(np.deg2rad(-10.0), np.deg2rad(2.0), 0.15)
    )
    pelvis_ty_bob_m: FourierSeries = field(default_factory=lambda: _second_harmonic(0.0, 0.01, 0.32))
    pelvis_tx_m: FourierSeries = field(default_factory=lambda: _second_harmonic(0.0, 0.01, 0.185))

    def __post_init__(self):
        if not 0 < self.treadmill_speed_m_per_s <= 5:
            raise LoperInputError(f"treadmill_speed_m_per_s must lie in 0 .. 5 m/s, got {self.treadmill_speed_m_per_s}")
        if not 10 <= self.cadence_strides_per_min <= 120:
            raise LoperInputError(f"cadence_strides_per_min must lie in 10 .. 120, got {self.cadence_strides_per_min}")
        for name in ("stance_fraction", "curve_stance_fraction"):
            value = getattr(self, name)
            if not 0.5 < value < 0.85:
                raise LoperInputError(f"{name} must lie in 0.5 .. 0.85 (walking), got {value}")
        for name in ("hip_flexion_rad", "knee_flexion_rad", "ankle_dorsiflexion_rad", "pelvis_tilt_rad",
                     "pelvis_ty_bob_m", "pelvis_tx_m"):
            if not isinstance(getattr(self, name), FourierSeries):
                raise LoperInputError(f"{name} must be a FourierSeries, got {type(getattr(self, name)).__name__}")

    @property
    def stride_s(self) -> float:
        """Nominal stride duration (s)."""
        return 60.0 / self.cadence_strides_per_min

    def joint_series(self, joint: str) -> FourierSeries:
        """The series of ``joint`` in {hip_flexion, knee_flexion, ankle_dorsiflexion}."""
        if joint not in _JOINTS:
            raise LoperInputError(f"joint must be one of {_JOINTS}, got {joint!r}")
        return getattr(self, f"{joint}_rad")

    def curve_phase(self, stride_phase) -> np.ndarray:
        """Map the stride phase (toe-off at ``stance_fraction``) onto the curves' phase.

        Identity when both stance fractions agree; otherwise a monotone C1
        cubic Hermite warp through (0, 0), (stance_fraction,
        curve_stance_fraction), (1, 1), periodic in slope. Input and output in
        [0, 1).
        """
        x = np.mod(np.asarray(stride_phase, float), 1.0)
        s, s0 = self.stance_fraction, self.curve_stance_fraction
        if s == s0:
            return x
        d1, d2 = s0 / s, (1.0 - s0) / (1.0 - s)

        def slope(h_prev, d_prev, h_next, d_next):  # Fritsch-Butland weighted harmonic mean (PCHIP)
            w1, w2 = 2 * h_next + h_prev, h_next + 2 * h_prev
            return (w1 + w2) / (w1 / d_prev + w2 / d_next)

        m0 = slope(1.0 - s, d2, s, d1)
        ms = slope(s, d1, 1.0 - s, d2)
        warp = CubicHermiteSpline([0.0, s, 1.0], [0.0, s0, 1.0], [m0, ms, m0])
        return np.clip(warp(x), 0.0, np.nextafter(1.0, 0.0))

    def joint_angles(self, stride_phase) -> dict[str, np.ndarray]:
        """Nominal right-leg joint angles (rad) at the stride phase; the left leg uses ``phase - 0.5``."""
        psi = self.curve_phase(stride_phase)
        return {j: self.joint_series(j)(psi) for j in _JOINTS}


def leg_length_from_height(height_m: float) -> float:
    """Standing hip-joint height (m) of the model for a body height (m): thigh + shank + ankle height."""
    if not 1.0 <= height_m <= 2.5:
        raise LoperInputError(f"height_m must lie in 1 .. 2.5 m, got {height_m}")
    seg = _anthropometry(float(height_m), 1.0)
    return float(seg["segments"]["thigh"]["length"] + seg["segments"]["shank"]["length"] + seg["ankle_height"])


def _leg_geometry(leg_length_m: float) -> dict[str, float]:
    """Segment lengths (m) of the model whose standing hip height is ``leg_length_m``."""
    height = leg_length_m / leg_length_from_height(1.0)
    a = _anthropometry(height, 1.0)
    s = a["segments"]
    return {
        "thigh": s["thigh"]["length"], "shank": s["shank"]["length"],
        "foot": s["foot"]["length"], "ankle_height": a["ankle_height"],
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


def _check_rng(rng) -> np.random.Generator:
    if not isinstance(rng, np.random.Generator):
        raise LoperInputError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    return rng


def _solve_phase(phase_of_t: PchipInterpolator, knot_t: np.ndarray, knot_phase0: int, targets: np.ndarray) -> np.ndarray:
    """Times at which the monotone phase reaches ``targets`` (bisection inside the bracketing stride)."""
    k = np.floor(targets).astype(int) - knot_phase0
    lo, hi = knot_t[k].copy(), knot_t[k + 1].copy()
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        below = phase_of_t(mid) < targets
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    return 0.5 * (lo + hi)


def walking_kinematics(
    duration_s: float,
    sample_rate_hz: float,
    gait: NominalGait,
    rng: np.random.Generator,
    timing_cv: float = 0.03,
    amplitude_cv: float = 0.05,
    leg_length_m: float | None = None,
    start_phase: float | None = None,
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

    Returns
    -------
    coordinates : pandas.DataFrame, shape (n_samples, 10)
        ``time_s`` and the model coordinates :data:`loper_analysis.model.COORDINATES`
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
    if not isinstance(gait, NominalGait):
        raise LoperInputError(f"gait must be a NominalGait, got {type(gait).__name__}")
    rng = _check_rng(rng)
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
    amps = np.clip(1.0 + amplitude_cv * rng.standard_normal((2, len(_JOINTS), knot_t.size + 2)), 0.5, 1.5)

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
        for j, joint in enumerate(_JOINTS):
            a = amps[i_leg, j, idx] * (1.0 - w) + amps[i_leg, j, idx + 1] * w
            series = gait.joint_series(joint)
            out[f"{joint}_{side}"] = series.mean + a * (series(psi) - series.mean)
    coordinates = pd.DataFrame({c: out[c] for c in ("time_s", *COORDINATES)})

    s = gait.stance_fraction
    first, last = int(np.floor(Phi[0])) - 1, int(np.ceil(phase_of_t(duration_s))) + 1
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
    events = pd.DataFrame(rows, columns=list(EVENT_COLUMNS)).sort_values("time_s", kind="stable").reset_index(drop=True)
    return coordinates, events


def _stances(events: pd.DataFrame) -> tuple[dict[str, list[tuple[float, float]]], float, float]:
    """Stance intervals per side (start, end) in s, the typical stance duration and the mean stance fraction.

    A leading toe-off (foot already in stance at the start) starts one typical
    stance earlier; a trailing heel strike ends one typical stance later.
    """
    complete, strides = [], []
    pending: dict[str, tuple[list, list]] = {}
    for side in ("left", "right"):
        ev = events[events["side"] == side].sort_values("time_s", kind="stable")
        kinds, times = ev["event"].tolist(), ev["time_s"].to_numpy(float)
        for i in range(1, len(kinds)):
            if kinds[i] == kinds[i - 1]:
                raise LoperInputError(
                    f"events: {side} {kinds[i]} at {times[i]:.4f} s follows another {kinds[i]} "
                    f"(at {times[i - 1]:.4f} s); heel strikes and toe-offs must alternate per side"
                )
        intervals, open_ends = [], []
        for i, (kind, tt) in enumerate(zip(kinds, times)):
            if kind == "heel_strike":
                if i + 1 < len(kinds):
                    intervals.append((tt, times[i + 1]))
                    complete.append(times[i + 1] - tt)
                else:
                    open_ends.append(("end", tt))
            elif i == 0:
                open_ends.append(("start", tt))
            if i >= 2:
                strides.append(tt - times[i - 2])
        pending[side] = (intervals, open_ends)
    if not complete or not strides:
        raise LoperInputError("events: need at least one complete stance (heel strike -> toe-off) and one stride")
    stance = float(np.median(complete))
    fraction = float(np.mean(complete) / np.mean(strides))
    out = {}
    for side, (intervals, open_ends) in pending.items():
        for where, tt in open_ends:
            intervals.append((tt - stance, tt) if where == "start" else (tt, tt + stance))
        out[side] = sorted(intervals)
    return out, stance, fraction


#: Normalised vertical-force shape over stance (fraction of stance, body weights), without the edge step.
_FZ_KNOTS = (
    (0.0, 0.0), (0.1, 0.35), (0.22, 1.1), (0.36, 0.85), (0.5, 0.72),
    (0.64, 0.85), (0.78, 1.1), (0.9, 0.35), (1.0, 0.0),
)


def treadmill_grf(
    events: pd.DataFrame,
    duration_s: float,
    analog_rate_hz: float,
    body_mass_kg: float,
    rng: np.random.Generator | None = None,
    noise_sd_n: float = 2.0,
    edge_n: float = 100.0,
    belt_speed_m_per_s: float = 0.5,
    foot_length_m: float = 0.26,
    ap_peak_fraction: float = 0.1,
) -> pd.DataFrame:
    """Split-belt treadmill forces and moments (left foot on the left belt) from gait events.

    Vertical force in stance: ``edge_n + c·BW·Q(u)``, ``u`` = fraction of the
    stance, ``Q`` the monotone cubic (PCHIP) through the knots (0, 0),
    (0.1, 0.35), (0.22, 1.1), (0.36, 0.85), (0.5, 0.72) and their mirror images
    (body weights), ``c`` set so that both belts together average body weight
    (``BW = m·g``) given the mean stance fraction of the events (70 kg,
    ``edge_n`` = 100 N, stance fraction 0.65: ``c`` = 0.88, peaks 1.11 BW at
    22 % and 78 % of stance, valley 0.78 BW). Zero in swing; the force steps
    from 0 to ``edge_n`` at heel strike and back to 0 at toe-off (stance is
    ``heel strike <= t < toe-off``), see the module docstring for the rise time.

    Fore-aft force ``-ap_peak_fraction·BW·sin(2πu)``: braking (negative) in the
    first half of stance, propulsion in the second; zero net impulse.

    Centre of pressure in the belt frame (x forward, y left, origin under the
    COP at mid-stance): it rolls from the heel 0.8 foot lengths forward while
    the belt carries the foot backward, ``x = 0.8·L_foot·(u - 0.5) -
    v_belt·(t - t_mid)``; ``y`` runs from 1 cm lateral to 1 cm medial. Moments
    about the belt origin for a force applied on the belt surface (z = 0,
    mediolateral force 0): ``mx = y·fz``, ``my = -x·fz``, ``mz = -y·fx`` plus a
    free moment of 0.

    Gaussian noise (SD ``noise_sd_n``) is added to every force sample, and
    ``noise_sd_n × 0.05 m`` to every moment sample, in swing too; the COP
    columns are noise-free and NaN in swing (undefined).

    Parameters
    ----------
    events : pandas.DataFrame
        ``side``, ``event``, ``time_s`` as from :func:`walking_kinematics`;
        heel strikes and toe-offs must alternate per side. A first toe-off
        without a heel strike before it (foot in stance at the start) starts
        one typical (median) stance earlier; a last heel strike without a
        toe-off ends one typical stance later.
    duration_s : float
        Trial duration (s); ``round(duration_s * analog_rate_hz)`` samples from 0.
    analog_rate_hz : float
        Analog sample rate (Hz), e.g. 1024.
    body_mass_kg : float
        Body mass (kg), 0 .. 300.
    rng : numpy.random.Generator or None
        Noise source; None = a fixed seed (0), still reproducible.
    noise_sd_n : float
        SD of the force noise (N), >= 0.
    edge_n : float
        Force step at heel strike and toe-off (N); keep it above the event
        threshold plus a few noise SDs, and below half body weight.
    belt_speed_m_per_s : float
        Belt speed (m/s), moves the COP backward during stance.
    foot_length_m : float
        Foot length (m) for the COP roll.
    ap_peak_fraction : float
        Peak fore-aft force as a fraction of body weight (0 .. 0.5).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`GRF_COLUMNS`: ``time_s``; ``fz_*_n``, ``fx_*_n`` (N);
        ``mx_*_nm``, ``my_*_nm``, ``mz_*_nm`` (N·m); ``cop_x_*_m``,
        ``cop_y_*_m`` (m, NaN in swing).

    Raises
    ------
    LoperInputError
        Missing columns, unknown side or event names, non-finite times,
        events that do not alternate per side, no complete stance or stride,
        out-of-range arguments.
    """
    if not isinstance(events, pd.DataFrame) or not set(EVENT_COLUMNS) <= set(events.columns):
        raise LoperInputError(f"events must be a DataFrame with columns {list(EVENT_COLUMNS)}")
    bad_side = sorted(set(events["side"]) - set(_SIDES))
    bad_event = sorted(set(events["event"]) - {"heel_strike", "toe_off"})
    if bad_side or bad_event:
        raise LoperInputError(f"events: unknown side(s) {bad_side} or event(s) {bad_event}")
    if not np.all(np.isfinite(events["time_s"].to_numpy(float))):
        raise LoperInputError("events: time_s must be finite")
    if not (np.isfinite(duration_s) and duration_s > 0):
        raise LoperInputError(f"duration_s must be > 0, got {duration_s}")
    if not (np.isfinite(analog_rate_hz) and analog_rate_hz > 0):
        raise LoperInputError(f"analog_rate_hz must be > 0, got {analog_rate_hz}")
    if not 0 < body_mass_kg <= 300:
        raise LoperInputError(f"body_mass_kg must lie in 0 .. 300 kg, got {body_mass_kg}")
    if not noise_sd_n >= 0:
        raise LoperInputError(f"noise_sd_n must be >= 0, got {noise_sd_n}")
    bw = body_mass_kg * GRAVITY_M_PER_S2
    if not 0 < edge_n < 0.5 * bw:
        raise LoperInputError(f"edge_n must lie in 0 .. {0.5 * bw:.1f} N (half body weight), got {edge_n}")
    if not 0 <= belt_speed_m_per_s <= 5:
        raise LoperInputError(f"belt_speed_m_per_s must lie in 0 .. 5 m/s, got {belt_speed_m_per_s}")
    if not 0 < foot_length_m <= 0.5:
        raise LoperInputError(f"foot_length_m must lie in 0 .. 0.5 m, got {foot_length_m}")
    if not 0 <= ap_peak_fraction <= 0.5:
        raise LoperInputError(f"ap_peak_fraction must lie in 0 .. 0.5, got {ap_peak_fraction}")
    rng = np.random.default_rng(0) if rng is None else _check_rng(rng)
    n = int(round(duration_s * analog_rate_hz))
    if n < 2:
        raise LoperInputError(f"duration_s * analog_rate_hz must give >= 2 samples, got {n}")

    stances, _, fraction = _stances(events)
    shape = PchipInterpolator(*np.array(_FZ_KNOTS).T)
    q_mean = float(shape.integrate(0.0, 1.0))
    scale = (bw / (2.0 * fraction) - edge_n) / (bw * q_mean)
    if scale <= 0:
        raise LoperInputError(
            f"edge_n = {edge_n} N is too large for body weight {bw:.0f} N at stance fraction {fraction:.2f}"
        )

    t = np.arange(n) / analog_rate_hz
    cols = {"time_s": t}
    for side in ("left", "right"):
        fz, fx = np.zeros(n), np.zeros(n)
        cx, cy = np.full(n, np.nan), np.full(n, np.nan)
        lateral = 1.0 if side == "left" else -1.0  # +y is left
        for t_on, t_off in stances[side]:
            idx = slice(int(np.searchsorted(t, t_on, "left")), int(np.searchsorted(t, t_off, "left")))
            ts = t[idx]  # t_on <= ts < t_off
            if ts.size == 0:
                continue
            dur = t_off - t_on
            u = (ts - t_on) / dur
            fz[idx] = edge_n + scale * bw * shape(u)
            fx[idx] = -ap_peak_fraction * bw * np.sin(2.0 * np.pi * u)
            cx[idx] = 0.8 * foot_length_m * (u - 0.5) - belt_speed_m_per_s * (ts - t_on - 0.5 * dur)
            cy[idx] = lateral * 0.01 * (1.0 - 2.0 * u)
        x0, y0 = np.nan_to_num(cx), np.nan_to_num(cy)
        cols[f"fz_{side}_n"] = fz
        cols[f"fx_{side}_n"] = fx
        cols[f"mx_{side}_nm"] = y0 * fz
        cols[f"my_{side}_nm"] = -x0 * fz
        cols[f"mz_{side}_nm"] = -y0 * fx
        cols[f"cop_x_{side}_m"] = cx
        cols[f"cop_y_{side}_m"] = cy
    if noise_sd_n > 0:
        for name in GRF_COLUMNS[1:11]:
            sd = noise_sd_n if name.endswith("_n") else noise_sd_n * 0.05
            cols[name] = cols[name] + rng.normal(0.0, sd, n)
    return pd.DataFrame({c: cols[c] for c in GRF_COLUMNS})
