"""Nominal slow treadmill walking: joint-angle and pelvis curves of one stride as Fourier series.

Joint-angle curves
------------------
One stride of the right leg, phase ``0`` = heel strike, ``1`` = the next
heel strike, toe-off at :data:`CURVE_STANCE_FRACTION` (0.65, slow walking).
The curves are **not a data set**: they are smooth approximations shaped
after the textbook normal-gait curves (D. A. Winter, *Biomechanics and Motor
Control of Human Movement*, 4th ed., 2009, ch. 4 and appendix; J. Perry and
J. M. Burnfield, *Gait Analysis*, 2nd ed., 2010) with amplitudes somewhat
reduced for slow walking. A handful of key points per joint (read off the
general shape, not digitised) is interpolated by a periodic cubic spline and
truncated to 8 harmonics; the resulting coefficients are the defaults of
:class:`NominalGait` (in rad) and reproduce the key points within 0.4 degrees
(``tests/synthetic/test_gait_curves.py`` holds the key points and checks both):

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
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from loper_analysis.errors import LoperInputError

__all__ = [
    "CURVE_STANCE_FRACTION",
    "CURVE_JOINTS",
    "HIP_FLEXION_RAD",
    "KNEE_FLEXION_RAD",
    "ANKLE_DORSIFLEXION_RAD",
    "FourierSeries",
    "NominalGait",
]

#: Toe-off of the key-point curves, fraction of the stride (slow walking).
CURVE_STANCE_FRACTION: float = 0.65
#: Joint coordinates of the curves (the generic model's names without the side suffix).
CURVE_JOINTS: tuple[str, ...] = ("hip_flexion", "knee_flexion", "ankle_dorsiflexion")


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


# The Fourier series of the key points in radians (the tests check that they still agree).
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
    """Nominal slow treadmill walking of one stride (the study's 0.5 m/s at 36 strides/min).

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
        for name in (
            "hip_flexion_rad",
            "knee_flexion_rad",
            "ankle_dorsiflexion_rad",
            "pelvis_tilt_rad",
            "pelvis_ty_bob_m",
            "pelvis_tx_m",
        ):
            if not isinstance(getattr(self, name), FourierSeries):
                raise LoperInputError(f"{name} must be a FourierSeries, got {type(getattr(self, name)).__name__}")

    @property
    def stride_s(self) -> float:
        """Nominal stride duration (s)."""
        return 60.0 / self.cadence_strides_per_min

    def joint_series(self, joint: str) -> FourierSeries:
        """The series of ``joint`` in {hip_flexion, knee_flexion, ankle_dorsiflexion}."""
        if joint not in CURVE_JOINTS:
            raise LoperInputError(f"joint must be one of {CURVE_JOINTS}, got {joint!r}")
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
        return {j: self.joint_series(j)(psi) for j in CURVE_JOINTS}
