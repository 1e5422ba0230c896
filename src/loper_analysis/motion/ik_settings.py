"""The IK stage's settings (:class:`IKSettings`): the tasks, the solvers' tolerances and the limits a trial's fit is
held to, from the config (section ``opensim``, read by :mod:`loper_analysis.stages.ik.settings`)."""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass

from loper_analysis.constants import MIN_IK_MARKERS
from loper_analysis.motion.ik import IK_SOLVER, OPENSIM_ACCURACY, TREE_STEP_TOLERANCE
from loper_analysis.motion.marker_geometry import GEOMETRY_STOP_CHANGE, GEOMETRY_WARN_CHANGE
from loper_analysis.motion.plausibility import IK_MAX_FRACTION, IK_STOP_RMS_M, IK_WARN_RMS_M

__all__ = ["DEFAULT_MARKER_WEIGHT", "IKSettings"]

#: Weight of every model marker without a weight of its own (config ``ik.default_marker_weight``).
DEFAULT_MARKER_WEIGHT: float = 1.0


@dataclass(frozen=True)
class IKSettings:
    """How a trial's markers are solved for the model's coordinates (config ``opensim.*``).

    Attributes
    ----------
    tasks_file : str, optional
        OpenSim IK task-set XML or TSV (``ik.ik_tasks``); None: the weights below.
    default_weight : float
        Weight of a model marker without an entry in ``marker_weights`` (``ik.default_marker_weight``).
    marker_weights : mapping, optional
        Marker -> weight, 0 leaving a marker out (``ik.marker_weights``).
    coordinate_tasks : mapping, optional
        Coordinate -> ``{"weight": w, "value": rad or None}`` (``ik.coordinate_tasks``).
    tree_step_tolerance : float
        The tree solver stops a frame when its last step moved no coordinate by more than this (rad or m;
        ``ik.tree_step_tolerance``).
    opensim_accuracy : float
        Accuracy of OpenSim's ``InverseKinematicsSolver``, unitless: roughly the number of correct digits asked
        of the weighted objective's minimum (``ik.opensim_accuracy``); also when it serves in the tree's place.
    solver : str
        ``tree`` or ``opensim`` (``ik.ik_solver``; :func:`loper_analysis.motion.ik.inverse_kinematics`).
    min_markers : int
        Fewest weighted markers present in a frame for IK to solve it (no config key).
    max_marker_rms_m, warn_marker_rms_m : float
        A frame whose marker RMS error (m) exceeds the first counts as failed, the second as poorly fitted
        (``ik.max_marker_rms_m``, ``ik.warn_marker_rms_m``; the second None: no warning).
    max_rms_fraction : float
        Share of frames above either level that stops the trial, or warns (``ik.max_rms_fraction``).
    coordinate_map : mapping, optional
        Angle -> ``{"coordinate": name, "sign": +-1}`` of the angle table (``ik.coordinate_map``); None:
        :data:`loper_analysis.motion.ik.DEFAULT_COORDINATE_MAP`.
    geometry_warn_change, geometry_stop_change : float
        Median relative change of the distances between markers on one body, walking trial against the static
        trial (without one: against the model's markers), above which
        the trial is warned about or refused as another subject's (``ik.geometry_warn_change``,
        ``ik.geometry_stop_change``; :mod:`loper_analysis.motion.marker_geometry`).
    subjects_model : bool
        Whether the model was scaled to this subject's static trial (True) or given as it is (a ``model_osim``
        of the subject sheet, the command line's ``--model``): its markers may then sit elsewhere than on the
        subject, and a change against them beyond ``geometry_stop_change`` is a warning, unless the distances
        differ by a factor beyond 1.5 (a unit). A comparison with the static trial stops whatever the model.
    n_chunks : int
        The time chunks a trial's IK is split into, one job each, joined afterwards (``ik.ik_chunks``; 1: one
        job per trial).
    """

    tasks_file: str | os.PathLike | None = None
    default_weight: float = DEFAULT_MARKER_WEIGHT
    marker_weights: Mapping[str, float] | None = None
    coordinate_tasks: Mapping[str, Mapping] | None = None
    tree_step_tolerance: float = TREE_STEP_TOLERANCE
    opensim_accuracy: float = OPENSIM_ACCURACY
    solver: str = IK_SOLVER
    min_markers: int = MIN_IK_MARKERS
    max_marker_rms_m: float = IK_STOP_RMS_M
    warn_marker_rms_m: float | None = IK_WARN_RMS_M
    max_rms_fraction: float = IK_MAX_FRACTION
    coordinate_map: Mapping[str, Mapping] | None = None
    geometry_warn_change: float = GEOMETRY_WARN_CHANGE
    geometry_stop_change: float = GEOMETRY_STOP_CHANGE
    subjects_model: bool = True
    n_chunks: int = 1
