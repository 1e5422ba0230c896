"""The model stage's settings: scaling and the segment table (config ``opensim.*`` of the model,
``model.static_*``), with the markers' rotation, the IK's static pose and the study's leg."""

from __future__ import annotations

from collections.abc import Mapping

from loper_analysis.motion.ik_settings import IKSettings
from loper_analysis.motion.model_settings import ModelSettings
from loper_analysis.motion.trial_markers import MarkerSettings
from loper_analysis.stages.study.settings import StudySettings

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ("study", "markers", "ik")


def read_settings(config: Mapping, study: StudySettings, markers: MarkerSettings, ik: IKSettings) -> ModelSettings:
    """The model settings of a validated config: ``model.static_duration_s`` (s),
    ``model.static_max_motion_rms_m`` (m), ``model.scale_factor_range``, ``segment_bodies``,
    ``brace_attachment_fraction``, ``generic_model`` and ``scale_setup``; the rotation is the markers', the static
    pose's coordinate map, tolerances and solver the IK's, the leg the study's."""
    m = o = config["model"]
    return ModelSettings(
        rotation_deg=markers.rotation_deg,
        static_duration_s=m["static_duration_s"],
        max_motion_rms_m=m["static_max_motion_rms_m"],
        factor_range=tuple(float(v) for v in o["scale_factor_range"]),
        segment_bodies=o["segment_bodies"],
        side=study.design.perturbed_side,
        attachment_fraction=o["brace_attachment_fraction"],
        coordinate_map=ik.coordinate_map,
        tree_step_tolerance=ik.tree_step_tolerance,
        opensim_accuracy=ik.opensim_accuracy,
        solver=ik.solver,
        generic_model=o["generic_model"],
        scale_setup=o["scale_setup"],
    )
