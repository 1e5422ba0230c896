"""The status of one joint's fitted row: convergence, goodness of fit, bounds, information in the intervals.

Rules (``docs/identification.md``, section "Fit status"), judged in this order:

1. the optimiser did not converge: ``failed``;
2. the joint's VAF is below ``min_vaf_pct`` (or undefined, a response of
   zero): ``failed`` - the model does not describe the measured response;
3. K or D lies on its upper bound, or on a lower bound other than zero (within
   ``at_bound_fraction`` of the bound range): ``not_identifiable`` - the
   data ask for a value the bounds exclude, and the estimate is the bound;
4. the 95 % interval of K or D reaches 0, or its lower bound when that is
   above 0 (the data cannot tell the estimate from no stiffness or damping
   at all) *and* its upper
   end reaches the upper end of the joint's plausible range
   (``plausible_range``; by default the study's range of across-subject
   means, :data:`DEFAULT_PLAUSIBLE_RANGES`): the interval holds "none" and
   every plausible size alike, so the data say nothing about the size:
   ``not_identifiable``;
5. the 95 % interval of K or D overlaps the joint's plausible range and is
   at least as wide as it (and rule 4 did not already judge it): it cannot
   place the parameter within the range of sizes the joint plausibly has,
   wherever its centre (an interval wholly outside the range still says the
   parameter lies outside it). When the parameter is strongly correlated with one of
   another joint (``|r| >= COUPLING_CORRELATION``, e.g. the knee's D with
   the hip's: the pulse on the thigh moves both), the reason names that
   parameter: the data cannot separate the two joints' shares:
   ``not_identifiable``;
6. the 95 % interval of K or D spans more than ``max_ci_fraction`` of the
   bound range, or is infinite: ``not_identifiable``;
7. the joint's model response is smaller than its residual (RMS over the
   window, ratio below ``min_response_to_residual``,
   :data:`MIN_RESPONSE_TO_RESIDUAL` = 1; :func:`response_and_residual_rms`):
   the residual, which the interval takes for noise, is larger than the
   response K and D are fitted to, and the estimate can be biased beyond its
   interval (a joint that barely moves in the window): ``not_identifiable``.

The intervals these rules judge are the fit's own; where the perturbed pairs scatter beyond the null pairs
(:func:`~loper_analysis.impedance.identification.jackknife.widen_to_pair_scatter`) they come from the perturbed
pairs' jackknife, and the reason says so.

Every finding of 2-7 is named in the reason (parameter or key, value and
limit); the status is the most severe. An estimate on a lower bound of zero
is a valid estimate (no measurable stiffness or damping, e.g. the knee's K
early in swing): by itself it adds nothing to the reason; rule 4 judges
whether its interval says anything.
"""

from __future__ import annotations

import numpy as np

from loper_analysis.constants import PARAMETERS
from loper_analysis.errors import LoperInputError
from loper_analysis.reference import ANKLE_SWING_IMPEDANCE, STUDY_SWING_IMPEDANCE

__all__ = [
    "MIN_VAF_PCT",
    "MIN_RESPONSE_TO_RESIDUAL",
    "MAX_CI_FRACTION",
    "AT_BOUND_FRACTION",
    "COUPLING_CORRELATION",
    "DEFAULT_PLAUSIBLE_RANGES",
    "check_plausible_range",
    "joint_status",
    "data_finding_inputs",
    "response_and_residual_rms",
    "strongest_coupling",
]

#: VAF (%) below which a joint's fit is ``failed``: below 0 the model explains less than no response at all.
MIN_VAF_PCT: float = 0.0
#: An estimate within this fraction of its bound range of a bound lies on the bound.
AT_BOUND_FRACTION: float = 1e-6
#: A K or D whose 95 % CI spans more than this share of its bound range is not identifiable (1: only an unbounded
#: one; ``impedance.max_ci_fraction``).
MAX_CI_FRACTION: float = 1.0

#: A joint whose model response (RMS over the window) is smaller than this multiple of its residual's is not
#: identifiable (rule 7): 1, the response no larger than what the fit leaves unexplained (a VAF of about 50 %).
MIN_RESPONSE_TO_RESIDUAL: float = 1.0

#: A parameter whose estimate correlates at least this strongly (absolute) with one of another joint trades off
#: against it; a too-wide interval's reason names that parameter (rule 5).
COUPLING_CORRELATION: float = 0.8

