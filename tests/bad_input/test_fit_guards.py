"""Bad inputs of the identification never give an ``ok`` row with a meaningless estimate.

* a fit window longer than the validation study's simulated swing is refused, naming the key;
* a subject fit whose strides are too short for the window fails with a reason naming
  ``impedance.window_after_s``, its value and the longest window the strides allow;
* an estimate on an upper bound is ``not_identifiable``, a VAF below the floor ``failed``;
* a trial whose unperturbed strides are grossly deviant is left out of every onset's null pairs.
"""

from __future__ import annotations

import logging
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import identify_impedance
from loper_analysis.impedance.identification.impedance import IdentificationSettings, fit_onset, impedance_rows
from loper_analysis.impedance.identification.validation import (
    ValidationSettings,
    perturbed_trial,
    validation_window,
)
from loper_analysis.impedance.responses import ResponseSettings
from loper_analysis.impedance.responses.response_window import ResponseWindow
from loper_analysis.stages.validation.step import validation_chunk
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry
from tests.bad_input.fit_trials import ONSET_MS, fit_inputs, walking_trial

PARAMS = segment_parameters_from_anthropometry(1.73, 64.9)
TRUTH = (60.0, 3.0, 5.0, 0.2, 20.0, 0.5)
#: Perturbed swings of walking_trial are 60, 62, 59 and 61 frames at 128 Hz, onsets 13 frames after toe-off:
#: the longest leaves (62 - 13) / 128 = 0.3828 s after the onset.
LONGEST_AFTER_ONSET_S = (62 - 13) / 128


# ---------------------------------------------------------------- the validation study's window


@pytest.mark.parametrize("after, limit", [(1.0, "0.55 s"), (0.56, "0.55 s")])
def test_validation_refuses_a_window_after_the_heel_strike(after, limit):
    with pytest.raises(LoperInputError) as info:
        ValidationSettings(window=ResponseWindow(after_s=after))
    message = str(info.value)
    assert f"impedance.window_after_s = {after:g} s" in message
    assert f"at most {limit}" in message and "validation.swing_duration_s = 0.6 s" in message
    assert "validation.onset_s = 0.05 s" in message


def test_validation_refuses_a_window_before_toe_off():
    with pytest.raises(LoperInputError) as info:
        ValidationSettings(window=ResponseWindow(before_s=0.1))
    assert "impedance.window_before_s = 0.1 s" in str(info.value) and "at most 0.05 s" in str(info.value)


def test_validation_accepts_the_window_up_to_the_heel_strike():
    settings = ValidationSettings(window=ResponseWindow(after_s=0.55, before_s=0.05))
    assert settings.onset_s + settings.window.after_s == pytest.approx(settings.swing_duration_s)


def test_validation_chunk_step_refuses_before_writing(tmp_path):
    out = [tmp_path / "errors.tsv", tmp_path / "fits.tsv"]
    with pytest.raises(LoperInputError, match=r"impedance\.window_after_s = 1 s"):
        validation_chunk(tmp_path / "segments.tsv", ValidationSettings(window=ResponseWindow(after_s=1.0)), 0, 2, *out)
    assert not any(p.exists() for p in out)


# ---------------------------------------------------------------- subject fits: strides too short for the window


@pytest.fixture(scope="module")
def onset_trials():
    return [walking_trial("pert100-1", 1), walking_trial("pert100-2", 2)]


def _fit(trials, after, null=(), min_strides=4, counterfactual="conditional", **ident):
    settings = IdentificationSettings(**{"n_starts": 3, "min_null_pairs": 20, **ident})
    return fit_onset(
        [fit_inputs(t) for t in trials],
        PARAMS,
        ONSET_MS,
        "S01",
        null_trials=[fit_inputs(t) for t in null],
        response=ResponseSettings(
            window=ResponseWindow(after_s=after), min_strides=min_strides, counterfactual=counterfactual
        ),
        identification=settings,
    )


def test_a_window_longer_than_every_swing_names_the_key(onset_trials):
    result = _fit(onset_trials, 1.0)
    rows = result.rows
    assert (rows.status == "failed").all() and rows.K_nm_per_rad.isna().all()
    reason = rows.reason.iloc[0]
    assert reason.startswith("0 valid perturbed stride(s), fewer than 4: not fitted")
    assert "8 of 8 perturbed stride(s) too short" in reason
    assert "onset 100 ms + impedance.window_after_s = 1 s" in reason
    assert f"the longest swing leaves {LONGEST_AFTER_ONSET_S:.3g} s after the onset" in reason  # 0.383 s
    total = result.counts.set_index("trial").loc["total"]
    assert (total.n_perturbed, total.n_too_short, total.n_kept) == (8, 8, 0)


def test_strides_too_short_are_dropped_one_by_one(onset_trials):
    """0.38 s keeps the two 62-frame swings (0.3828 s after the onset) and drops the other six."""
    result = _fit(onset_trials, 0.38)
    total = result.counts.set_index("trial").loc["total"]
    assert (total.n_too_short, total.n_kept) == (6, 2)
    assert "6 of 8 perturbed stride(s) too short" in result.rows.reason.iloc[0]
    assert "impedance.window_after_s = 0.38 s" in result.rows.reason.iloc[0]
    # enough strides left: the fit runs and its reason does not mention the window
    fitted = _fit(onset_trials, 0.38, min_strides=2, noise_model="white")
    assert fitted.rows.n_strides.tolist() == [2, 2, 2] and not fitted.rows.reason.str.contains("window_after").any()


