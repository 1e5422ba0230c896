"""Inverse kinematics through OpenSim, in memory, plus forward marker kinematics.

One ``InverseKinematicsSolver`` is reused for all frames (far faster than
``InverseKinematicsTool`` per call); markers enter as a ``TimeSeriesTableVec3``
in metres with its ``Units`` metadata set (OpenSim assumes metres when the
metadata is missing). Missing (NaN) markers are dropped by OpenSim in that
frame; a frame with fewer than ``min_markers`` weighted markers is refused
before solving. Coordinate tasks (e.g. locking a coordinate at its default) are
honoured. Models are ``opensim.Model`` objects (:func:`loper_analysis.io.osim.read_model`).

Task specification: ``marker_weights`` {marker: weight} and
``coordinate_tasks`` {coordinate: (weight, value or None)} where ``None``
means the coordinate's default value. Without marker weights every model
marker present in the data gets weight 1. :func:`loper_analysis.io.ik_tasks.read_ik_tasks`
reads them from an OpenSim IK task-set XML or a TSV.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import model_source
from loper_analysis.motion.ik_determinacy import (
    ModelTree,
    model_tree,
    require_markers_beyond_root,
    undetermined_coordinates,
)
from loper_analysis.motion.markers import frames_with_markers, require_markers_per_frame

__all__ = [
    "OPENSIM_ACCURACY",
    "TREE_STEP_TOLERANCE",
    "IK_SOLVER",
    "IK_SOLVERS",
    "IKResult",
    "IK_SUMMARY_COLUMNS",
    "marker_positions",
    "inverse_kinematics",
    "require_model_markers",
    "ik_task_weights",
    "chunk_frames",
    "join_chunks",
    "DEFAULT_COORDINATE_MAP",
    "ANGLE_COLUMNS",
    "joint_angle_table",
]

#: The tree solver's step tolerance (rad or m; config ``ik.tree_step_tolerance``): it stops a frame when its last
#: step moved no coordinate by more than this (:mod:`loper_analysis.motion.tree_ik`).
TREE_STEP_TOLERANCE: float = 1e-6
#: Accuracy of OpenSim's ``InverseKinematicsSolver`` (config ``ik.opensim_accuracy``): unitless, roughly the
#: number of correct digits asked of the weighted objective's minimum (OpenSim's own default is 1e-5).
OPENSIM_ACCURACY: float = 1e-6


#: The IK solvers (config ``ik.ik_solver``): the model's kinematic tree (:mod:`loper_analysis.motion.tree_ik`)
#: or OpenSim's ``InverseKinematicsSolver`` (:mod:`loper_analysis.motion.opensim_ik`).
IK_SOLVERS: tuple[str, ...] = ("tree", "opensim")
#: The pipeline's IK solver.
IK_SOLVER: str = "tree"
#: Frames from which :func:`marker_positions` places markers with the model's kinematic tree: below them
#: building and checking the tree (about 0.1 s) costs more than OpenSim's own placing (0.1 ms per frame).
TREE_MIN_FRAMES: int = 1000

#: Columns of the one-row IK summary of a trial (:meth:`IKResult.summary`).
IK_SUMMARY_COLUMNS: tuple[str, ...] = (
    "n_frames",
    "n_frames_solved",
    "n_frames_left_out",
    "first_solved_s",
    "last_solved_s",
    "marker_rms_mean_m",
    "marker_rms_max_m",
    "n_frames_over_warn",
    "worst_marker",
    "worst_marker_rms_m",
    "worst_markers_mm",
    "marker_geometry_change",
    "warnings",
    "solver",
)


@dataclass
class IKResult:
    """IK output: ``coordinates`` (n_frames, n_coordinates) in rad or m, in model order.

    ``marker_rms_m`` and ``marker_max_m`` (n_frames,) are the RMS and largest
    marker distance error per frame (m). ``undetermined`` maps each coordinate
    that no marker, task or model constraint determined in some frames to the
    number of those frames, written as NaN (:mod:`loper_analysis.motion.ik_determinacy`).
    ``solved`` (n_frames,) is False for the frames left out of the solve (too
    few markers): every coordinate and error is NaN there.
    ``marker_errors_m`` (n_frames, n_markers_in_use) holds each weighted
    marker's distance error (m, NaN where missing), in the order of
    ``marker_names``. ``warning``: a poor fit's warning, set by the file step; ``warnings``: other warnings
    of the file step (a joint angle that looks inverted). ``geometry_change``: the median relative change of the
    distances between markers on one body against the static trial's, or the model's
    (:mod:`loper_analysis.motion.marker_geometry`;
    NaN when not compared). ``solver``: the solver that gave the coordinates (``tree`` or ``opensim``);
    ``fallback_reason``: why OpenSim's solver served when the tree's was asked for (the model's joint the tree
    does not hold, or its check against OpenSim failing; '' otherwise).
    """

    time_s: np.ndarray
    coordinates: np.ndarray
    coordinate_names: list[str]
    marker_rms_m: np.ndarray
    marker_max_m: np.ndarray
    undetermined: dict[str, int] = field(default_factory=dict)
    solved: np.ndarray | None = None
    marker_errors_m: np.ndarray | None = None
    marker_names: list[str] = field(default_factory=list)
    warning: str | None = None
    warnings: list[str] = field(default_factory=list)
    geometry_change: float = float("nan")
    solver: str = ""
    fallback_reason: str = ""

    @property
    def n_left_out(self) -> int:
        """Frames left out of the solve (too few markers)."""
        return 0 if self.solved is None else int((~self.solved).sum())

    def summary(self, warn_rms_m: float) -> pd.DataFrame:
        """One row: frames solved and left out, the solved span (s) and the marker RMS error (m).

        Columns :data:`IK_SUMMARY_COLUMNS`; ``n_frames_over_warn`` counts the
        frames whose marker RMS error exceeds ``warn_rms_m`` (m); ``worst_marker`` is the marker with the
        largest RMS error over the trial (``worst_marker_rms_m``; '' and NaN without marker errors),
        ``worst_markers_mm`` the three worst with their RMS error in mm, as text (``LTHI 28.0, RTHI 25.1, ...``);
        ``warnings`` joins :attr:`warning` and :attr:`warnings` ('' when none); ``solver`` is :attr:`solver`, with
        :attr:`fallback_reason` after a colon when there is one (``opensim: joint 'free' is a FreeJoint ...``).
        """
        solved = np.ones(self.time_s.size, bool) if self.solved is None else self.solved
        rms = self.marker_rms_m[np.isfinite(self.marker_rms_m)]
        t = self.time_s[solved]
        per_marker = self.marker_error_rms_m()
        worst = max(per_marker, key=per_marker.get) if per_marker else ""
        return pd.DataFrame(
            [
                {
                    "n_frames": int(self.time_s.size),
                    "n_frames_solved": int(solved.sum()),
                    "n_frames_left_out": int((~solved).sum()),
                    "first_solved_s": float(t[0]) if t.size else np.nan,
                    "last_solved_s": float(t[-1]) if t.size else np.nan,
                    "marker_rms_mean_m": float(rms.mean()) if rms.size else np.nan,
                    "marker_rms_max_m": float(rms.max()) if rms.size else np.nan,
                    "n_frames_over_warn": int((rms > warn_rms_m).sum()),
                    "worst_marker": worst,
                    "worst_marker_rms_m": per_marker[worst] if worst else np.nan,
                    "worst_markers_mm": ", ".join(f"{m} {1e3 * e:.1f}" for m, e in list(per_marker.items())[:3]),
                    "marker_geometry_change": self.geometry_change,
                    "warnings": " | ".join(w for w in [self.warning, *self.warnings] if w),
                    "solver": f"{self.solver}: {self.fallback_reason}" if self.fallback_reason else self.solver,
                }
            ],
            columns=list(IK_SUMMARY_COLUMNS),
        )

    def marker_error_rms_m(self) -> dict[str, float]:
        """Each weighted marker's RMS distance error over the frames it is present in (m), largest first."""
        if self.marker_errors_m is None or not len(self.marker_names):
            return {}
        E = np.asarray(self.marker_errors_m, float)
        out = {}
        for j, name in enumerate(self.marker_names):
            e = E[:, j][np.isfinite(E[:, j])]
            if e.size:
                out[name] = float(np.sqrt(np.mean(e**2)))
        return dict(sorted(out.items(), key=lambda kv: -kv[1]))

    def frame(self) -> pd.DataFrame:
        """Tidy-wide table: time_s plus one column per coordinate (rad or m)."""
        return pd.DataFrame(self.coordinates, columns=self.coordinate_names).assign(time_s=self.time_s)[
            ["time_s", *self.coordinate_names]
        ]


