"""The strides stage's settings (:class:`StrideSettings`): the leg, the samples per cycle and the IQR rule, from
the config (:meth:`StrideSettings.from_config`, section ``strides``)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from loper_analysis.gait.outliers import IQR_WHISKER, MAX_OUTLIER_FRACTION, MIN_VALID_STRIDES
from loper_analysis.gait.resampling import N_POINTS
from loper_analysis.study_design import PERTURBED_SIDE, StudyDesign

__all__ = ["StrideSettings"]


@dataclass(frozen=True)
class StrideSettings:
    """Strides of one leg (config ``strides.*``, ``trials.perturbed_side``).

    ``side``: the leg; ``n_points``: samples per time-normalised stride, stance or swing; ``whisker``,
    ``max_fraction``: the IQR rule (:func:`loper_analysis.gait.outliers.iqr_outliers`); ``min_valid``: the
    fewest kept strides of an ``ok`` trial.
    """

    side: str = PERTURBED_SIDE
    n_points: int = N_POINTS
    whisker: float = IQR_WHISKER
    max_fraction: float = MAX_OUTLIER_FRACTION
    min_valid: int = MIN_VALID_STRIDES

    @classmethod
    def from_config(cls, config: Mapping) -> StrideSettings:
        """The settings of a validated config.

        Parameters
        ----------
        config : mapping
            The validated configuration: ``strides.n_points``, ``strides.iqr_whisker``,
            ``strides.max_outlier_fraction`` and ``strides.min_valid_strides``; the leg is the study design's
            (``trials.perturbed_side``, :meth:`loper_analysis.study_design.StudyDesign.from_config`).

        Raises
        ------
        KeyError
            A key missing, named.
        """
        s = config["strides"]
        return cls(
            side=StudyDesign.from_config(config["trials"]).perturbed_side,
            n_points=s["n_points"],
            whisker=s["iqr_whisker"],
            max_fraction=s["max_outlier_fraction"],
            min_valid=s["min_valid_strides"],
        )
