"""loper_analysis.transparency: statistics of normalised strides and the transparency table, against analytic
answers."""

import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.outliers import MIN_VALID_STRIDES
from loper_analysis.reference import STUDY_TRANSPARENCY_RAD
from loper_analysis.stages.settings import stage_settings
from loper_analysis.study_design import PERTURBED_SIDE
from loper_analysis.transparency import (
    TRANSPARENCY_COLUMNS,
    TransparencySettings,
    isv_ave,
    mean_sd,
    mean_toe_off_pct,
    rmsd,
    transparency_table,
    within_subject_sd,
)

CONFIG = yaml.safe_load((Path(__file__).resolve().parents[1] / "config" / "config.yaml").read_text())


def test_mean_sd_and_within_subject_sd():
    base = np.sin(np.linspace(0, 2 * np.pi, 51))
    x = np.stack([base - 0.3, base, base + 0.3])  # SD 0.3 at every point (ddof = 1)
    mean, sd = mean_sd(x)
    np.testing.assert_allclose(mean, base, atol=1e-15)
    np.testing.assert_allclose(sd, 0.3, rtol=1e-12)
    assert within_subject_sd(x) == pytest.approx(0.3, rel=1e-12)
    x3 = np.stack([x, 2 * x], axis=-1)
    np.testing.assert_allclose(within_subject_sd(x3), [0.3, 0.6], rtol=1e-12)


def test_rmsd_of_known_curves():
    u = np.linspace(0, 1, 101)
    a = np.sin(2 * np.pi * u)
    assert rmsd(a, a + 0.1) == pytest.approx(0.1, rel=1e-12)
    # sum_k sin^2(2 pi k / 100) over k = 0..100 is 50: RMSD = c sqrt(50 / 101)
    c = 0.25
    assert rmsd(np.zeros(101), c * a) == pytest.approx(c * np.sqrt(50 / 101), rel=1e-12)
    np.testing.assert_allclose(
        rmsd(np.column_stack([a, a]), np.column_stack([a + 0.02, a - 0.05])), [0.02, 0.05], rtol=1e-12
    )


def test_isv_ave_of_known_sds():
    assert isv_ave([0.02, 0.03, 0.04, 0.05, 0.06]) == pytest.approx(2 / 5 * 0.20, rel=1e-12)
    np.testing.assert_allclose(isv_ave([[0.02, 0.1], [0.04, 0.3]]), [0.06, 0.4], rtol=1e-12)


def test_mean_toe_off_pct_of_known_strides():
    # strides of 1 s with a 0.6 s stance: toe-off at 60 %
    strides = pd.DataFrame({"stride": [0, 1, 2], "stance_s": 0.6, "duration_s": 1.0})
    assert mean_toe_off_pct(strides) == pytest.approx(60.0, rel=1e-12)


def _subject(offsets, sd_no_device, sd_device, n_points=51):
    """Per-phase arrays with a known mean offset (device - no_device) and known SDs per joint."""
    u = np.linspace(0, 1, n_points)
    base = np.column_stack([0.4 * np.sin(2 * np.pi * u), 0.9 * u, -0.1 * np.cos(np.pi * u)])
    spread = np.array([-1.0, 0.0, 1.0])[:, None, None]  # SD 1 across the 3 strides
    out = {}
    for condition, shift, sd in (("no_device", 0.0, sd_no_device), ("device", offsets, sd_device)):
        out[condition] = {phase: base + np.asarray(shift) + spread * np.asarray(sd) for phase in ("stance", "swing")}
    # the swing phase of the device condition carries twice the offset
    out["device"]["swing"] = base + 2 * np.asarray(offsets) + spread * np.asarray(sd_device)
    return out


