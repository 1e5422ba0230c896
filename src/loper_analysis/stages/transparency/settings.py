"""The transparency stage's settings: the strides' leg and fewest kept strides (it has no keys of its own)."""

from __future__ import annotations

from collections.abc import Mapping

from loper_analysis.gait.stride_settings import StrideSettings
from loper_analysis.transparency import TransparencySettings

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ("strides",)


def read_settings(config: Mapping, strides: StrideSettings) -> TransparencySettings:
    """The transparency's settings: the strides' leg and ``min_valid_strides``."""
    return TransparencySettings(side=strides.side, min_strides=strides.min_valid)
