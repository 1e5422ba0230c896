"""Lower bounds below zero: a knee with slightly negative damping is recovered, and the status rules judge
"none at all" at 0, not at the lower bound."""

from pathlib import Path

import numpy as np
import pytest
import yaml
from jsonschema import ValidationError, validate

from loper_analysis.config_file import load_config
from loper_analysis.impedance.identification import identify_impedance
from loper_analysis.impedance.identification.status import joint_status
from loper_analysis.impedance.identification.validation import perturbed_trial
from loper_analysis.impedance.identification.window import prepare_window, window_options
from loper_analysis.stages.settings import stage_settings
from tests.impedance.identification.validation_windows import PARAMS, SETTINGS

#: Hip, knee, ankle K (N·m/rad) and D (N·m·s/rad): the knee's K and D just below zero (within noise of a
#: small positive value, as estimates of the early-swing knee are).
TRUTH = np.array([40.0, 2.0, -0.4, -0.02, 10.0, 0.5])
LOWER = np.array([-20.0, -1.0, -20.0, -1.0, -20.0, -1.0])


def _window():
    t, q_u, q_p, f_p, pelvis, t_force = perturbed_trial(PARAMS, TRUTH, SETTINGS)
    return prepare_window(
        t - SETTINGS.onset_s,
        q_u,
        q_p,
        PARAMS,
        0.0,
        force_unperturbed_n=np.zeros_like(f_p),
        force_perturbed_n=f_p,
        force_time_s=t_force - SETTINGS.onset_s,
        pelvis_angle_unperturbed_rad=pelvis,
        pelvis_angle_perturbed_rad=pelvis,
        **window_options(SETTINGS),
    )


def test_negative_values_are_recovered_within_signed_bounds_and_clipped_at_zero():
    window = _window()
    signed = identify_impedance(window, n_starts=5, seed=0, lower=LOWER, upper=SETTINGS.upper)
    np.testing.assert_allclose(signed.estimate[[0, 2]], TRUTH[[0, 2]], atol=0.01)  # K, N·m/rad
    np.testing.assert_allclose(signed.estimate[[1, 3]], TRUTH[[1, 3]], atol=0.001)  # D, N·m·s/rad
    # bounds at 0: the knee's K and D sit on the bound and the hip's absorb part of the response
    clipped = identify_impedance(window, n_starts=5, seed=0, lower=np.zeros(6), upper=SETTINGS.upper)
    assert clipped.estimate[2] < 1e-9 and clipped.estimate[3] < 1e-9
    assert abs(clipped.estimate[0] - TRUTH[0]) > 0.05


@pytest.mark.parametrize(
    "low, high, identifiable",
    [(-0.3, 4.0, False), (0.5, 3.9, True), (-0.3, 2.0, True)],  # (0.5, 3.9): clear of 0, narrower than 0-3.5
)
def test_rule_4_asks_whether_the_interval_holds_zero_not_the_lower_bound(low, high, identifiable):
    status, reason = joint_status("knee", [1.8, 0.08], [low, 0.05], [high, 0.11], 95.0, [-20.0, -1.0], [200.0, 10.0])
    assert (status == "ok") == identifiable
    if not identifiable:
        assert "holds both 0 and the plausible range 0–3.5 N·m/rad" in reason


def test_an_estimate_on_a_negative_lower_bound_is_not_identifiable():
    status, reason = joint_status("knee", [-20.0, 0.08], [-20.0, 0.05], [-15.0, 0.11], 95.0, [-20, -1], [200, 10])
    assert status == "not_identifiable" and "at its lower bound -20 N·m/rad" in reason


def test_the_config_layer_sets_negative_lower_bounds_for_the_fit_only():
    root = Path(__file__).resolve().parents[3]
    config, _ = load_config(
        [root / "config/config.yaml", root / "config/paper.yaml", root / "config/signed_bounds.yaml"]
    )
    settings = stage_settings(config, "impedance").identification
    np.testing.assert_array_equal(settings.lower, LOWER)
    assert config["subjects"] == "config/subjects_paper.tsv"  # the layers below stay
    # the plausible ranges (sizes a joint may have) stay non-negative
    schema = yaml.safe_load((root / "workflow/schemas/config.schema.yaml").read_text())
    config["impedance"]["plausible_ranges"]["knee"]["stiffness_nm_per_rad"] = [-1.0, 3.5]
    with pytest.raises(ValidationError, match="-1.0 is less than the minimum of 0"):
        validate(config, schema)
