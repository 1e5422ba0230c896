"""The model stage's settings (motion.model_settings): every config key to its field, and the part of the
settings that generation, scaling and the segment table each read."""

import dataclasses
from pathlib import Path

import yaml

from loper_analysis.motion.model_settings import STATIC_DURATION_S, STATIC_MAX_MOTION_RMS_M, ModelSettings
from loper_analysis.stages.settings import stage_settings

CONFIG = yaml.safe_load((Path(__file__).resolve().parents[2] / "config" / "config.yaml").read_text())
BODIES = {"thigh": ["femur_{s}"], "shank": ["tibia_{s}"], "foot": ["talus_{s}", "calcn_{s}?"]}
MAP = {"hip": {"coordinate": "hip_flexion_{s}", "sign": 1}}


def _changed() -> ModelSettings:
    """Settings from the shipped config with every key the model stage reads set away from its default."""
    config = yaml.safe_load(yaml.safe_dump(CONFIG))
    config["markers"].update(lab_to_model_rotation_deg=[0, 0, 90])
    config["model"].update(
        static_duration_s=0.5,
        static_max_motion_rms_m=0.02,
        scale_factor_range=[0.7, 1.4],
        segment_bodies=BODIES,
        brace_attachment_fraction=0.6,
    )
    config["ik"].update(coordinate_map=MAP, tree_step_tolerance=1e-8, opensim_accuracy=1e-7)
    config["study"]["perturbed_side"] = "right"
    return stage_settings(config, "model")


def test_every_config_key_reaches_its_field():
    """Each changed key appears, converted (lists to float tuples), in its own field."""
    settings = _changed()
    assert settings == ModelSettings(
        rotation_deg=(0.0, 0.0, 90.0),
        static_duration_s=0.5,
        max_motion_rms_m=0.02,
        time_range_s=None,
        factor_range=(0.7, 1.4),
        segment_bodies=BODIES,
        side="right",
        attachment_fraction=0.6,
        coordinate_map=MAP,
        tree_step_tolerance=1e-8,
        opensim_accuracy=1e-7,
    )
    assert isinstance(settings.rotation_deg, tuple) and isinstance(settings.factor_range[0], float)


def test_defaults_are_the_named_constants():
    """The static window 1 s and motion limit 0.05 m; the left leg; rod at 0.8 of the thigh."""
    default = ModelSettings()
    assert (STATIC_DURATION_S, STATIC_MAX_MOTION_RMS_M) == (1.0, 0.05)
    assert (default.static_duration_s, default.max_motion_rms_m) == (1.0, 0.05)
    assert (default.rotation_deg, default.side, default.attachment_fraction) == ((-90.0, 0.0, 0.0), "left", 0.8)


def test_each_step_reads_only_its_part():
    """Generation keeps rotation and static window; scaling all but side and rod; segments bodies, side, rod."""
    settings = dataclasses.replace(_changed(), time_range_s=(0.1, 0.6))
    assert settings.for_generic() == ModelSettings(rotation_deg=(0.0, 0.0, 90.0), static_duration_s=0.5)
    assert settings.for_scaling() == dataclasses.replace(settings, side="left", attachment_fraction=0.8)
    assert settings.for_scaling().time_range_s == (0.1, 0.6)
    assert settings.for_segments() == ModelSettings(segment_bodies=BODIES, side="right", attachment_fraction=0.6)
    default = ModelSettings()
    assert (default.for_generic(), default.for_scaling(), default.for_segments()) == (default, default, default)