#: Plausible range per joint, ((K low, K high) N·m/rad, (D low, D high) N·m·s/rad): the study's across-subject
#: means for hip and knee, a stated choice for the ankle (:data:`loper_analysis.reference.ANKLE_SWING_IMPEDANCE`).
DEFAULT_PLAUSIBLE_RANGES: dict[str, tuple[tuple[float, float], tuple[float, float]]] = {
    **{j: (r["K"], r["D"]) for j, r in STUDY_SWING_IMPEDANCE.items()},
    "ankle": (ANKLE_SWING_IMPEDANCE["K"], ANKLE_SWING_IMPEDANCE["D"]),
}

_PARAMETERS = (
    ("K", "N·m/rad", "impedance.stiffness_bounds_nm_per_rad", "stiffness"),
    ("D", "N·m·s/rad", "impedance.damping_bounds_nms_per_rad", "damping"),
)


def check_plausible_range(joint: str, plausible_range) -> np.ndarray:
    """The plausible range of a joint as a (2, 2) array ``[[K low, K high], [D low, D high]]``, each
    ``0 <= low < high``."""
    r = np.asarray(plausible_range, dtype=float)
    if r.shape != (2, 2) or not np.all(np.isfinite(r)) or np.any(r[:, 0] < 0) or np.any(r[:, 0] >= r[:, 1]):
        raise LoperInputError(
            f"impedance.plausible_ranges of the {joint}: K and D each need [low, high] with "
            f"0 <= low < high, got {np.asarray(plausible_range).tolist()}"
        )
    return r


def response_and_residual_rms(measured, model) -> tuple[np.ndarray, np.ndarray]:
    """Per joint, the RMS of the model response and of the residual over the fit window.

    Parameters
    ----------
    measured, model : (n, j) array_like
        The measured response and the model's (rad; columns hip, knee, ankle), e.g. ``ImpedanceFit.measured``
        and ``ImpedanceFit.model``.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        RMS of ``model`` and of ``measured - model`` per column (j,), rad.
    """
    y, f = np.asarray(measured, dtype=float), np.asarray(model, dtype=float)
    if y.ndim != 2 or y.shape != f.shape or y.shape[0] == 0:
        raise LoperInputError(f"measured and model must be one (n, j) shape with n >= 1, got {y.shape} and {f.shape}")
    return np.sqrt(np.mean(f**2, axis=0)), np.sqrt(np.mean((y - f) ** 2, axis=0))


def data_finding_inputs(fit, joint_index: int) -> dict:
    """:func:`joint_status`'s inputs of rule 7 for one joint of a fit.

    Parameters
    ----------
    fit : ImpedanceFit
        The fit (its ``measured`` and ``model``).
    joint_index : int
        0, 1, 2: hip, knee, ankle.

    Returns
    -------
    dict
        ``response_rms_rad``, ``residual_rms_rad`` (:func:`response_and_residual_rms`).
    """
    response, residual = response_and_residual_rms(fit.measured, fit.model)
    return dict(response_rms_rad=response[joint_index], residual_rms_rad=residual[joint_index])


def strongest_coupling(
    correlation, joint: str, names: tuple[str, ...] = PARAMETERS
) -> tuple[tuple[str, float] | None, tuple[str, float] | None]:
    """Per K and D of ``joint``, the parameter of another joint (or an inter-joint coupling) it correlates with most
    strongly.

    Parameters
    ----------
    correlation : (p, p) array_like
        Correlation of the fit's parameters, order ``names``; NaN where a parameter has no finite standard error.
    joint : str
        ``hip``, ``knee`` or ``ankle``.
    names : the fit's parameters (:attr:`~loper_analysis.impedance.identification.ImpedanceFit.parameters`):
        :data:`loper_analysis.constants.PARAMETERS`, then its couplings' ``K_<coupling>``.

    Returns
    -------
    (K, D) : each ``(name, r)`` (``("D_hip", -0.93)``), or None when no correlation with another parameter is finite.
    """
    c = np.asarray(correlation, dtype=float)
    names = tuple(names)
    if c.shape != (len(names),) * 2:
        raise LoperInputError(f"correlation must be {len(names)} x {len(names)}, got shape {c.shape}")
    own = (f"K_{joint}", f"D_{joint}")
    out = []
    for p in own:
        i = names.index(p)
        others = [k for k, name in enumerate(names) if name not in own and np.isfinite(c[i, k])]
        if not others:
            out.append(None)
            continue
        k = max(others, key=lambda k: abs(c[i, k]))
        out.append((names[k], float(c[i, k])))
    return out[0], out[1]