def marker_positions(model, coordinate_values: dict[str, np.ndarray], marker_names=None) -> np.ndarray:
    """Ground positions (n, n_markers, 3) in m of an ``opensim.Model``'s markers for coordinate trajectories (rad or m).

    ``coordinate_values`` maps coordinate names to trajectories of one common
    length n, or of length 1 (held for every frame); coordinates not given
    stay at their defaults, and each is set as OpenSim's ``Coordinate.setValue``
    sets it (a locked one left at its default, a clamped one as given, couplers
    not enforced). ``marker_names`` selects and orders the markers
    (default: every model marker, in model order).

    From :data:`TREE_MIN_FRAMES` frames on, the model's kinematic tree places the markers
    (:mod:`loper_analysis.motion.kinematic_tree`, checked against OpenSim first); OpenSim places them for
    fewer frames and for a model the tree does not hold.

    Raises
    ------
    LoperInputError
        An unknown coordinate or marker, or trajectories of unequal lengths.
    """
    from loper_analysis.motion.opensim_ik import opensim_marker_positions

    model.initSystem()
    cs = model.getCoordinateSet()
    names = [cs.get(i).getName() for i in range(cs.getSize())]
    unknown = [c for c in coordinate_values if c not in names]
    if unknown:
        raise LoperInputError(f"{model_source(model)}: unknown coordinate(s) {unknown}; has {names}")
    values = {c: np.atleast_1d(np.asarray(v, float)) for c, v in coordinate_values.items()}
    n = max((len(v) for v in values.values()), default=1)
    uneven = {c: len(v) for c, v in values.items() if len(v) not in (1, n)}
    if uneven:
        raise LoperInputError(f"coordinate trajectories must have length 1 or {n}, got {uneven}")
    ms = model.getMarkerSet()
    all_markers = [ms.get(i).getName() for i in range(ms.getSize())]
    wanted = list(all_markers if marker_names is None else marker_names)
    missing = [mk for mk in wanted if mk not in all_markers]
    if missing:
        raise LoperInputError(f"{model_source(model)}: marker(s) {missing} not in the model")
    tree = _checked_tree(model) if n >= TREE_MIN_FRAMES else None
    if tree is None:
        return opensim_marker_positions(model, values, wanted)
    order = [tree.marker_names.index(mk) for mk in wanted]
    return tree.positions(tree.poses(values, n))[:, order]