def test_transparency_table_known_answers():
    per_subject = {
        "S01": _subject([0.01, 0.02, -0.045], [0.02, 0.03, 0.02], [0.5, 0.5, 0.5]),
        "S02": _subject([0.03, 0.00, 0.01], [0.04, 0.05, 0.03], [0.5, 0.5, 0.5]),
    }
    table = transparency_table(per_subject)
    assert list(table.columns) == list(TRANSPARENCY_COLUMNS)
    assert len(table) == 2 * 2 * 3 + 2 * 3
    assert list(table["subject"].unique()) == ["S01", "S02", "all"]
    idx = table.set_index(["subject", "phase", "joint"])
    np.testing.assert_allclose(
        idx.loc[("S01", "stance"), "rmsd_rad"].loc[["hip", "knee", "ankle"]], [0.01, 0.02, 0.045], rtol=1e-9
    )
    np.testing.assert_allclose(
        idx.loc[("S01", "swing"), "rmsd_rad"].loc[["hip", "knee", "ankle"]], [0.02, 0.04, 0.09], rtol=1e-9
    )
    np.testing.assert_allclose(
        idx.loc[("S02", "stance"), "sd_rad"].loc[["hip", "knee", "ankle"]], [0.04, 0.05, 0.03], rtol=1e-9
    )
    assert (table["n_strides_no_device"].iloc[:12] == 3).all()
    summary = idx.loc["all"]
    # mean RMSD over subjects; ISV_ave = (2 / 2) (sigma_S01 + sigma_S02), sigma from the no-device strides
    np.testing.assert_allclose(summary.loc[("stance", "hip"), "rmsd_rad"], 0.02, rtol=1e-9)
    np.testing.assert_allclose(summary.loc[("swing", "ankle"), "rmsd_rad"], (0.09 + 0.02) / 2, rtol=1e-9)
    np.testing.assert_allclose(summary.loc[("stance", "hip"), "isv_ave_rad"], 0.06, rtol=1e-9)
    np.testing.assert_allclose(summary.loc[("stance", "knee"), "isv_ave_rad"], 0.08, rtol=1e-9)
    np.testing.assert_allclose(summary.loc[("stance", "knee"), "sd_rad"], 0.04, rtol=1e-9)
    assert summary.loc[("stance", "hip"), "n_strides_device"] == 6
    # ISV_ave hip 0.06, knee 0.08, ankle 0.05; stance RMSD 0.02, 0.01, 0.0275; swing 0.04, 0.02, 0.055
    assert summary.loc["stance", "transparent"].all()
    swing = summary.loc["swing", "transparent"].loc[["hip", "knee", "ankle"]]
    np.testing.assert_array_equal(swing, [True, True, False])
    np.testing.assert_allclose(summary.loc[("swing", "ankle"), "isv_ave_rad"], 0.05, rtol=1e-9)
    # subject rows compare with the group ISV_ave: S01 swing ankle 0.09 > 0.05 > 0.02 (S02)
    assert not idx.loc[("S01", "swing", "ankle"), "transparent"]
    assert idx.loc[("S02", "swing", "ankle"), "transparent"]
    # sigma from the device strides instead: SD 0.5 everywhere -> ISV_ave = 1.0
    dev = transparency_table(per_subject, isv_condition="device").set_index(["subject", "phase", "joint"])
    np.testing.assert_allclose(dev.loc["all", "isv_ave_rad"], 1.0, rtol=1e-9)
    assert dev.attrs["isv_condition"] == "device"
    assert set(STUDY_TRANSPARENCY_RAD) == {(p, j) for p in ("stance", "swing") for j in ("hip", "knee", "ankle")}


def test_bad_inputs_are_named():
    good = np.zeros((3, 11, 3))
    with pytest.raises(LoperInputError, match="subject S07: condition 'device' missing"):
        transparency_table({"S07": {"no_device": {"stance": good, "swing": good}}})
    with pytest.raises(LoperInputError, match=r"subject S07, device, swing needs >= 2 strides, got 1"):
        transparency_table(
            {"S07": {"no_device": {"stance": good, "swing": good}, "device": {"stance": good, "swing": good[:1]}}}
        )
    with pytest.raises(LoperInputError, match="isv_condition must be one of"):
        transparency_table({"S07": {}}, isv_condition="both")
    with pytest.raises(LoperInputError, match="mean_a .* and mean_b .* must share a shape"):
        rmsd(np.zeros(5), np.zeros(6))
    with pytest.raises(LoperInputError, match="sigmas must be finite and >= 0"):
        isv_ave([0.1, np.nan])


# --------------------------------------------------------------------------- settings


def test_settings_of_the_config_and_the_defaults_agree():
    """The left leg and at least 5 kept strides, the strides' own."""
    assert stage_settings(CONFIG, "transparency") == TransparencySettings() == TransparencySettings("left", 5)
    assert (PERTURBED_SIDE, MIN_VALID_STRIDES) == ("left", 5)


def test_settings_take_the_config_s_side_and_stride_minimum():
    config = copy.deepcopy(CONFIG)
    config["study"]["perturbed_side"] = "right"
    config["strides"]["min_valid_strides"] = 7
    assert stage_settings(config, "transparency") == TransparencySettings(side="right", min_strides=7)


@pytest.mark.parametrize(("section", "key"), [("study", "perturbed_side"), ("strides", "min_valid_strides")])
def test_settings_name_a_missing_key(section, key):
    config = copy.deepcopy(CONFIG)
    del config[section][key]
    with pytest.raises(LoperInputError, match=f"^config: key '{section}.{key}' missing: "):
        stage_settings(config, "transparency")
