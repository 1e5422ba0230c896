"""The strides stage's settings (config ``strides.*``), with the study's leg."""

from __future__ import annotations

from collections.abc import Mapping

from loper_analysis.gait.stride_settings import StrideSettings
from loper_analysis.stages.study.settings import StudySettings

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ("study",)


def read_settings(config: Mapping, study: StudySettings) -> StrideSettings:
    """The stride settings of a validated config: ``strides.n_points``, ``iqr_whisker``,
    ``max_outlier_fraction`` and ``min_valid_strides``; the leg is the study design's ``perturbed_side``."""
    s = config["strides"]
    return StrideSettings(
        side=study.design.perturbed_side,
        n_points=s["n_points"],
        whisker=s["iqr_whisker"],
        max_fraction=s["max_outlier_fraction"],
        min_valid=s["min_valid_strides"],
    )