def _checked_tree(model):
    """The model's kinematic tree, checked against OpenSim's marker positions; None if the tree does not hold it."""
    from loper_analysis.motion.kinematic_tree import UnsupportedModel, check_against_opensim, kinematic_tree

    try:
        tree = kinematic_tree(model)
        check_against_opensim(model, tree)
    except UnsupportedModel:
        return None
    return tree


def require_model_markers(model, source: str = "") -> None:
    """Refuse a model without markers (an empty MarkerSet: the marker set kept in a file of its own), naming the
    model and where its markers come from."""
    if model.getMarkerSet().getSize():
        return
    where = f"{source}: " if source else ""
    raise LoperInputError(
        f"{where}{model_source(model)} has no markers (its MarkerSet is empty): IK and scaling fit the model's "
        "markers. Give the model with its marker set: the marker set file that came with it (OpenSim's "
        "gait2392_Scale_MarkerSet.xml beside gait2392_simbody.osim) is attached by the ScaleTool setup's "
        "<MarkerSet> (model.scale_setup), or `loper-analysis inspect STATIC WALK --config-out ...` writes a "
        "model with its markers"
    )


def inverse_kinematics(
    model,
    time_s,
    markers_m,
    labels,
    *,
    marker_weights: dict[str, float] | None = None,
    coordinate_tasks: dict[str, tuple[float, float | None]] | None = None,
    tree_step_tolerance: float = TREE_STEP_TOLERANCE,
    opensim_accuracy: float = OPENSIM_ACCURACY,
    min_markers: int = 3,
    source: str = "",
    undetermined: str = "nan",
    sparse_frames: str = "leave_out",
    solver: str = IK_SOLVER,
) -> IKResult:
    """IK of marker trajectories (m) on an ``opensim.Model``: OpenSim's objective, solved frame by frame.

    ``solver="tree"`` solves on the model's kinematic tree
    (:mod:`loper_analysis.motion.tree_ik`, checked against OpenSim's marker
    positions first); a model the tree does not reproduce (a constraint, a
    joint or function it does not hold) falls back on OpenSim's solver, and
    :attr:`IKResult.solver` says so. ``solver="opensim"`` uses OpenSim's
    ``InverseKinematicsSolver`` (:mod:`loper_analysis.motion.opensim_ik`).
    Each solver stops at its own tolerance: the tree's when its last step
    moved no coordinate by more than ``tree_step_tolerance`` (rad or m),
    OpenSim's at its unitless ``opensim_accuracy`` (also when it serves in
    the tree's place).

    A marker that is NaN in a frame is left out of that frame's solve (OpenSim's
    ``MarkersReference`` drops it). A frame holding fewer than ``min_markers``
    weighted markers, or weighted markers on the body jointed to the ground
    only (:func:`loper_analysis.motion.markers.frames_with_markers`), cannot be
    solved: with ``sparse_frames="leave_out"`` it is left out (every
    coordinate and error NaN, ``IKResult.solved`` False; a subject outside
    the capture volume at the start and end of an overground trial), with
    ``"error"`` the trial is refused
    (:func:`loper_analysis.motion.markers.require_markers_per_frame`). A trial
    without any frame to solve is refused either way, and so is one whose
    weighted markers all sit on the body jointed to the ground
    (:func:`loper_analysis.motion.ik_determinacy.require_markers_beyond_root`);
    ``source`` names the file in messages.

    A coordinate that no present weighted marker, coordinate task or model
    constraint determines in a frame
    (:func:`loper_analysis.motion.ik_determinacy.undetermined_coordinates`, e.g. the
    knee when no shank or foot marker is present) is NaN in that frame with
    ``undetermined="nan"`` (counted in :attr:`IKResult.undetermined`);
    ``undetermined="error"`` refuses the trial instead.

    Raises
    ------
    LoperInputError
        A weighted marker missing from the model or from the data, a
        coordinate task on an unknown coordinate, no model marker in the data,
        a frame with fewer than ``min_markers`` weighted markers present
        (``sparse_frames="error"``) or no frame with enough, weighted markers
        on the pelvis only, undetermined coordinates with
        ``undetermined="error"``; a model whose coordinates do not map onto
        the state (naming the .osim file and the coordinate).
    """
    labels = list(labels)
    t = np.asarray(time_s, float)
    if solver not in IK_SOLVERS:
        raise LoperInputError(f"solver must be one of {IK_SOLVERS}, got {solver!r}")
    if t.ndim != 1 or t.size < 1 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise LoperInputError("time_s must be finite and strictly increasing")
    X, kept_labels, marker_weights = _weighted_markers(model, labels, markers_m, marker_weights, source)
    if undetermined not in ("nan", "error"):
        raise LoperInputError(f"undetermined must be 'nan' or 'error', got {undetermined!r}")
    if sparse_frames not in ("leave_out", "error"):
        raise LoperInputError(f"sparse_frames must be 'leave_out' or 'error', got {sparse_frames!r}")
    tree, solved = _frames_to_solve(model, X, kept_labels, t, min_markers, source, sparse_frames)
    free = undetermined_coordinates(tree, X, kept_labels, coordinate_tasks)  # (n_frames, n_coordinates)
    free[~solved] = False  # frames left out are NaN throughout, not counted as undetermined
    lacking = {c: int(n) for c, n in zip(tree.coordinates, free.sum(axis=0)) if n}
    if lacking and undetermined == "error":
        raise LoperInputError(
            f"{source or 'markers'}: no weighted marker present determines coordinate(s) "
            + ", ".join(f"{c} ({n} of {t.size} frames)" for c, n in lacking.items())
        )
    frames = np.flatnonzero(solved)
    Q, E, in_use_names, used, reason = _solution(
        model,
        t,
        X,
        kept_labels,
        marker_weights,
        solver=solver,
        coordinate_tasks=coordinate_tasks,
        frames=frames,
        tree_step_tolerance=tree_step_tolerance,
        opensim_accuracy=opensim_accuracy,
        source=source,
    )
    # OpenSim reports 0 (not NaN) for a marker missing in a frame: leave those out of RMS and max
    in_use = [kept_labels.index(name) for name in in_use_names]
    E[np.isnan(X[:, in_use, :]).any(axis=2)] = np.nan
    with warnings.catch_warnings():  # a frame without any marker gives NaN, silently
        warnings.simplefilter("ignore", RuntimeWarning)
        rms, mx = np.sqrt(np.nanmean(E * E, axis=1)), np.nanmax(E, axis=1)
    coordinates = Q
    coordinates[free] = np.nan  # the solver left them at a default or the previous frame's value
    return IKResult(
        time_s=t,
        coordinates=coordinates,
        coordinate_names=[model.getCoordinateSet().get(i).getName() for i in range(Q.shape[1])],
        marker_rms_m=rms,
        marker_max_m=mx,
        undetermined=lacking,
        solved=solved,
        marker_errors_m=E,
        marker_names=in_use_names,
        solver=used,
        fallback_reason=reason,
    )