# ---------------------------------------------------------------- estimates on a bound, VAF below the floor


@pytest.fixture(scope="module")
def truth_window():
    settings = ValidationSettings()
    return validation_window(PARAMS, settings, perturbed_trial(PARAMS, TRUTH, settings))


def test_a_response_of_the_wrong_sign_puts_k_on_its_upper_bound(truth_window):
    """A passive K, D >= 0 cannot turn the knee against the pulse: the fit pushes K_knee to 200 N·m/rad."""
    flipped = replace(truth_window, measured=truth_window.measured * np.array([1.0, -1.0, 1.0]))
    fit = identify_impedance(flipped, n_starts=4, seed=1)
    assert fit.estimate[2] == pytest.approx(200.0, abs=1e-9)
    rows = impedance_rows(fit, "S01", 50, 12).set_index("joint")
    assert rows.loc["knee", "status"] == "not_identifiable"
    assert (
        "K_knee = 200 N·m/rad at its upper bound 200 N·m/rad (impedance.stiffness_bounds_nm_per_rad)"
        in rows.loc["knee", "reason"]
    )
    # the fit is polished by least_squares at xtol/ftol 1e-14: its VAF holds to 1e-9 (the same with the kernels
    # compiled for a generic CPU); 0.01 is the quoted figure's last digit
    assert rows.loc["knee", "vaf_pct"] == pytest.approx(11.03, abs=0.01)


def test_a_vaf_below_the_floor_fails_the_joint(truth_window):
    """Every response flipped: hip VAF -64 %, ankle -28 % -> failed; the floor is a keyword (config min_vaf_pct)."""
    fit = identify_impedance(replace(truth_window, measured=-truth_window.measured), n_starts=4, seed=1)
    np.testing.assert_allclose(fit.vaf_pct, [-63.94, 16.79, -28.21], atol=0.01)  # polished fit: holds to 1e-9
    hip_vaf, knee_vaf = fit.vaf_pct[0], fit.vaf_pct[1]
    rows = impedance_rows(fit, "S01", 50, 12).set_index("joint")
    assert rows.status.tolist() == ["failed", "not_identifiable", "failed"]
    # the reason quotes the fit's own VAF (-63.9, 16.8 %): the value is checked above, the wording here
    assert rows.loc["hip", "reason"].startswith(f"VAF {hip_vaf:.1f} % below impedance.min_vaf_pct = 0 %")
    assert "K_hip = 200 N·m/rad at its upper bound" in rows.loc["hip", "reason"]
    strict = impedance_rows(fit, "S01", 50, 12, min_vaf_pct=20.0).set_index("joint")
    assert f"VAF {knee_vaf:.1f} % below impedance.min_vaf_pct = 20 %" in strict.loc["knee", "reason"]
    assert strict.loc["knee", "status"] == "failed"


def test_the_true_impedance_stays_ok(truth_window):
    fit = identify_impedance(truth_window, n_starts=4, seed=1)
    rows = impedance_rows(fit, "S01", 50, 12)
    assert rows.status.tolist() == ["ok"] * 3 and rows.reason.tolist() == [""] * 3
    assert rows.vaf_pct.min() > 99.9


# ---------------------------------------------------------------- one bad trial and every onset's null pairs


def test_a_grossly_deviant_trial_is_left_out_of_the_null_pairs(onset_trials, caplog):
    """Strides 20x as varied as the others' (offsets +-1 rad): the trial is left out, the fit equals the fit
    without it; without the screen the trial's pairs change the fit. (The null pairs of the matched strides,
    which come from every trial with the device; the conditional counterfactual's come from the onset's own
    trials.)"""
    device = walking_trial("walk-device", 3, perturbed=())
    bad = walking_trial("pert300-1", 4, spread=1.0)
    good = [*onset_trials, device]
    with caplog.at_level(logging.WARNING, logger="loper_analysis.impedance.responses.null_pairs"):
        with_bad = _fit(onset_trials, 0.25, null=[*good, bad], counterfactual="matched_stride")
    assert "trial pert300-1 left out of the null pairs" in caplog.text
    without = _fit(onset_trials, 0.25, null=good, counterfactual="matched_stride")
    numbers = [c for c in with_bad.rows.columns if c not in ("reason",)]
    pd.testing.assert_frame_equal(with_bad.rows[numbers], without.rows[numbers], check_exact=True)
    assert with_bad.rows.n_null_pairs.iloc[0] == without.rows.n_null_pairs.iloc[0] == 69
    assert with_bad.rows.reason.str.contains(r"trial pert300-1 left out of the null pairs: .* 18\.9 times").all()
    unscreened = _fit(onset_trials, 0.25, null=[*good, bad], counterfactual="matched_stride", max_null_trial_ratio=None)
    assert unscreened.rows.n_null_pairs.iloc[0] > 69
    assert not np.allclose(unscreened.rows.K_nm_per_rad, without.rows.K_nm_per_rad)
