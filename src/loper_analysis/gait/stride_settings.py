"""The strides stage's settings (:class:`StrideSettings`): the leg, the samples per cycle and the IQR rule, from
the config (section ``strides``, read by :mod:`loper_analysis.stages.strides.settings`)."""

from __future__ import annotations

from dataclasses import dataclass

from loper_analysis.gait.outliers import IQR_WHISKER, MAX_OUTLIER_FRACTION, MIN_VALID_STRIDES
from loper_analysis.gait.resampling import N_POINTS
from loper_analysis.study_design import PERTURBED_SIDE

__all__ = ["StrideSettings"]


@dataclass(frozen=True)
class StrideSettings:
    """Strides of one leg (config ``strides.*``, ``study.perturbed_side``).

    ``side``: the leg; ``n_points``: samples per time-normalised stride, stance or swing; ``whisker``,
    ``max_fraction``: the IQR rule (:func:`loper_analysis.gait.outliers.iqr_outliers`); ``min_valid``: the
    fewest kept strides of an ``ok`` trial.
    """

    side: str = PERTURBED_SIDE
    n_points: int = N_POINTS
    whisker: float = IQR_WHISKER
    max_fraction: float = MAX_OUTLIER_FRACTION
    min_valid: int = MIN_VALID_STRIDES
