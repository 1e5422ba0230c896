"""A pilot subject's plan (planning.pilot_plan): the settings from the config, the planned impedance from fit
rows, the plan request's checks, and the plan of one onset against its covariance computed step by step."""

import copy
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.responses import ResponseSettings, null_pair_windows
from loper_analysis.planning.covariance import stride_covariance
from loper_analysis.planning.inputs import pilot_perturbed_pairs
from loper_analysis.planning.pilot_plan import (
    STRIDES,
    PlanningSettings,
    check_plan_request,
    pilot_plan,
    planned_impedance,
)
from loper_analysis.planning.precision import precision_table, target_answer
from loper_analysis.planning.window import PlanSettings
from loper_analysis.stages.settings import stage_settings
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry
from loper_analysis.synthetic.coordinate_trials import perturbation_experiment

CONFIG = yaml.safe_load((Path(__file__).resolve().parents[2] / "config" / "config.yaml").read_text())
PARAMS = segment_parameters_from_anthropometry(1.73, 64.9)
TRUTH = np.array([55.0, 3.5, 3.0, 0.10, 8.0, 0.3])
MATCHED = ResponseSettings(counterfactual="matched_stride")
PLAN = PlanSettings(interval_scatter="perturbed_pairs")


def test_settings_of_the_shipped_config():
    """Onsets, stride counts, targets and the null-trial ratio are the config's."""
    settings = stage_settings(CONFIG, "planning")
    assert settings.onsets_ms == (50, 175, 300)
    assert settings.strides == (10, 20, 40) == STRIDES
    assert settings.targets == tuple(CONFIG["planning"]["targets"])
    assert settings.max_null_trial_ratio == CONFIG["impedance"]["max_null_trial_ratio"]
    assert settings.plan == stage_settings(CONFIG, "planning").plan
    assert settings.response == stage_settings(CONFIG, "impedance").response


@pytest.mark.parametrize(
    ("path", "message"),
    [
        (("impedance", "counterfactual"), "config: key 'impedance.counterfactual' missing: "),
        (("device",), "config: key 'device' missing: the device settings read it$"),
        (("planning", "pulse_force_n"), "config: key 'planning.pulse_force_n' missing: "),
    ],
)
def test_a_missing_key_is_named(path, message):
    config = copy.deepcopy(CONFIG)
    node = config
    for key in path[:-1]:
        node = node[key]
    del node[path[-1]]
    with pytest.raises(LoperInputError, match=f"^{message}"):
        stage_settings(config, "planning")


def _rows(knee_k: float = 3.0, status: str = "ok") -> pd.DataFrame:
    """Fit rows of P01 at 50 ms (K, D per joint) and a decoy row of another subject."""
    rows = [
        ("P01", 50, "hip", 55.0, 3.5, "ok"),
        ("P01", 50, "knee", knee_k, 0.1, status),
        ("P01", 50, "ankle", 8.0, 0.3, "ok"),
        ("P02", 50, "hip", 99.0, 9.9, "ok"),
        ("P01", 175, "hip", 77.0, 7.7, "ok"),
    ]
    return pd.DataFrame(rows, columns=["subject", "onset_ms", "joint", "K_nm_per_rad", "D_nms_per_rad", "status"])


def test_planned_impedance_is_the_subjects_row_at_the_onset():
    """K, D of hip, knee, ankle in that order; a knee without estimate is refused naming file, joint and status."""
    np.testing.assert_array_equal(planned_impedance(_rows(), "P01", 50, "fits.tsv"), TRUTH)
    failed = _rows(np.nan, "failed").assign(reason="no convergence")
    with pytest.raises(
        LoperInputError,
        match=r"^fits.tsv: no fitted impedance of subject P01 at onset 50 ms for the knee \(failed: no convergence\)",
    ):
        planned_impedance(failed, "P01", 50, "fits.tsv")
    with pytest.raises(LoperInputError, match=r"for the knee \(no row\)"):
        planned_impedance(_rows(), "P01", 175, "fits.tsv")
    with pytest.raises(LoperInputError, match=r"^fits.tsv: impedance rows lack column\(s\) \['D_nms_per_rad'\]"):
        planned_impedance(_rows().drop(columns="D_nms_per_rad"), "P01", 50, "fits.tsv")


def test_plan_request_is_checked_before_any_work():
    """The counts come back as given; a bad mode, no onsets or a count below 1 is refused by name."""
    assert check_plan_request(PlanningSettings(onsets_ms=(50,), strides=(5, 12))) == [5, 12]
    with pytest.raises(LoperInputError, match=r"^unplannable must be 'raise' or 'note', got 'skip'"):
        check_plan_request(PlanningSettings(onsets_ms=(50,)), "skip")
    with pytest.raises(LoperInputError, match=r"no onsets \(onsets_ms\)"):
        check_plan_request(PlanningSettings())
    for bad in (0, 2.5, True):
        with pytest.raises(LoperInputError, match=f"stride count must be a whole number >= 1 .*got {bad!r}$"):
            check_plan_request(PlanningSettings(onsets_ms=(50,), strides=(10, bad)))


def test_an_onset_without_perturbed_trials_is_noted_or_stops():
    """An empty pilot: each onset's 6 x 2 rows carry the cause in ``note`` with no prediction, or the plan stops."""
    settings = PlanningSettings(onsets_ms=(50, 175), strides=(10, 20))
    table, answers = pilot_plan([], PARAMS, settings, "P01", impedance=TRUTH, unplannable="note")
    assert answers == [] and len(table) == 2 * 6 * 2
    assert list(table["onset_ms"].unique()) == [50.0, 175.0]
    assert table["predicted_sd"].isna().all()
    assert table.loc[13, "note"].startswith("not planned: pilot P01, onset 175 ms: no trial of the pilot is perturbed")
    with pytest.raises(LoperInputError, match=r"^pilot P01, onset 50 ms: no trial of the pilot is perturbed"):
        pilot_plan([], PARAMS, settings, "P01", impedance=TRUTH)


def test_plan_of_one_onset_is_its_stride_covariance():
    """Matched strides: the table is precision_table of the pilot's null and perturbed pairs' covariance, the
    answers those of the targets without an onset or at this one."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        full, _ = perturbation_experiment([11, 0], PARAMS, 1.73, 50, TRUTH, [40], angle_noise_sd_rad=0.001)
        null = null_pair_windows([full], 50, MATCHED, source="P01")
        pairs = pilot_perturbed_pairs([full], 50, MATCHED)
    sc = stride_covariance(null, PARAMS, TRUTH, PLAN, perturbed_pairs=pairs)
    targets = (
        {"joint": "hip", "parameter": "K", "percent": 20},
        {"joint": "knee", "parameter": "D", "half_width": 0.05, "onset_ms": 50},
        {"joint": "ankle", "parameter": "K", "percent": 10, "onset_ms": 175},
    )
    settings = PlanningSettings(onsets_ms=(50,), strides=(10, 40), targets=targets, plan=PLAN, response=MATCHED)
    table, answers = pilot_plan([full], PARAMS, settings, "P01", impedance={50: TRUTH}, pool_scatter=False)
    pd.testing.assert_frame_equal(table, precision_table(sc, [10, 40], 50, "P01", PLAN, None))
    assert answers == [
        target_answer(sc, "hip", "K", 50, percent=20),
        target_answer(sc, "knee", "D", 50, half_width=0.05),
    ]
    assert table["predicted_sd"].notna().all() and (table["n_null_pairs"] == sc.n_null_pairs).all()
