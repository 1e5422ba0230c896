"""The model stage's settings (:class:`ModelSettings`): how the subject's model is built, scaled and turned into a
segment table, from the config (read by :mod:`loper_analysis.stages.model.settings`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

from loper_analysis.constants import LAB_TO_MODEL_ROTATION_DEG
from loper_analysis.motion.ik import IK_SOLVER, OPENSIM_ACCURACY, TREE_STEP_TOLERANCE
from loper_analysis.motion.plausibility import SCALE_FACTOR_RANGE
from loper_analysis.study_design import PERTURBED_SIDE
from loper_analysis.swing_leg.dynamics import BRACE_ATTACHMENT_FRACTION

__all__ = ["STATIC_DURATION_S", "STATIC_MAX_MOTION_RMS_M", "ModelSettings"]

#: Scaling averages the first this many seconds of the static trial when the scale setup sets no time range (s;
#: config ``model.static_duration_s``).
STATIC_DURATION_S: float = 1.0
#: A static-trial marker moving more than this over the scaling window stops scaling (m, RMS about its mean;
#: config ``model.static_max_motion_rms_m``).
STATIC_MAX_MOTION_RMS_M: float = 0.05


@dataclass(frozen=True)
class ModelSettings:
    """How the subject's model is built, scaled and turned into a segment table (config ``markers.*``,
    ``opensim.*``, ``study.perturbed_side``).

    Attributes
    ----------
    rotation_deg : (float, float, float)
        Lab -> model rotation about the fixed X, Y, Z axes, degrees: the lab's vertical, for the mass from the
        static trial's force plates (``markers.lab_to_model_rotation_deg``).
    static_duration_s : float or None
        Without a time range (``time_range_s``, the scale setup's): the stillest this many seconds of the static
        trial are averaged, s (:func:`loper_analysis.motion.still_window.stillest_window_s`); None: the whole trial
        (``model.static_duration_s``).
    max_motion_rms_m : float or None
        Largest RMS motion of a marker over the window, m: a subject who does not stand still is refused; None:
        not checked (``model.static_max_motion_rms_m``).
    time_range_s : (float, float), optional
        The window, s, overriding the setup's time ranges and ``static_duration_s`` (no config key).
    factor_range : (float, float)
        Least and largest plausible factor of a measurement (``model.scale_factor_range``).
    segment_bodies : mapping, optional
        Segment -> body names with ``{s}`` for the side suffix (``model.segment_bodies``); None: the model's
        own kind.
    side : {"left", "right"}
        The leg of the segment table (``study.perturbed_side``).
    attachment_fraction : float
        Rod attachment as a fraction of the thigh length, for a model without brace markers
        (``model.brace_attachment_fraction``).
    coordinate_map : mapping, optional
        Our angle -> model coordinate and sign, for the static pose of the scale report
        (``ik.coordinate_map``); None: :data:`loper_analysis.motion.ik.DEFAULT_COORDINATE_MAP`.
    tree_step_tolerance, opensim_accuracy : float
        The tree solver's step tolerance (rad or m) and OpenSim's solver's unitless accuracy for the scale report's
        static pose (``ik.tree_step_tolerance``, ``ik.opensim_accuracy``).
    solver : str
        IK solver of the scale report's static pose (``ik.ik_solver``).
    generic_model : str, optional
        The OpenSim model scaled per subject (``model.generic_model``); None: a sagittal model generated per
        subject.
    scale_setup : str, optional
        An OpenSim ScaleTool setup file whose measurements, marker pairs and time range scaling follows
        (``model.scale_setup``); None: the measurements of the model's kind.
    """

    rotation_deg: tuple[float, float, float] = LAB_TO_MODEL_ROTATION_DEG
    static_duration_s: float | None = STATIC_DURATION_S
    max_motion_rms_m: float | None = STATIC_MAX_MOTION_RMS_M
    time_range_s: tuple[float, float] | None = None
    factor_range: tuple[float, float] = SCALE_FACTOR_RANGE
    segment_bodies: Mapping[str, Sequence[str]] | None = None
    side: str = PERTURBED_SIDE
    attachment_fraction: float = BRACE_ATTACHMENT_FRACTION
    coordinate_map: Mapping[str, Mapping] | None = None
    tree_step_tolerance: float = TREE_STEP_TOLERANCE
    opensim_accuracy: float = OPENSIM_ACCURACY
    solver: str = IK_SOLVER
    generic_model: str | None = None
    scale_setup: str | None = None

    def for_generic(self) -> ModelSettings:
        """What the generated model reads (the static trial's window and vertical, for a mass from its plates),
        the other fields at their defaults: a setting it does not read leaves its rule's params unchanged."""
        return ModelSettings(rotation_deg=self.rotation_deg, static_duration_s=self.static_duration_s)

    def for_scaling(self) -> ModelSettings:
        """What scaling reads: all but the segment table's leg and rod attachment (at their defaults)."""
        return replace(self, side=PERTURBED_SIDE, attachment_fraction=BRACE_ATTACHMENT_FRACTION)

    def for_segments(self) -> ModelSettings:
        """What the segment table reads (bodies, side, rod attachment), the other fields at their defaults."""
        return ModelSettings(
            segment_bodies=self.segment_bodies, side=self.side, attachment_fraction=self.attachment_fraction
        )