def joint_status(
    joint: str,
    estimate,
    ci_low,
    ci_high,
    vaf_pct: float,
    lower,
    upper,
    *,
    success: bool = True,
    message: str = "",
    plausible_range=None,
    max_ci_fraction: float = MAX_CI_FRACTION,
    min_vaf_pct: float = MIN_VAF_PCT,
    at_bound_fraction: float = AT_BOUND_FRACTION,
    coupling=None,
    response_rms_rad: float | None = None,
    residual_rms_rad: float | None = None,
    min_response_to_residual: float = MIN_RESPONSE_TO_RESIDUAL,
) -> tuple[str, str]:
    """Status (``ok`` | ``not_identifiable`` | ``failed``) and reason of one joint's row.

    Parameters
    ----------
    joint : str
        Joint name, quoted in the reason (``K_knee``).
    estimate, ci_low, ci_high : (2,) array_like
        K (N·m/rad) and D (N·m·s/rad), and the ends of their 95 % intervals.
    vaf_pct : float
        The joint's VAF (%); NaN when the measured response is zero.
    lower, upper : (2,) array_like
        Bounds of K and D.
    success, message : the optimiser's convergence flag and message.
    plausible_range : (2, 2) array_like, optional
        ``[[K low, K high], [D low, D high]]`` (rule 4); None: the joint's
        entry of :data:`DEFAULT_PLAUSIBLE_RANGES` (none for another joint name:
        rule 4 is skipped).
    max_ci_fraction, min_vaf_pct, at_bound_fraction : the thresholds (see the module docstring).
    coupling : (2,) sequence of (str, float) or None, optional
        Per K and D the parameter of another joint it correlates with most strongly and that correlation
        (``("D_hip", -0.93)``), or None; named in the reason of a too-wide interval when
        ``|r| >= COUPLING_CORRELATION`` (rule 5).
    response_rms_rad, residual_rms_rad : float, optional
        RMS (rad) of the joint's model response and of its residual over the fit window
        (:func:`response_and_residual_rms`); rule 7 is skipped when either is None or their ratio is undefined.
    min_response_to_residual : float
        Rule 7's least ratio of the two (> 0).

    Returns
    -------
    (str, str)
        The status and the reason ("" for a plain ``ok``).
    """
    est = np.asarray(estimate, dtype=float)
    low, high = np.asarray(ci_low, dtype=float), np.asarray(ci_high, dtype=float)
    lb, ub = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    for name, a in (("estimate", est), ("ci_low", low), ("ci_high", high), ("lower", lb), ("upper", ub)):
        if a.shape != (2,):
            raise LoperInputError(f"{joint}: {name} must hold K and D (2 values), got shape {a.shape}")
    if not (0 <= at_bound_fraction < 0.5):
        raise LoperInputError(f"at_bound_fraction must lie in [0, 0.5), got {at_bound_fraction}")
    if plausible_range is None:
        plausible_range = DEFAULT_PLAUSIBLE_RANGES.get(joint)
    plausible = None if plausible_range is None else check_plausible_range(joint, plausible_range)
    widths = high - low
    if not success:
        return "failed", f"optimiser did not converge: {message}"
    failed = _vaf_findings(joint, vaf_pct, min_vaf_pct)
    span = ub - lb
    unidentifiable = _bound_findings(joint, est, lb, ub, at_bound_fraction)
    coupling = (None, None) if coupling is None else tuple(coupling)
    if len(coupling) != 2:
        raise LoperInputError(f"{joint}: coupling must hold K and D (2 entries), got {len(coupling)}")
    for i, (p, unit, _, what) in enumerate(_PARAMETERS):
        if plausible is None or np.isnan(low[i]) or np.isnan(high[i]):
            continue
        r_low, r_high = plausible[i]
        floor = max(lb[i], 0.0)  # none at all, or the least the bounds allow
        interval = f"{p}_{joint} = {est[i]:.3g} {unit}, 95 % CI {low[i]:.3g} … {high[i]:.3g} {unit}"
        if low[i] <= floor + at_bound_fraction * span[i] and high[i] >= r_high:
            unidentifiable.append(
                f"{interval}: holds both {floor:g} and the plausible range {r_low:g}–{r_high:g} {unit} "
                f"(impedance.plausible_ranges), the data cannot tell the {what} from {floor:g}"
            )
        elif widths[i] >= r_high - r_low and low[i] <= r_high and high[i] >= r_low:
            text = (
                f"{interval}: wider than the plausible range {r_low:g}–{r_high:g} {unit} "
                f"(impedance.plausible_ranges), the data cannot place the {what} within it"
            )
            if coupling[i] is not None and abs(float(coupling[i][1])) >= COUPLING_CORRELATION:
                other, r = coupling[i][0], float(coupling[i][1])
                text += (
                    f"; it trades off against {other} (correlation {r:+.2f}): the data cannot separate "
                    f"{p}_{joint} from {other}"
                )
            unidentifiable.append(text)
    if not np.all(np.isfinite(widths)) or np.any(widths > max_ci_fraction * span):
        unidentifiable.append(
            f"95 % CI width K {widths[0]:.3g} N·m/rad, D {widths[1]:.3g} N·m·s/rad exceeds "
            f"{max_ci_fraction:g} of the bounds"
        )
    unidentifiable += _response_findings(joint, response_rms_rad, residual_rms_rad, min_response_to_residual)
    status = "failed" if failed else ("not_identifiable" if unidentifiable else "ok")
    return status, "; ".join(failed + unidentifiable)


