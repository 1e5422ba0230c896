"""Shared inputs of the identification tests: validation trials with a known impedance and their windows.

The "measured" data come from :func:`loper_analysis.impedance.identification.validation.perturbed_trial`
(fine-step RK4 of the same model with a known impedance), prepared the way
:func:`loper_analysis.impedance.identification.validation.run_validation_chunk` does it.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from loper_analysis.impedance.identification import identify_impedance
from loper_analysis.impedance.identification.validation import (
    ValidationSettings,
    perturbed_trial,
    validation_window,
    with_pulse_at_stages,
)
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry

PARAMS = segment_parameters_from_anthropometry(1.73, 64.9)
SETTINGS = ValidationSettings()
#: The impedance of the mid trial (order of PARAMETERS).
MID_TRUTH = np.array([75.0, 2.0, 75.0, 2.0, 75.0, 2.0])


@cache
def _mid_trial():
    arrays = perturbed_trial(PARAMS, MID_TRUTH, SETTINGS)
    for a in arrays:
        a.setflags(write=False)
    return arrays


def mid_trial():
    """(time_s, q_u, q_p, force_p, pelvis, force_time_s) of the mid impedance (computed once, read-only)."""
    return _mid_trial()


def window_for(trial, settings=SETTINGS, *, qu_measured=None, qp_measured=None, **overrides):
    """The window run_validation_chunk builds (q_reference = noise-free unperturbed coordinates)."""
    return validation_window(PARAMS, settings, trial, qu_measured, qp_measured, **overrides)


def truth_window(trial, settings=SETTINGS, **overrides):
    """The window with the truth's own step and force (the pulse at every RK4 stage): a round trip."""
    return with_pulse_at_stages(window_for(trial, settings, n_substeps=settings.truth_substeps, **overrides), settings)


def fit(window, n_starts=5, seed=0, settings=SETTINGS):
    """identify_impedance with the validation study's bounds and tolerance."""
    return identify_impedance(
        window,
        n_starts=n_starts,
        seed=seed,
        lower=settings.lower,
        upper=settings.upper,
        tolerance=settings.tolerance,
    )


def expect_error(func, *words):
    """``func()`` raises LoperInputError whose message holds every one of ``words``."""
    import pytest

    from loper_analysis.errors import LoperInputError

    with pytest.raises(LoperInputError) as info:
        func()
    for w in words:
        assert w in str(info.value), (w, str(info.value))
