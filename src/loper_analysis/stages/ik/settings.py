"""The ik stage's settings (config ``opensim.*``, the keys of inverse kinematics)."""

from __future__ import annotations

from collections.abc import Mapping

from loper_analysis.motion.ik_settings import IKSettings

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ()


def read_settings(config: Mapping) -> IKSettings:
    """The IK settings of a validated config: of ``opensim``, ``ik_tasks``, ``default_marker_weight``,
    ``marker_weights``, ``coordinate_tasks``, ``tree_step_tolerance`` (rad or m), ``opensim_accuracy``,
    ``ik_solver``, ``max_marker_rms_m`` (m), ``warn_marker_rms_m`` (m), ``max_rms_fraction``, ``coordinate_map``,
    ``geometry_warn_change``, ``geometry_stop_change`` and ``ik_chunks``."""
    o = config["ik"]
    return IKSettings(
        tasks_file=o["ik_tasks"],
        default_weight=o["default_marker_weight"],
        marker_weights=o["marker_weights"],
        coordinate_tasks=o["coordinate_tasks"],
        tree_step_tolerance=o["tree_step_tolerance"],
        opensim_accuracy=o["opensim_accuracy"],
        solver=o["ik_solver"],
        max_marker_rms_m=o["max_marker_rms_m"],
        warn_marker_rms_m=o["warn_marker_rms_m"],
        max_rms_fraction=o["max_rms_fraction"],
        coordinate_map=o["coordinate_map"],
        geometry_warn_change=o["geometry_warn_change"],
        geometry_stop_change=o["geometry_stop_change"],
        n_chunks=o["ik_chunks"],
    )
