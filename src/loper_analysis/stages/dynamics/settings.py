"""The dynamics stage's settings (config ``dynamics.*``), with the IK's coordinate map and the strides' points
per cycle."""

from __future__ import annotations

from collections.abc import Mapping

from loper_analysis.gait.stride_settings import StrideSettings
from loper_analysis.motion.ik_settings import IKSettings
from loper_analysis.stages.dynamics.step import DynamicsSettings

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ("ik", "strides")


def read_settings(config: Mapping, ik: IKSettings, strides: StrideSettings) -> DynamicsSettings:
    """The inverse dynamics' settings of a validated config: ``dynamics.cutoff_hz`` (Hz; null: no low-pass of the
    coordinates) and ``dynamics.foot_bodies`` (side -> the model body the ground's load acts on); the coordinate
    map (our angles' coordinates and signs) the IK's, the points per gait cycle the strides'."""
    d = config["dynamics"]
    return DynamicsSettings(
        cutoff_hz=d["cutoff_hz"],
        foot_bodies=dict(d["foot_bodies"]),
        coordinate_map=ik.coordinate_map,
        n_points=strides.n_points,
    )
