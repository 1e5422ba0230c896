"""Identification with a second rod at the shank: the fit takes both rods' forces and, on noise-free data, recovers
every joint's K and D, the ankle's too; with both rods the knee's and the ankle's estimates are more precise.

The "measured" perturbed stride is the fine-step RK4 of the same model with a known impedance and both pulses at
every stage (as :func:`loper_analysis.impedance.identification.validation.perturbed_trial` makes the one-rod
trials); the fit sees the forces sampled at the robot's 1 kHz, as it sees a robot log.
"""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.constants import PARAMETERS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import prepare_window, response_jacobian
from loper_analysis.impedance.identification.validation import (
    perturbed_trial,
    two_rod_trial,
    validation_pulse,
    validation_window,
)
from loper_analysis.impedance.identification.window import window_options
from tests.impedance.identification.validation_windows import PARAMS, SETTINGS, fit

#: The second rod just above the ankle: 85 % of the shank's length below the knee.
TWO_RODS = PARAMS.replace(shank_attachment_m=0.85 * PARAMS.length_m[1])
#: The study's hip and the study's knee (K 0-3.5 N·m/rad, D 0.02-0.14 N·m·s/rad), an ankle of 8 and 0.3.
STUDY_TRUTH = np.array([55.0, 3.5, 3.0, 0.1, 8.0, 0.3])


def _trial(truth, shank_scale: float, thigh_scale: float = 1.0):
    """A stride pushed at the thigh (``thigh_scale`` × the study's pulse) and at the shank (``shank_scale`` × it)."""
    return two_rod_trial(TWO_RODS, truth, SETTINGS, shank_scale, thigh_scale)


def _window(trial, *_):
    """The window the fit sees: the coordinates at 128 Hz, both rods' forces at the robot's 1 kHz."""
    return validation_window(TWO_RODS, SETTINGS, trial[:6], shank_force_perturbed_n=trial[6])


@pytest.mark.parametrize(("thigh", "shank"), [(1.0, 1.0), (0.0, 1.0)], ids=["both-rods", "shank-rod-alone"])
def test_noise_free_recovery_of_every_joint_with_the_shank_rod(thigh, shank):
    """Both rods at once, or the shank rod alone: the truth back at every joint (the fit's step against the truth's
    32 steps per sample and the forces at 1 kHz: measured |error| <= 2.7e-4 N·m/rad and 1.8e-5 N·m·s/rad; the
    tolerance is the one-rod recovery test's)."""
    window = _window(_trial(STUDY_TRUTH, shank, thigh), shank, thigh)
    result = fit(window, n_starts=5)
    assert result.success, result.message
    err = result.estimate - STUDY_TRUTH
    k = [PARAMETERS.index(f"K_{j}") for j in ("hip", "knee", "ankle")]
    d = [PARAMETERS.index(f"D_{j}") for j in ("hip", "knee", "ankle")]
    np.testing.assert_allclose(err[k], 0.0, rtol=0, atol=0.05)
    np.testing.assert_allclose(err[d], 0.0, rtol=0, atol=0.005)
    assert np.all(result.vaf_pct > 99.9), result.vaf_pct


def _precision(window) -> dict[str, float]:
    """Each parameter's SD per unit of white noise on the joint angles (sqrt of diag((J^T J)^-1))."""
    J = response_jacobian(window, STUDY_TRUTH)
    return dict(zip(PARAMETERS, np.sqrt(np.diag(np.linalg.inv(J.T @ J))), strict=True))


def test_both_rods_identify_the_knee_and_the_ankle_more_precisely_than_the_thigh_rod():
    """For the same noise, the estimates' SD with both rods pushing against the thigh rod alone (measured: hip
    0.44, knee 0.60 and 0.65, ankle 0.22 and 0.23 of the thigh rod's). A push at the shank alone barely moves the
    knee (its K's sensitivity 0.1 of the thigh push's), so the rods together, not the shank's alone, serve the
    knee."""
    thigh = _precision(_window(_trial(STUDY_TRUTH, 0.0), 0.0))
    both = _precision(_window(_trial(STUDY_TRUTH, 1.0), 1.0))
    ratio = {p: both[p] / thigh[p] for p in PARAMETERS}
    assert max(ratio[p] for p in ("K_knee", "D_knee")) < 0.8, ratio
    assert max(ratio[p] for p in ("K_ankle", "D_ankle")) < 0.4, ratio
    assert max(ratio[p] for p in ("K_hip", "D_hip")) < 1.0, ratio


def test_a_shank_force_without_a_shank_rod_is_refused():
    t, qu, qp, _, _, t_force, _ = _trial(STUDY_TRUTH, 1.0)
    with pytest.raises(LoperInputError, match="shank_attachment_m"):
        prepare_window(
            t,
            qu,
            qp,
            PARAMS,
            SETTINGS.onset_s,
            shank_force_perturbed_n=validation_pulse(t_force, SETTINGS),
            force_time_s=t_force,
            **window_options(SETTINGS),
        )


def test_without_the_shank_push_the_two_rod_stride_is_the_one_rod_stride_to_the_bit():
    one = perturbed_trial(PARAMS, STUDY_TRUTH, SETTINGS)
    two = _trial(STUDY_TRUTH, 0.0)
    for a, b in zip(one, two[:6], strict=True):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(two[6], 0.0)
    with pytest.raises(LoperInputError, match="shank_attachment_m"):
        two_rod_trial(PARAMS, STUDY_TRUTH, SETTINGS)