def _solution(
    model, t, X, labels, marker_weights, *, solver, tree_step_tolerance, opensim_accuracy, **options
) -> tuple[np.ndarray, np.ndarray, list[str], str, str]:
    """Coordinates (n_frames, n_coordinates) in coordinate-set order, marker errors (n_frames, n_in_use) in m,
    the markers in use, the solver that gave them (``tree`` or ``opensim``) and why OpenSim's served when the
    tree's was asked for ('' otherwise); each solver at its own tolerance, ``options`` (``coordinate_tasks``,
    ``frames``, ``source``) to both."""
    reason = ""
    if solver == "tree":
        from loper_analysis.motion.kinematic_tree import UnsupportedModel
        from loper_analysis.motion.tree_ik import tree_solution

        try:
            Q, E = tree_solution(
                model, t, X, labels, marker_weights, tree_step_tolerance=tree_step_tolerance, **options
            )
            return Q, E, list(labels), "tree", ""
        except UnsupportedModel as exc:
            reason = str(exc)
    from loper_analysis.motion.opensim_ik import opensim_solution

    return (
        *opensim_solution(model, t, X, labels, marker_weights, accuracy=opensim_accuracy, **options),
        "opensim",
        reason,
    )


def _weighted_markers(
    model, labels: list[str], markers_m, marker_weights: dict[str, float] | None, source: str
) -> tuple[np.ndarray, list[str], dict[str, float]]:
    """The trajectories (n_frames, n_weighted, 3) in m of the markers with a positive weight, their labels and
    the marker weights (None: every model marker in the data weighted 1).

    Raises LoperInputError for a model without markers, a weighted marker missing from the model or the data,
    or no model marker in the data."""
    where = f"{source}: " if source else ""
    ms = model.getMarkerSet()
    model_markers = [ms.get(i).getName() for i in range(ms.getSize())]
    require_model_markers(model, source)
    if marker_weights is None:
        marker_weights = {mk: 1.0 for mk in labels if mk in model_markers}
        if not marker_weights:
            raise LoperInputError(f"{where}none of the data's markers {labels[:8]}... is in {model_source(model)}")
    not_in_model = [mk for mk in marker_weights if mk not in model_markers]
    if not_in_model:
        raise LoperInputError(f"{where}marker(s) {not_in_model} of the IK tasks are not in {model_source(model)}")
    not_in_data = [mk for mk, w in marker_weights.items() if w > 0 and mk not in labels]
    if not_in_data:
        raise LoperInputError(f"marker(s) {not_in_data} of the IK tasks are not in the marker data")
    keep = [i for i, lab in enumerate(labels) if lab in marker_weights and marker_weights[lab] > 0]
    X = np.asarray(markers_m, float)[:, keep, :]
    kept_labels = [labels[i] for i in keep]
    return X, kept_labels, marker_weights


