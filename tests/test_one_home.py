"""One home per value and helper: the shared constants are the ones every default and caller uses.

Each test pins one value or helper to its home (the module named in its assertion) and checks that the
places that used to write it themselves now take it from there, with the same numbers and bytes.
"""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy.special import stdtrit

from loper_analysis import transparency
from loper_analysis.errors import LoperInputError
from loper_analysis.gait import events, outliers, strides
from loper_analysis.gait.outliers import MIN_STRIDES_FOR_OUTLIERS, MIN_VALID_STRIDES, iqr_outliers
from loper_analysis.gait.stride_settings import StrideSettings
from loper_analysis.impedance.identification import t_quantile
from loper_analysis.impedance.responses import MIN_PAIRS_FOR_OUTLIERS, ResponseSettings
from loper_analysis.io.atomic import write_tsv
from loper_analysis.io.segment_table import SEGMENT_FLOAT_FORMAT, read_segments, write_segments
from loper_analysis.planning.covariance import StrideCovariance
from loper_analysis.stages.strides import step as stride_steps
from loper_analysis.study_design import TRANSPARENCY_CONDITIONS, StudyDesign
from tests.parameter_sets import ASYMMETRIC

ROOT = Path(__file__).resolve().parents[1]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
SCHEMA = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
STEPS = ROOT / "src" / "loper_analysis" / "steps"


def _default(func, name: str):
    return inspect.signature(func).parameters[name].default


def test_min_valid_strides_is_the_config_value_and_every_default():
    assert MIN_VALID_STRIDES == CONFIG["strides"]["min_valid_strides"]
    schema = SCHEMA["properties"]["strides"]["properties"]["min_valid_strides"]
    if "default" in schema:
        assert schema["default"] == MIN_VALID_STRIDES
    defaults = {
        "strides.stride_tables": _default(strides.stride_tables, "min_valid"),
        "strides.stride_summary": _default(strides.stride_summary, "min_valid"),
        "gait.stride_settings.StrideSettings.min_valid": StrideSettings().min_valid,
        "steps.stride_steps.strides_summary": _default(stride_steps.strides_summary, "min_valid"),
        "transparency.transparency_results": _default(transparency.transparency_results, "min_strides"),
        "transparency.TransparencySettings.min_strides": transparency.TransparencySettings().min_strides,
        "outliers.check_enough_strides": _default(outliers.check_enough_strides, "minimum"),
        "ResponseSettings.min_strides": ResponseSettings().min_strides,
    }
    assert defaults == dict.fromkeys(defaults, MIN_VALID_STRIDES)


def test_the_iqr_rule_s_fewest_strides_has_one_home():
    assert MIN_STRIDES_FOR_OUTLIERS == 4
    assert strides.MIN_STRIDES_FOR_OUTLIERS is MIN_STRIDES_FOR_OUTLIERS  # imported, not written again
    assert MIN_PAIRS_FOR_OUTLIERS == MIN_STRIDES_FOR_OUTLIERS
    values = np.random.default_rng(4).normal(size=(MIN_STRIDES_FOR_OUTLIERS, 11))
    assert len(iqr_outliers(values)) == MIN_STRIDES_FOR_OUTLIERS
    with pytest.raises(LoperInputError, match=f"the IQR rule needs >= {MIN_STRIDES_FOR_OUTLIERS} strides, got 3"):
        iqr_outliers(values[:-1])


@pytest.mark.parametrize("dof", [1, 2, 3, 4, 9, 29, 102, 10**6])
def test_planning_takes_the_fit_s_t_quantile_with_the_same_numbers(dof):
    assert t_quantile(dof) == float(stdtrit(dof, 0.975))
    cov = StrideCovariance(np.eye(6), np.ones(6), None, 0)
    assert cov.t95(dof + 1) == t_quantile(dof)
    assert StrideCovariance(np.eye(6), np.ones(6), dof, 0).t95(50) == t_quantile(dof)


def test_condition_names_have_one_meaning():
    assert not hasattr(transparency, "CONDITIONS")
    assert TRANSPARENCY_CONDITIONS == ("no_device", "device")
    design = StudyDesign()
    conditions = {design.condition(trial) for trial in design.trials()}
    assert conditions == {"static", *TRANSPARENCY_CONDITIONS, "perturbation", "device_test"}
    assert (design.condition(design.no_device), design.condition(design.device)) == TRANSPARENCY_CONDITIONS


def test_the_stride_table_from_events_lives_with_the_strides():
    assert not hasattr(events, "strides") and not hasattr(events, "STRIDE_COLUMNS")
    kinds = ["heel_strike", "toe_off"] * 2 + ["heel_strike"]
    table = pd.DataFrame({"side": "left", "event": kinds, "time_s": [0.0, 0.6, 1.0, 1.6, 2.0]})
    out = strides.strides_from_events(table, "left")
    assert list(out.columns) == list(strides.STRIDE_COLUMNS)
    np.testing.assert_allclose(out["stance_s"], [0.6, 0.6])


def test_segment_table_bytes_are_the_format_of_io(tmp_path):
    assert SEGMENT_FLOAT_FORMAT == "%.10g"
    write_segments(ASYMMETRIC, tmp_path / "typed.tsv")
    write_tsv(ASYMMETRIC.to_frame(), tmp_path / "by_hand.tsv", "%.10g")
    assert (tmp_path / "typed.tsv").read_bytes() == (tmp_path / "by_hand.tsv").read_bytes()
    np.testing.assert_allclose(read_segments(tmp_path / "typed.tsv").packed, ASYMMETRIC.packed, rtol=1e-9)


def test_step_modules_do_not_import_each_other():
    steps = {p.stem for p in STEPS.glob("*.py")} - {"__init__", "logs"}  # logs: every step's job log
    found = []
    for path in sorted(STEPS.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                names = [node.module] if node.module else [a.name for a in node.names]
                found += [f"{path.stem} -> {n}" for n in names if n and n.split(".")[0] in steps]
    assert found == []


def test_the_iqr_rule_s_whisker_and_fraction_are_the_config_s_and_every_default():
    from loper_analysis.gait.outliers import IQR_WHISKER, MAX_OUTLIER_FRACTION
    from loper_analysis.impedance.responses import ResponseSettings
    from loper_analysis.impedance.responses.windows import window_outliers

    assert (IQR_WHISKER, MAX_OUTLIER_FRACTION) == (
        CONFIG["strides"]["iqr_whisker"],
        CONFIG["strides"]["max_outlier_fraction"],
    )
    for function in (iqr_outliers, strides.stride_tables, window_outliers):
        defaults = inspect.signature(function).parameters
        assert (defaults["whisker"].default, defaults["max_fraction"].default) == (IQR_WHISKER, MAX_OUTLIER_FRACTION)
    for settings in (ResponseSettings(), StrideSettings()):
        assert (settings.whisker, settings.max_fraction) == (IQR_WHISKER, MAX_OUTLIER_FRACTION)
