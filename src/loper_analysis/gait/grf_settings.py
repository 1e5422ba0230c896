"""The ground-reaction stage's settings (:class:`GRFSettings`): how a C3D's force platforms become ground
reactions in the model frame, from the config (section ``grf``, read by :mod:`loper_analysis.stages.grf.settings`)."""

from __future__ import annotations

from dataclasses import dataclass

from loper_analysis.constants import LAB_TO_MODEL_ROTATION_DEG, LOADED_THRESHOLD_N
from loper_analysis.gait.grf import MAX_RESTING_N, RESTING_BAND_N

__all__ = ["GRFSettings"]


@dataclass(frozen=True)
class GRFSettings:
    """How a C3D's force platforms become ground reactions in the model frame (config ``grf.*``, ``markers.*``).

    Attributes
    ----------
    rotation_deg : (float, float, float)
        Lab -> model rotation about the fixed X, Y, Z axes, degrees (``markers.lab_to_model_rotation_deg``).
    threshold_n : float
        A plate is loaded above this vertical force over its resting level, N (``grf.loaded_threshold_n``).
    band_n, max_rest_n : float
        The resting-level rule, N (``grf.resting_band_n``, ``grf.max_resting_n``;
        :func:`loper_analysis.gait.grf.resting_level`).
    """

    rotation_deg: tuple[float, float, float] = LAB_TO_MODEL_ROTATION_DEG
    threshold_n: float = LOADED_THRESHOLD_N
    band_n: float = RESTING_BAND_N
    max_rest_n: float = MAX_RESTING_N
