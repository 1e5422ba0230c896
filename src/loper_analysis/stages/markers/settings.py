"""The markers stage's settings: the walking trials' (config ``markers.*`` and ``markers.filter.*``)."""

from __future__ import annotations

from collections.abc import Mapping

from loper_analysis.motion.trial_markers import MarkerSettings

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ()


def read_settings(config: Mapping) -> MarkerSettings:
    """The walking trials' marker settings of a validated config: ``markers.lab_to_model_rotation_deg`` (deg),
    ``walking_direction``, ``min_travel_speed_m_per_s``, ``max_gap_frames``, ``extent_range_m`` (m), the label
    maps ``label_map`` and ``trial_label_maps``, the spans ``trial_spans_s`` (s) and the low-pass
    ``markers.filter.cutoff_hz`` (Hz) and ``markers.filter.order``."""
    m = config["markers"]
    f = m["filter"]
    return MarkerSettings(
        rotation_deg=tuple(float(v) for v in m["lab_to_model_rotation_deg"]),
        walking_direction=m["walking_direction"],
        min_travel_speed_m_per_s=float(m["min_travel_speed_m_per_s"]),
        max_gap_frames=int(m["max_gap_frames"]),
        cutoff_hz=f["cutoff_hz"],
        order=int(f["order"]),
        extent_range_m=tuple(float(v) for v in m["extent_range_m"]),
        label_map=m["label_map"] or None,
        trial_label_maps=m["trial_label_maps"],
        trial_spans_s=m["trial_spans_s"],
    )