def _vaf_findings(joint: str, vaf_pct: float, min_vaf_pct: float) -> list[str]:
    """Why the joint's fit failed by its VAF (%): undefined, or below ``min_vaf_pct``; empty when neither."""
    failed = []
    if not np.isfinite(vaf_pct):
        failed.append(f"VAF of the {joint} undefined: its measured response is zero over the fit window")
    elif vaf_pct < min_vaf_pct:
        failed.append(
            f"VAF {vaf_pct:.3g} % below impedance.min_vaf_pct = {min_vaf_pct:g} %: "
            f"the model does not describe the {joint} response"
        )
    return failed


def _response_findings(
    joint: str, response_rms: float | None, residual_rms: float | None, min_ratio: float
) -> list[str]:
    """Why the joint's K and D are not identifiable by the size of its response (rule 7): its model response's RMS
    ``response_rms`` (rad) below ``min_ratio`` times its residual's ``residual_rms``; empty otherwise, or when
    the ratio is undefined (either None or NaN, or both zero)."""
    if not (min_ratio > 0):
        raise LoperInputError(f"min_response_to_residual must be > 0, got {min_ratio}")
    if response_rms is None or residual_rms is None:
        return []
    a, e = float(response_rms), float(residual_rms)
    if not (np.isfinite(a) and np.isfinite(e)) or a >= min_ratio * e:
        return []
    ratio = a / e
    return [
        f"model response of the {joint} RMS {1e3 * a:.3g} mrad, {ratio:.2g} times its residual's {1e3 * e:.3g} mrad: "
        f"below {min_ratio:g} (MIN_RESPONSE_TO_RESIDUAL), the residual the interval takes for noise is larger than "
        f"the response K_{joint} and D_{joint} are fitted to, and they can be biased beyond their 95 % intervals"
    ]


def _bound_findings(joint: str, est: np.ndarray, lb: np.ndarray, ub: np.ndarray, at_bound_fraction: float) -> list[str]:
    """Per K and D (``est``, bounds ``lb``, ``ub``, each (2,)) on its upper bound, or on a lower bound other
    than zero (within ``at_bound_fraction`` of the bound range): why it is not identifiable (rule 3)."""
    found = []
    span = ub - lb
    for i, (p, unit, key, what) in enumerate(_PARAMETERS):
        tol = at_bound_fraction * span[i]
        name = f"{p}_{joint} = {est[i]:.6g} {unit}"
        if est[i] >= ub[i] - tol:
            found.append(
                f"{name} at its upper bound {ub[i]:g} {unit} ({key}): the data ask for more "
                f"{what} than the bounds allow"
            )
        elif est[i] <= lb[i] + tol and lb[i] != 0:
            found.append(
                f"{name} at its lower bound {lb[i]:g} {unit} ({key}): the data ask for "
                f"less {what} than the bounds allow"
            )
    return found
