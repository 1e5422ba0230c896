"""The report's settings (report.front_page_settings): the run's headline settings of a config, each the value the
settings type that reads its key holds, the calibration table and the design fingerprint; a changed key reaches the
page, a missing key is named."""

import copy
from pathlib import Path

import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.report.calibration import CALIBRATED_STAGES, design_fingerprint
from loper_analysis.report.front_page import RunSettings
from loper_analysis.report.front_page_settings import FrontPageSettings
from loper_analysis.stages.settings import stage_settings

CONFIG = yaml.safe_load((Path(__file__).resolve().parents[2] / "config" / "config.yaml").read_text())
#: The shipped config's run settings, written out.
SHIPPED = RunSettings(
    seed=2024,
    perturbation_onsets_ms=(50, 175, 300),
    perturbation_repeats=2,
    perturbed_side="left",
    filter_cutoff_hz=40.0,
    filter_order=4,
    window_before_s=0.025,
    window_after_s=0.25,
    stiffness_bounds_nm_per_rad=(0.0, 200.0),
    damping_bounds_nms_per_rad=(0.0, 10.0),
    n_starts=10,
    noise_model="null_pairs",
    null_pair_components=6,
    synthetic_variability="study",
    synthetic_walking_duration_s=45.0,
    pulse_force_n=40.0,
    pulse_duration_s=0.1,
)


def test_the_shipped_config_s_run_settings():
    """Every value, and the repr the front page rule's params compare (onsets and bounds as tuples; the design
    fingerprint left out: a changed design reruns the fits and the page after them)."""
    settings = stage_settings(CONFIG, "report")
    fingerprint = design_fingerprint({name: stage_settings(CONFIG, name) for name in CALIBRATED_STAGES})
    shipped = FrontPageSettings(SHIPPED, "config/calibration/truth_recovery.tsv", fingerprint)
    assert settings == shipped and len(settings.design_fingerprint) == 16
    assert repr(settings) == repr(shipped) and fingerprint not in repr(settings)


def test_the_calibration_key_reaches_the_settings_and_null_names_none():
    config = copy.deepcopy(CONFIG)
    config["report"]["calibration"] = "config/calibration/other.tsv"
    assert stage_settings(config, "report").calibration == "config/calibration/other.tsv"
    config["report"]["calibration"] = None
    assert stage_settings(config, "report").calibration is None


def test_every_key_the_page_lists_reaches_its_row():
    config = copy.deepcopy(CONFIG)
    config["seed"] = 7
    config["study"].update(perturbation_onsets_ms=[60, 200], perturbation_repeats=3, perturbed_side="right")
    config["markers"]["filter"].update(cutoff_hz=12.0, order=2)
    config["impedance"].update(
        window_before_s=0.03,
        window_after_s=0.2,
        stiffness_bounds_nm_per_rad=[1.0, 150.0],
        damping_bounds_nms_per_rad=[0.5, 8.0],
        n_starts=3,
        noise_model="white",
        null_pair_components=4,
    )
    config["synthetic"].update(variability="gentle", walking_duration_s=30.0, pulse_force_n=30.0, pulse_duration_s=0.08)
    assert stage_settings(config, "report").run == RunSettings(
        *(7, (60, 200), 3, "right", 12.0, 2, 0.03, 0.2, (1.0, 150.0), (0.5, 8.0)),
        *(3, "white", 4, "gentle", 30.0, 30.0, 0.08),
    )
    rows = dict(stage_settings(config, "report").run.rows())
    assert "3 random starts" in rows["bounds"] and rows["perturbations"].startswith("onsets 60, 200 ms after right")


@pytest.mark.parametrize(
    "path",
    [
        ("impedance", "n_starts"),
        ("markers", "filter", "cutoff_hz"),
        ("synthetic", "pulse_force_n"),
        ("seed",),
        ("report", "calibration"),
        ("report",),
    ],
)
def test_a_missing_key_is_named(path):
    config = copy.deepcopy(CONFIG)
    node = config
    for name in path[:-1]:
        node = node[name]
    del node[path[-1]]
    with pytest.raises(LoperInputError, match=f"^config: key '{'.'.join(path)}' missing: "):
        stage_settings(config, "report")