def _frames_to_solve(
    model, X: np.ndarray, kept_labels: list[str], t: np.ndarray, min_markers: int, source: str, sparse_frames: str
) -> tuple[ModelTree, np.ndarray]:
    """The model's tree (:func:`loper_analysis.motion.ik_determinacy.model_tree`) and which frames (n_frames,
    bool) hold enough weighted markers (``X``: n_frames, n_weighted, 3 in m) to solve.

    Raises LoperInputError for a sparse frame with ``sparse_frames="error"``, no frame to solve, or weighted
    markers on the body jointed to the ground only."""
    where = f"{source}: " if source else ""
    if sparse_frames == "error":
        require_markers_per_frame(X, kept_labels, min_markers, None, t, source)
    tree = model_tree(model)
    solved = frames_with_markers(
        X,
        kept_labels,
        min_markers,
        root_markers=[lab for lab in kept_labels if tree.marker_bodies.get(lab) in tree.root_bodies],
    )
    if not solved.any():
        require_markers_per_frame(X, kept_labels, min_markers, None, t, source)  # names the frames and markers
    require_markers_beyond_root(tree, X, kept_labels, source)
    if not solved.any():
        raise LoperInputError(
            f"{where}no frame holds {min_markers} weighted markers with one beyond the pelvis: "
            "nothing to solve (are the pelvis markers mapped in markers.label_map and weighted in "
            "the IK tasks?)"
        )
    return tree, solved


