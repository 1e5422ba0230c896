"""The IK stage's settings (motion.ik_settings): every ``opensim`` key the IK reads to its field, the defaults
the shipped config's, a missing key named; the model stage's static pose takes its solvers' tolerances and
coordinate map from here."""

import copy
from pathlib import Path

import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.motion.ik import OPENSIM_ACCURACY, TREE_STEP_TOLERANCE
from loper_analysis.motion.ik_settings import DEFAULT_MARKER_WEIGHT, IKSettings
from loper_analysis.stages.settings import stage_settings

CONFIG = yaml.safe_load((Path(__file__).resolve().parents[2] / "config" / "config.yaml").read_text())
MAP = {"knee_left": {"coordinate": "knee_angle_l", "sign": -1}}


def _changed() -> dict:
    """The shipped config with every key the IK reads set away from its default."""
    config = copy.deepcopy(CONFIG)
    config["ik"].update(
        ik_tasks="tasks.xml",
        default_marker_weight=0.5,
        marker_weights={"LASI": 2.0, "RASI": 0.0},
        coordinate_tasks={"pelvis_tilt": {"weight": 10.0, "value": None}},
        tree_step_tolerance=1e-8,
        opensim_accuracy=1e-7,
        max_marker_rms_m=0.03,
        warn_marker_rms_m=None,
        max_rms_fraction=0.25,
        coordinate_map=MAP,
        geometry_warn_change=0.08,
        geometry_stop_change=0.4,
    )
    return config


def test_every_config_key_reaches_its_field():
    """Each changed key in its own field; the fewest markers (no key) and the subject's own model keep theirs."""
    assert stage_settings(_changed(), "ik") == IKSettings(
        tasks_file="tasks.xml",
        default_weight=0.5,
        marker_weights={"LASI": 2.0, "RASI": 0.0},
        coordinate_tasks={"pelvis_tilt": {"weight": 10.0, "value": None}},
        tree_step_tolerance=1e-8,
        opensim_accuracy=1e-7,
        min_markers=IKSettings().min_markers,
        max_marker_rms_m=0.03,
        warn_marker_rms_m=None,
        max_rms_fraction=0.25,
        coordinate_map=MAP,
        geometry_warn_change=0.08,
        geometry_stop_change=0.4,
        subjects_model=True,
    )


def test_the_shipped_config_gives_the_defaults():
    """Tree step tolerance and OpenSim's accuracy 1e-6, weight 1, RMS limits 0.06 / 0.02 m over 10 % of the
    frames, geometry 5 % / 8 %."""
    shipped = stage_settings(CONFIG, "ik")
    assert shipped.tree_step_tolerance == TREE_STEP_TOLERANCE == 1e-6
    assert shipped.opensim_accuracy == OPENSIM_ACCURACY == 1e-6
    assert (shipped.default_weight, DEFAULT_MARKER_WEIGHT) == (1.0, 1.0)
    assert (shipped.max_marker_rms_m, shipped.warn_marker_rms_m, shipped.max_rms_fraction) == (0.06, 0.02, 0.1)
    assert (shipped.geometry_warn_change, shipped.geometry_stop_change) == (0.05, 0.08)
    assert shipped.tasks_file is None and shipped.marker_weights == {} and shipped.coordinate_tasks == {}
    assert (shipped.min_markers, shipped.subjects_model) == (IKSettings().min_markers, True)


def test_the_scale_report_takes_the_ik_tolerances_and_coordinate_map():
    """ik.tree_step_tolerance, ik.opensim_accuracy and ik.coordinate_map reach the model stage's static pose as
    the IK's, each tolerance for its own solver."""
    model, ik = stage_settings(_changed(), "model"), stage_settings(_changed(), "ik")
    assert (ik.tree_step_tolerance, ik.opensim_accuracy, ik.coordinate_map) == (1e-8, 1e-7, MAP)
    assert (model.tree_step_tolerance, model.opensim_accuracy, model.coordinate_map) == (1e-8, 1e-7, MAP)
    assert (model.for_scaling().tree_step_tolerance, model.for_scaling().opensim_accuracy) == (1e-8, 1e-7)


@pytest.mark.parametrize("key", ["tree_step_tolerance", "opensim_accuracy", "geometry_stop_change", "ik_tasks"])
def test_a_missing_key_is_named(key):
    config = copy.deepcopy(CONFIG)
    del config["ik"][key]
    with pytest.raises(LoperInputError, match=f"^config: key 'ik.{key}' missing: the ik settings read it$"):
        stage_settings(config, "ik")
