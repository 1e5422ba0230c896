"""What averaging the pairs does to the model response, and a fit that allows for it.

The fit compares the mean measured response of a subject's pairs with the model's response about the
*mean* unperturbed window, driven by the *mean* force. Each stride, though, answers the perturbation
about its own course with its own force, and the swing leg's dynamics are not linear in that course
(the inertia, gravity and the rod's lever change with the joint angles). The mean of the strides'
responses therefore differs from the response about their mean, by a term of second order in the
strides' spread: a bias of the estimate that no number of strides removes (with the stride-to-stride
variability of the study and the exact counterfactual, hip K +0.56 N·m/rad and knee D +0.055 N·m·s/rad,
more than the knee's truth, at 175 ms; none without that variability).

* :func:`pair_windows` - every kept pair prepared as a window of its own;
* :func:`averaging_bias` - at an impedance, the mean of the pairs' model responses minus the response of
  the mean window (rad, (n_out, 3));
* :func:`averaging_corrected_fit` - the fit of the mean window whose measured response is corrected by
  that term, evaluated again at each new estimate.

Method: ``docs/identification.md`` (Averaging the pairs).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from loper_analysis.impedance.identification.fit import ImpedanceFit, identify_impedance
from loper_analysis.impedance.identification.onset_fit import force_keywords
from loper_analysis.impedance.identification.window import PreparedWindow, prepare_window, simulate_response
from loper_analysis.swing_leg.dynamics import SegmentParameters

__all__ = ["pair_windows", "averaging_bias", "averaging_corrected_fit", "AVERAGING_ITERATIONS"]

#: Evaluations of the averaging term, each followed by a refit (the term changes little with the impedance).
AVERAGING_ITERATIONS: int = 2


def pair_windows(pairs: Mapping, params: SegmentParameters, **window_options) -> list[PreparedWindow]:
    """Each pair of ``pairs`` prepared as a window of its own.

    ``pairs``: the responses' per-pair series (:func:`loper_analysis.impedance.responses.subject_onset_response`,
    ``series["pairs"]``): ``time_s`` (n,), ``q_perturbed`` / ``q_unperturbed`` (n_pairs, n, 4; m, rad),
    ``pelvis_angle_perturbed_rad`` / ``pelvis_angle_unperturbed_rad`` (n_pairs, n), ``force_perturbed_n``
    / ``force_unperturbed_n`` (n_pairs, k, 2; N; (n_pairs, k, 4) with a second rod:
    :func:`~loper_analysis.impedance.identification.onset_fit.force_keywords`) and, when the force has its own
    rate, ``force_time_s`` (k,). ``window_options``:
    :func:`~loper_analysis.impedance.identification.window.prepare_window`'s keywords, those of the mean window.
    """
    out = []
    for i in range(int(pairs["n_pairs"])):
        out.append(
            prepare_window(
                pairs["time_s"],
                pairs["q_unperturbed"][i],
                pairs["q_perturbed"][i],
                params,
                0.0,
                **force_keywords(pairs["force_perturbed_n"][i], pairs["force_unperturbed_n"][i]),
                force_time_s=pairs.get("force_time_s"),
                pelvis_angle_unperturbed_rad=pairs["pelvis_angle_unperturbed_rad"][i],
                pelvis_angle_perturbed_rad=pairs["pelvis_angle_perturbed_rad"][i],
                **window_options,
            )
        )
    return out


def averaging_bias(window: PreparedWindow, windows: list[PreparedWindow], impedance) -> np.ndarray:
    """Mean of the pairs' model responses minus the mean window's, at ``impedance`` (6,): (n_out, 3) rad."""
    each = np.mean([simulate_response(w, impedance) for w in windows], axis=0)
    return each - simulate_response(window, impedance)


def averaging_corrected_fit(
    window: PreparedWindow,
    windows: list[PreparedWindow],
    fit: ImpedanceFit,
    iterations: int = AVERAGING_ITERATIONS,
    **fit_options,
) -> tuple[PreparedWindow, ImpedanceFit, np.ndarray]:
    """Refit the mean window with its measured response less :func:`averaging_bias` at the last estimate.

    ``fit``: the fit of ``window`` as it is; ``fit_options``: :func:`identify_impedance`'s keywords. Each of
    ``iterations`` rounds evaluates the term at the current estimate and refits (starting also from it).
    Returns the corrected window (its ``measured`` is the mean response less the term), its fit and the
    term (n_out, 3) rad. With no pair window the fit is returned unchanged with a zero term.
    """
    bias = np.zeros_like(window.measured)
    if not windows:
        return window, fit, bias
    corrected = window
    starts = fit_options.pop("extra_starts", None)
    for _ in range(iterations):
        bias = averaging_bias(window, windows, fit.estimate)
        corrected = replace(window, measured=window.measured - bias)
        first = fit.estimate[None, :] if starts is None else np.vstack([fit.estimate[None, :], starts])
        fit = identify_impedance(corrected, extra_starts=first, **fit_options)
    return corrected, fit, bias
