"""Inter-joint (bi-articular) stiffness as an option of the fit: strides simulated with a known hip-knee (and
knee-ankle) coupling give it back, a truth without one gives the six K and D back with a coupling of 0, and the
fit reports the coupling's SD, interval and correlations.

The "measured" strides are :func:`loper_analysis.impedance.identification.validation.coupled_trial`'s: the
validation study's fine-step RK4 of the same model with the true couplings, pushed at the thigh (and, with two
rods, at the shank too). Fitted with the truth's own step and stage forces the model is the truth's, so the
estimate can differ from the truth only by the fit's convergence (its SciPy polish runs to tolerances of 1e-14);
with the fit's own step (2 RK4 steps per sample against the truth's 32) also by the integration's difference.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from loper_analysis.constants import PARAMETERS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import (
    identify_impedance,
    per_step,
    prediction_error,
    stage_times_s,
    t_quantile,
)
from loper_analysis.impedance.identification.fit import (
    COUPLING_BOUNDS_NM_PER_RAD,
    DEFAULT_LOWER,
    DEFAULT_UPPER,
    fit_bounds,
    parameter_bounds,
)
from loper_analysis.impedance.identification.validation import (
    coupled_trial,
    perturbed_trial,
    validation_pulse,
    validation_window,
)
from loper_analysis.impedance.identification.window import check_couplings
from tests.impedance.identification.validation_windows import PARAMS, SETTINGS

#: The second rod just above the ankle: 85 % of the shank's length below the knee.
TWO_RODS = PARAMS.replace(shank_attachment_m=0.85 * PARAMS.length_m[1])
#: The study's hip (K 55 N·m/rad, D 3.5 N·m·s/rad), its knee (3, 0.1) and an ankle of 8 and 0.3.
STUDY = np.array([55.0, 3.5, 3.0, 0.1, 8.0, 0.3])
HIP_KNEE = ("hip_knee",)
#: The fit's convergence on a noise-free round trip: its polish stops at relative steps of 1e-14; the largest
#: error measured over these tests is 5e-12 N·m/rad.
CONVERGED = 1e-8


def _trial(truth, two_rods: bool, couplings=HIP_KNEE):
    params = TWO_RODS if two_rods else PARAMS
    return coupled_trial(params, truth, SETTINGS, couplings, 1.0 if two_rods else 0.0)


def _window(trial, two_rods: bool, couplings=HIP_KNEE, truth_step: bool = True):
    """The fit's window of a stride; with ``truth_step`` at the truth's RK4 step with the pulses at every stage
    (the model is then the truth's), else as the fit takes the data (2 steps per sample, forces at 1 kHz)."""
    params = TWO_RODS if two_rods else PARAMS
    extra = {"shank_force_perturbed_n": trial[6]} if two_rods else {}
    if truth_step:
        extra["n_substeps"] = SETTINGS.truth_substeps
    window = validation_window(params, SETTINGS, trial[:6], couplings=couplings, **extra)
    if truth_step:
        pulse = per_step(validation_pulse(stage_times_s(window), SETTINGS))
        window = replace(window, force_perturbed_n=pulse, shank_force_perturbed_n=pulse if two_rods else None)
    return window


@pytest.mark.parametrize("k_hip_knee", [-6.0, 4.0])
@pytest.mark.parametrize("two_rods", [False, True], ids=["thigh-rod", "both-rods"])
def test_a_stride_with_a_known_hip_knee_coupling_gives_it_back(two_rods, k_hip_knee):
    """Either sign of the coupling (|K_hk| below sqrt(K_hip K_knee) = 12.8 N·m/rad: a positive definite
    stiffness), pushed at the thigh alone or by both rods: all seven parameters back to the fit's convergence."""
    truth = np.append(STUDY, k_hip_knee)
    window = _window(_trial(truth, two_rods), two_rods)
    assert window.parameters == (*PARAMETERS, "K_hip_knee")
    np.testing.assert_allclose(prediction_error(window, truth), 0.0, rtol=0, atol=1e-13)
    fit = identify_impedance(window, n_starts=5, seed=0)
    assert fit.success, fit.message
    assert fit.parameters == window.parameters
    np.testing.assert_allclose(fit.estimate, truth, rtol=0, atol=CONVERGED)


def test_with_the_fits_own_step_the_coupling_comes_back_within_the_recovery_tolerance():
    """The data as the fit takes them (2 RK4 steps per sample against the truth's 32, the force at 1 kHz): the
    integration's difference moves every K by at most 2.2e-3 N·m/rad (measured), inside the one-rod recovery
    test's 0.05 N·m/rad and 0.005 N·m·s/rad."""
    truth = np.append(STUDY, -6.0)
    fit = identify_impedance(_window(_trial(truth, False), False, truth_step=False), n_starts=5, seed=0)
    assert fit.success, fit.message
    err = fit.estimate - truth
    np.testing.assert_allclose(err[[0, 2, 4, 6]], 0.0, rtol=0, atol=0.05)
    np.testing.assert_allclose(err[[1, 3, 5]], 0.0, rtol=0, atol=0.005)


@pytest.mark.parametrize("two_rods", [False, True], ids=["thigh-rod", "both-rods"])
def test_a_truth_without_coupling_fitted_with_one_gives_the_six_back_and_a_coupling_of_zero(two_rods):
    trial = _trial(np.append(STUDY, 0.0), two_rods)
    if not two_rods:  # a zero coupling in the truth is the six-parameter truth, to the bit
        for a, b in zip(perturbed_trial(PARAMS, STUDY, SETTINGS), trial[:6], strict=True):
            np.testing.assert_array_equal(a, b)
    fit = identify_impedance(_window(trial, two_rods), n_starts=5, seed=0)
    assert fit.success, fit.message
    np.testing.assert_allclose(fit.estimate, np.append(STUDY, 0.0), rtol=0, atol=CONVERGED)


def test_both_couplings_come_back_with_two_rods():
    """Hip-knee and knee-ankle couplings at once (the knee-ankle one as a gastrocnemius gives it: negative)."""
    couplings = ("hip_knee", "knee_ankle")
    truth = np.append(STUDY, [-6.0, -2.0])
    window = _window(_trial(truth, True, couplings), True, couplings)
    assert window.parameters[6:] == ("K_hip_knee", "K_knee_ankle")
    fit = identify_impedance(window, n_starts=5, seed=0)
    assert fit.success, fit.message
    np.testing.assert_allclose(fit.estimate, truth, rtol=0, atol=CONVERGED)


def test_the_fit_reports_the_couplings_sd_interval_and_correlations():
    """On the stride with the validation's noise (0.01 rad or m peak to peak) divided by sqrt(30), the mean of 30
    strides: the coupling's interval is its estimate +- t SD cut to its bounds, the correlation matrix is symmetric
    with a unit diagonal, and the fit of a window given the coupling by ``identify_impedance(couplings=...)`` is the
    fit of a window prepared with it. Pushed at the thigh alone, K_hip_knee trades off against K_knee and K_hip
    (measured correlations -0.999 and -0.99) and scatters 21 N·m/rad here."""
    truth = np.append(STUDY, -6.0)
    trial = _trial(truth, False)
    rng = np.random.default_rng(3)
    a = SETTINGS.noise_peak_to_peak / 2 / np.sqrt(30)
    qu, qp = (x + rng.uniform(-a, a, x.shape) for x in trial[1:3])
    plain = validation_window(PARAMS, SETTINGS, trial[:6], qu, qp)
    fit = identify_impedance(plain, n_starts=5, seed=0, couplings=HIP_KNEE)
    assert fit.parameters[-1] == "K_hip_knee" and fit.estimate.shape == (7,)
    estimate, sd, low, high = fit.value("K_hip_knee")
    assert 0 < sd < np.inf
    t = t_quantile(fit.ci_dof)
    expected = np.clip([estimate - t * sd, estimate + t * sd], *COUPLING_BOUNDS_NM_PER_RAD)
    np.testing.assert_allclose([low, high], expected, rtol=1e-12)
    assert fit.correlation[6, 2] < -0.9  # with the knee's K
    assert fit.correlation.shape == (7, 7)
    # symmetric to the rounding of the pseudo-inverse of a J^T J this ill-conditioned (5.5e-11 measured)
    np.testing.assert_allclose(fit.correlation, fit.correlation.T, rtol=0, atol=1e-9)
    np.testing.assert_allclose(np.diag(fit.correlation), 1.0, rtol=1e-12)
    assert np.all(np.abs(fit.correlation) <= 1.0 + 1e-12)
    same = identify_impedance(replace(plain, couplings=HIP_KNEE), n_starts=5, seed=0)
    np.testing.assert_array_equal(same.estimate, fit.estimate)
    np.testing.assert_array_equal(same.correlation, fit.correlation)
    with pytest.raises(LoperInputError, match="no 'K_knee_ankle'"):
        fit.value("K_knee_ankle")


def test_the_couplings_bounds_are_signed_and_follow_the_six():
    lb, ub = fit_bounds(DEFAULT_LOWER, DEFAULT_UPPER, HIP_KNEE)
    np.testing.assert_array_equal(lb, [*DEFAULT_LOWER, COUPLING_BOUNDS_NM_PER_RAD[0]])
    np.testing.assert_array_equal(ub, [*DEFAULT_UPPER, COUPLING_BOUNDS_NM_PER_RAD[1]])
    assert COUPLING_BOUNDS_NM_PER_RAD == (-200.0, 200.0)
    # the settings' way: one pair per kind, then the couplings'
    lb2, ub2 = parameter_bounds((0.0, 200.0), (0.0, 10.0), ("knee_ankle", "hip_knee"), (-50.0, 50.0))
    np.testing.assert_array_equal(lb2, [0, 0, 0, 0, 0, 0, -50, -50])
    np.testing.assert_array_equal(ub2, [200, 10, 200, 10, 200, 10, 50, 50])
    np.testing.assert_array_equal(fit_bounds(lb2, ub2, ("hip_knee", "knee_ankle"))[0], lb2)
    with pytest.raises(LoperInputError, match="8 finite values .*K_knee_ankle"):
        fit_bounds(lb, ub, ("hip_knee", "knee_ankle"))
    with pytest.raises(LoperInputError, match="bounds of K_hip_knee"):
        fit_bounds([*DEFAULT_LOWER, 5.0], [*DEFAULT_UPPER, 5.0], HIP_KNEE)


def test_couplings_are_named_from_the_known_pairs():
    assert check_couplings(["knee_ankle", "K_hip_knee"]) == ("hip_knee", "knee_ankle")
    assert check_couplings(()) == ()
    with pytest.raises(LoperInputError, match="unknown inter-joint coupling"):
        check_couplings(["hip_ankle"])
    with pytest.raises(LoperInputError, match="named twice"):
        check_couplings(["hip_knee", "K_hip_knee"])
    with pytest.raises(LoperInputError, match="collection of names"):
        check_couplings("hip_knee")
    window = _window(_trial(np.append(STUDY, 0.0), False), False, truth_step=False)
    with pytest.raises(LoperInputError, match="7 values per row"):
        prediction_error(window, STUDY)