def ik_task_weights(
    model,
    labels: Sequence[str],
    tasks=None,
    default_weight: float = 1.0,
    marker_weights: Mapping[str, float] | None = None,
    coordinate_tasks: Mapping[str, Mapping] | None = None,
    source: str = "",
):
    """Marker weights and coordinate tasks of one trial.

    ``tasks`` is ``(marker_weights, coordinate_tasks)`` as read from an IK task
    file (:func:`loper_analysis.io.ik_tasks.read_ik_tasks`); without it every
    marker of ``model`` gets ``marker_weights.get(marker, default_weight)`` and
    ``coordinate_tasks`` (``{coordinate: {"weight": w, "value": rad or None}}``)
    are taken as given. A weighted model marker absent from the trial's
    ``labels`` is an error naming it and ``source`` (a model with more
    markers than the lab places, such as Rajagopal2016's full-body set:
    weight 0 in ``marker_weights`` or an IK task file naming the markers to
    track).

    Returns
    -------
    (dict, dict)
        ``{marker: weight}`` and ``{coordinate: (weight, value or None)}``.
    """
    require_model_markers(model, source)
    if tasks is not None:
        weights, coords = tasks
    else:
        ms = model.getMarkerSet()
        names = [ms.get(i).getName() for i in range(ms.getSize())]
        extra = sorted(set(marker_weights or {}) - set(names))
        if extra:
            raise LoperInputError(f"ik.marker_weights: marker(s) {extra} are not in {model_source(model)}")
        weights = {m: float((marker_weights or {}).get(m, default_weight)) for m in names}
        coords = {c: (float(v["weight"]), v.get("value")) for c, v in (coordinate_tasks or {}).items()}
    missing = [m for m, w in weights.items() if w > 0 and m not in labels]
    if missing:
        raise LoperInputError(
            f"{source}: marker(s) {missing} of the model's marker set are missing from the file "
            "(map the lab's labels to them in markers.label_map, or leave them out of IK: weight 0 "
            "in ik.marker_weights, or an IK task file in ik.ik_tasks)"
        )
    return weights, coords


def chunk_frames(n_frames: int, n_chunks: int, chunk: int) -> slice:
    """Frames of time chunk ``chunk`` (0-based) of ``n_chunks`` near-equal chunks of a trial of ``n_frames``.

    The chunks tile the trial without overlap. IK solves every frame on its
    own (the previous frame is only the starting guess), so chunks solved
    separately join seamlessly (:func:`join_chunks`; checked against one run
    in ``tests/motion/test_ik.py``).
    """
    if n_chunks < 1 or not 0 <= chunk < n_chunks:
        raise LoperInputError(f"chunk must lie in 0 .. {n_chunks - 1} (n_chunks = {n_chunks}), got {chunk}")
    if n_frames < n_chunks:
        raise LoperInputError(f"a trial of {n_frames} frames cannot be split into {n_chunks} chunks")
    edges = np.linspace(0, n_frames, n_chunks + 1).round().astype(int)
    return slice(int(edges[chunk]), int(edges[chunk + 1]))


