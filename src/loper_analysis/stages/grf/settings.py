"""The grf stage's settings (config ``grf.*``), with the markers' rotation."""

from __future__ import annotations

from collections.abc import Mapping

from loper_analysis.gait.grf_settings import GRFSettings
from loper_analysis.motion.trial_markers import MarkerSettings

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ("markers",)


def read_settings(config: Mapping, markers: MarkerSettings) -> GRFSettings:
    """The ground-reaction settings of a validated config: ``grf.loaded_threshold_n``, ``grf.resting_band_n``
    and ``grf.max_resting_n`` (N); the rotation is the markers'."""
    g = config["grf"]
    return GRFSettings(
        rotation_deg=markers.rotation_deg,
        threshold_n=g["loaded_threshold_n"],
        band_n=g["resting_band_n"],
        max_rest_n=g["max_resting_n"],
    )
