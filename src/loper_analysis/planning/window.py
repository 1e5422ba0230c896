"""The planned experiment as the fit would see it: the planner's settings and its identification window
(method: ``docs/planning.md``).

* :class:`PlanSettings` - the planned pulse, impedance and the fit's window and bounds;
* :func:`planning_window` - the identification window of the planned experiment: the pilot's mean
  unperturbed swing as the reference, the pulse along the thigh normal.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from loper_analysis.checks import number
from loper_analysis.constants import COUPLING_UNIT, PARAMETER_UNITS, PARAMETERS
from loper_analysis.device.controller import DeviceParameters
from loper_analysis.errors import LoperInputError
from loper_analysis.filtering import CUTOFF_HZ, ORDER
from loper_analysis.impedance.identification import (
    FitBounds,
    PreparedWindow,
    check_interval_scatter,
    prepare_window,
    window_options,
)
from loper_analysis.impedance.identification.fit import (
    COUPLING_BOUNDS_NM_PER_RAD,
    DAMPING_BOUNDS_NMS_PER_RAD,
    STIFFNESS_BOUNDS_NM_PER_RAD,
)
from loper_analysis.impedance.identification.null_pairs import MIN_NULL_PAIRS, NULL_PAIR_COMPONENTS
from loper_analysis.impedance.identification.window import INITIAL_STATE_DEGREE, N_SUBSTEPS, check_couplings
from loper_analysis.impedance.responses.response_window import ResponseWindow
from loper_analysis.planning.inputs import pulse_force_n
from loper_analysis.study_design import PULSE_DURATION_S, PULSE_FORCE_N
from loper_analysis.swing_leg.dynamics import SegmentParameters
from loper_analysis.swing_leg.rods import ShankRod, segment_normal, shank_rod_direction

__all__ = ["null_pair_arrays", "planned_impedance", "PlanSettings", "planning_window"]


@dataclass(frozen=True)
class PlanSettings(FitBounds):
    """The planned pulse and the identification settings the prediction follows (config ``identification``).

    ``pulse_force_n`` (N, desired force) for ``pulse_duration_s`` (s) from the
    onset; ``window`` (:class:`~loper_analysis.impedance.responses.response_window.ResponseWindow`: the fit's
    window and initial-state span, s), ``initial_state_degree``, ``n_substeps``, ``null_pair_components``,
    ``min_null_pairs``, ``interval_scatter`` (whose scatter the fit's
    intervals take, hence their t quantile) and the bounds (N·m/rad,
    N·m·s/rad) as the fit uses them; ``force_cutoff_hz`` and ``force_order``
    the load cell's low-pass; ``force_rate_hz`` the rate of the pulse given
    to the fit (the robot log's). ``shank_pulse_force_n`` (N): a second rod's pulse, just above the ankle where
    ``shank_rod`` (:class:`~loper_analysis.swing_leg.rods.ShankRod`) places and points it, pushed with the
    thigh's (same timing and device); 0: the thigh rod alone. ``couplings``: inter-joint stiffnesses the planned
    fit adds to K and D per joint (names of :data:`~loper_analysis.constants.COUPLINGS`, e.g. ``("hip_knee",)``
    for the bi-articular hip-knee stiffness), within ``coupling_bounds_nm_per_rad`` (N·m/rad); the plan then
    predicts their SD too and says whether the design identifies them
    (:func:`loper_analysis.planning.precision.precision_table`).
    """

    pulse_force_n: float = PULSE_FORCE_N
    pulse_duration_s: float = PULSE_DURATION_S
    window: ResponseWindow = field(default_factory=ResponseWindow)
    initial_state_degree: int = INITIAL_STATE_DEGREE
    n_substeps: int = N_SUBSTEPS
    null_pair_components: int = NULL_PAIR_COMPONENTS
    min_null_pairs: int = MIN_NULL_PAIRS
    interval_scatter: str = "cross_validated_null_pairs"
    stiffness_bounds_nm_per_rad: tuple[float, float] = STIFFNESS_BOUNDS_NM_PER_RAD
    damping_bounds_nms_per_rad: tuple[float, float] = DAMPING_BOUNDS_NMS_PER_RAD
    force_cutoff_hz: float = CUTOFF_HZ
    force_order: int = ORDER
    force_rate_hz: float = DeviceParameters.sample_rate_hz
    shank_pulse_force_n: float = 0.0
    shank_rod: ShankRod = field(default_factory=ShankRod)
    couplings: tuple[str, ...] = ()
    coupling_bounds_nm_per_rad: tuple[float, float] = COUPLING_BOUNDS_NM_PER_RAD

    def __post_init__(self):
        object.__setattr__(self, "couplings", check_couplings(self.couplings))
        number("pulse_force_n", self.pulse_force_n)
        number("shank_pulse_force_n", self.shank_pulse_force_n)
        check_interval_scatter(self.interval_scatter)
        if number("force_rate_hz", self.force_rate_hz) <= 0:
            raise LoperInputError(f"force_rate_hz must be > 0 Hz, got {self.force_rate_hz:g}")
        self.window.check_pulse(self.pulse_duration_s)


def planning_window(
    null_pairs: Mapping,
    params: SegmentParameters,
    settings: PlanSettings = PlanSettings(),
    device=None,
    source: str = "pilot",
) -> PreparedWindow:
    """The identification window of the planned experiment (onset at t = 0).

    Reference: the mean of the pilot's unperturbed null-pair strides
    (``null_pairs["q_unperturbed"]`` (M, n, 4) and
    ``pelvis_angle_unperturbed_rad`` (M, n), on the grid ``time_s`` (n,)
    relative to the onset; :func:`loper_analysis.impedance.responses.null_pair_windows`),
    the mean swing a perturbed stride starts from. The perturbed force is
    :func:`pulse_force_n` along the thigh's forward normal of that swing (and, with
    ``settings.shank_pulse_force_n``, a second rod's along the shank's, at
    the point and angle of ``settings.shank_rod``),
    given to the fit at ``settings.force_rate_hz`` (``force_time_s`` of
    :func:`~loper_analysis.impedance.identification.prepare_window`, as the fit takes
    the robot log's samples); the minimal-impedance force and the initial
    deviation are zero (they average out over the perturbed strides).
    ``measured`` is zero: only the model's sensitivities are used.
    """
    t, arrays, n_pairs = null_pair_arrays(null_pairs, source)
    if n_pairs < 1:
        raise LoperInputError(f"{source}: no null pairs: the pilot needs unperturbed strides walked with the device")
    q_ref = arrays["q_unperturbed"].mean(axis=0)
    pelvis = arrays["pelvis_angle_unperturbed_rad"].mean(axis=0)
    rate = float(settings.force_rate_hz)
    t_force = np.arange(math.ceil(t[0] * rate - 1e-6), math.floor(t[-1] * rate + 1e-6) + 1) / rate
    force = pulse_force_n(
        t_force,
        settings.pulse_force_n,
        settings.pulse_duration_s,
        device,
        settings.force_cutoff_hz,
        settings.force_order,
    )
    force_vector = force[:, None] * segment_normal(np.interp(t_force, t, q_ref[:, 1]))
    shank = {}
    if settings.shank_pulse_force_n:
        params = params.replace(shank_attachment_m=settings.shank_rod.attachment_m(params.length_m[1]))
        shank_force = pulse_force_n(
            t_force,
            settings.shank_pulse_force_n,
            settings.pulse_duration_s,
            device,
            settings.force_cutoff_hz,
            settings.force_order,
        )
        shank_direction = shank_rod_direction(np.interp(t_force, t, q_ref[:, 2]), settings.shank_rod)
        shank_vector = shank_force[:, None] * shank_direction
        shank = {"shank_force_perturbed_n": shank_vector, "shank_force_unperturbed_n": np.zeros_like(shank_vector)}
    return prepare_window(
        t,
        q_ref,
        q_ref,
        params,
        0.0,
        force_perturbed_n=force_vector,
        force_unperturbed_n=np.zeros_like(force_vector),
        force_time_s=t_force,
        **shank,
        pelvis_angle_unperturbed_rad=pelvis,
        pelvis_angle_perturbed_rad=pelvis,
        **window_options(settings),
    )


def planned_impedance(impedance, settings: PlanSettings, source: str) -> np.ndarray:
    """The planned values (p,) checked to lie within the fit's bounds: K and D per joint (order of
    :data:`PARAMETERS`), then each of ``settings.couplings`` (N·m/rad); for couplings the six alone plan each
    coupling at 0 (no coupling: the value a design must tell a coupling from)."""
    names = PARAMETERS + tuple(f"K_{c}" for c in settings.couplings)
    p = np.asarray(impedance, dtype=float)
    if settings.couplings and p.shape == (len(PARAMETERS),):
        p = np.concatenate([p, np.zeros(len(settings.couplings))])
    if p.shape != (len(names),) or not np.all(np.isfinite(p)):
        raise LoperInputError(
            f"{source}: the planned impedance must be {len(names)} finite values ({', '.join(names)}), "
            f"got {np.asarray(impedance).tolist()}"
        )
    out = np.flatnonzero((p < settings.lower) | (p > settings.upper))
    if out.size:
        i = int(out[0])
        raise LoperInputError(
            f"{source}: planned {names[i]} = {p[i]:g} {PARAMETER_UNITS.get(names[i], COUPLING_UNIT)} lies "
            f"outside the identification bounds {settings.lower[i]:g} .. {settings.upper[i]:g}"
        )
    return p


def null_pair_arrays(null_pairs: Mapping, source: str) -> tuple[np.ndarray, dict[str, np.ndarray], int]:
    """Checked grid and arrays of the pilot's null pairs, and how many there are."""
    missing = [
        k
        for k in (
            "time_s",
            "q_perturbed",
            "q_unperturbed",
            "pelvis_angle_perturbed_rad",
            "pelvis_angle_unperturbed_rad",
        )
        if k not in null_pairs
    ]
    if missing:
        raise LoperInputError(f"{source}: null pairs lack {missing}")
    t = np.asarray(null_pairs["time_s"], dtype=float)
    arrays = {
        k: np.asarray(null_pairs[k], dtype=float)
        for k in ("q_perturbed", "q_unperturbed", "pelvis_angle_perturbed_rad", "pelvis_angle_unperturbed_rad")
    }
    n = int(arrays["q_unperturbed"].shape[0]) if arrays["q_unperturbed"].ndim == 3 else 0
    return t, arrays, n