def join_chunks(frames: list[pd.DataFrame], sources: list[str] | None = None) -> pd.DataFrame:
    """Concatenate IK chunks (``time_s`` + coordinates) in order; refuse gaps, overlaps or differing columns."""
    if not frames:
        raise LoperInputError("no IK chunk to join")
    sources = sources or [f"chunk {i}" for i in range(len(frames))]
    cols = list(frames[0].columns)
    for f, src in zip(frames[1:], sources[1:]):
        if list(f.columns) != cols:
            raise LoperInputError(f"{src}: columns {list(f.columns)} differ from {sources[0]}'s {cols}")
    for a, b, src in zip(frames[:-1], frames[1:], sources[1:]):
        if len(a) < 2 or len(b) < 1:
            raise LoperInputError(f"{src}: an IK chunk needs at least 2 frames")
        step = float(np.median(np.diff(a["time_s"].to_numpy())))
        gap = float(b["time_s"].iloc[0] - a["time_s"].iloc[-1])
        if not 0.5 * step < gap < 1.5 * step:
            raise LoperInputError(
                f"{src}: starts at t = {b['time_s'].iloc[0]:.6f} s, {gap:.6f} s after the previous chunk's last frame "
                f"(expected one frame, {step:.6f} s): chunks overlap or leave a gap"
            )
    return pd.concat(frames, ignore_index=True)


#: Our angle columns (the convention of :mod:`loper_analysis.constants`) -> (model coordinate, sign) for the generic
#: model.
#: ``pelvis_angle`` is the swing-leg model's theta_pelvis (= -pelvis_tilt of the OpenSim model).
DEFAULT_COORDINATE_MAP: dict[str, tuple[str, float]] = {
    "pelvis_x": ("pelvis_tx", 1.0),
    "pelvis_angle": ("pelvis_tilt", -1.0),
    "hip_left": ("hip_flexion_l", 1.0),
    "knee_left": ("knee_flexion_l", 1.0),
    "ankle_left": ("ankle_dorsiflexion_l", 1.0),
    "hip_right": ("hip_flexion_r", 1.0),
    "knee_right": ("knee_flexion_r", 1.0),
    "ankle_right": ("ankle_dorsiflexion_r", 1.0),
}
#: Column of each mapped quantity in the angle tables (SI unit in the name).
ANGLE_COLUMNS: dict[str, str] = {k: (f"{k}_m" if k == "pelvis_x" else f"{k}_rad") for k in DEFAULT_COORDINATE_MAP}


def joint_angle_table(coordinates: pd.DataFrame, coordinate_map: dict | None = None, source: str = "") -> pd.DataFrame:
    """Tidy table of our joint angles from model coordinates (rad, m).

    ``coordinates`` has ``time_s`` plus model coordinate columns (rad or m);
    ``coordinate_map`` maps each of :data:`ANGLE_COLUMNS`' keys to
    ``(coordinate, sign)`` or ``{"coordinate": name, "sign": ±1}`` (a user
    model such as gait2392: ``knee_left: [knee_angle_l, -1]``). Returns
    ``time_s`` plus one column per mapped quantity, flexion / dorsiflexion
    positive, pelvis angle as theta_pelvis of the swing-leg model.
    """
    cmap = DEFAULT_COORDINATE_MAP if coordinate_map is None else coordinate_map
    unknown = sorted(set(cmap) - set(ANGLE_COLUMNS))
    if unknown:
        raise LoperInputError(f"coordinate map: unknown key(s) {unknown}; known: {sorted(ANGLE_COLUMNS)}")
    out = {"time_s": coordinates["time_s"].to_numpy(float)}
    for key, column in ANGLE_COLUMNS.items():
        if key not in cmap:
            continue
        entry = cmap[key]
        name, sign = (entry["coordinate"], entry["sign"]) if isinstance(entry, dict) else entry
        if float(sign) not in (1.0, -1.0):
            raise LoperInputError(f"coordinate map, key {key}: sign must be 1 or -1, got {sign}")
        if name not in coordinates.columns:
            raise LoperInputError(
                f"{source or 'coordinates'}: coordinate '{name}' (coordinate map, key {key}) is not among "
                f"{[c for c in coordinates.columns if c != 'time_s']}"
            )
        out[column] = float(sign) * coordinates[name].to_numpy(float)
    return pd.DataFrame(out)
