"""One scaling of a generic OpenSim model to a static trial, on arrays and OpenSim objects.

What surrounds OpenSim's ScaleTool (:func:`loper_analysis.io.scale_tool.run_scale_tool`): the scaling window
and the static pose averaged over it, checked against the tool's measurements (:func:`scaling_pose`), the
subject's mass (:func:`scaling_mass_kg`), and the checks of the model the tool wrote with the subject's height
(:func:`scaled_subject`). :func:`generated_scale_tool` is the tool of the generated model
(:mod:`loper_analysis.motion.model`); the report of a run is
:func:`loper_analysis.motion.scale_report.scale_run_report`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from loper_analysis.errors import LoperInputError
from loper_analysis.io import scale_tool
from loper_analysis.motion.body_size import body_height_m, body_mass_kg, model_stature_m, require_stature
from loper_analysis.motion.marker_names import unknown_markers_hint
from loper_analysis.motion.markers import lab_up
from loper_analysis.motion.model_settings import ModelSettings
from loper_analysis.motion.plausibility import measurement_scale_factors, require_scale_factors
from loper_analysis.motion.static_trial import (
    StaticPose,
    log_static_pose,
    scale_window_s,
    static_pose,
    time_range_is_set,
)

__all__ = [
    "ScalingPose",
    "generated_scale_tool",
    "scaled_subject",
    "scaling_mass_kg",
    "scaling_pose",
    "with_joint_centres",
]


def generated_scale_tool():
    """An ``opensim.ScaleTool`` for the generated model: each body scaled uniformly by the ratio of its marker-pair
    distances (:data:`loper_analysis.motion.model.SCALE_MEASUREMENTS`), mass distribution preserved, no marker
    placement."""
    from loper_analysis.motion.marker_templates import measured_scale_tool
    from loper_analysis.motion.model import SCALE_MEASUREMENTS

    tool = measured_scale_tool({body: (pairs, [body]) for body, pairs in SCALE_MEASUREMENTS.items()})
    tool.getMarkerPlacer().setApply(False)
    return tool


def with_joint_centres(
    markers: tuple[np.ndarray, np.ndarray, Sequence[str]],
    spec,
    widths_m: Mapping[str, float],
    *,
    static_trc: str,
) -> tuple[tuple[np.ndarray, np.ndarray, list[str]], dict[str, str]]:
    """The static trial with its joint centres appended as markers, and how each was found.

    Parameters
    ----------
    markers : (ndarray, ndarray, list of str)
        The static trial: times (s), shape (n,); marker positions (m), shape (n, n_markers, 3); labels.
    spec : loper_analysis.motion.marker_templates.JointCentreSpec
        The centres the model's marker set holds and the landmarks they come from.
    widths_m : mapping
        The lab's knee and ankle widths and marker diameter, m
        (:func:`loper_analysis.motion.joint_centres.widths_from_processing`).
    static_trc : str
        The static trial's file, in messages.

    Raises
    ------
    LoperInputError
        A landmark the centres need is missing (:func:`loper_analysis.motion.joint_centres.static_joint_centres`).
    """
    from loper_analysis.motion.joint_centres import static_joint_centres

    times, X, labels = markers
    centres = static_joint_centres(labels, X, spec.landmarks, widths_m, source=static_trc)
    keep = [i for i, n in enumerate(centres.names) if n in spec.names and n not in labels]
    names = [*labels, *(centres.names[i] for i in keep)]
    X = np.concatenate([X, centres.markers_m[:, keep]], axis=1)
    return (times, X, names), {centres.names[i]: centres.methods[centres.names[i]] for i in keep}


@dataclass(frozen=True)
class ScalingPose:
    """The scaling window of a static trial and its pose (:func:`scaling_pose`).

    Attributes
    ----------
    window_s : (float, float)
        The scaling window (s).
    ranges : dict
        The model scaler's and marker placer's own time ranges (s) where they apply, keyed by the tool's parts;
        None where unset, or all None when ``settings.time_range_s`` overrides them.
    pose : StaticPose
        The window's frames, each marker's missing frames holding its mean over the present ones.
    """

    window_s: tuple[float, float]
    ranges: dict
    pose: StaticPose


def scaling_pose(
    tool,
    generic,
    markers: tuple[np.ndarray, np.ndarray, Sequence[str]],
    settings: ModelSettings,
    *,
    static_trc: str,
    setup_xml: str | None = None,
    lab_labels: Mapping[str, str] | None = None,
) -> ScalingPose:
    """The static trial's scaling window, the tool's own time ranges and the averaged pose, each checked; the
    measurements' scale factors must lie in ``settings.factor_range``.

    The window (:func:`loper_analysis.motion.static_trial.scale_window_s`) is ``settings.time_range_s`` when
    given, else the tool's time ranges where they are set, else the ``settings.static_duration_s`` seconds where
    the measurement markers move least (:func:`loper_analysis.motion.still_window.stillest_window_s`; None: the
    whole trial). Within it each marker counts where it is present
    (:func:`loper_analysis.motion.static_trial.static_pose`, at most ``settings.max_motion_rms_m`` of motion).

    Parameters
    ----------
    tool : opensim.ScaleTool
        Its measurements' marker pairs and its parts' time ranges.
    generic : opensim.Model
        The generic model (with the setup's markers): its measurement distances and marker names.
    markers : (ndarray, ndarray, list of str)
        The static trial: times (s), shape (n,); marker positions (m), shape (n, n_markers, 3); labels.
    settings : ModelSettings
        ``time_range_s``, ``static_duration_s``, ``max_motion_rms_m`` and ``factor_range``.
    static_trc : str
        The static trial's file, in messages.
    setup_xml : str, optional
        The tool's setup file, in messages (None: a tool built for the generated model).
    lab_labels : mapping, optional
        {model marker: lab label}, for messages.

    Raises
    ------
    LoperInputError
        A time range outside the trial or reversed; measurement markers the static trial lacks (all listed); a
        measurement marker absent from every frame of the window; too much motion; a scale factor outside
        ``settings.factor_range``.
    """
    times, X, labels = markers
    time_range_s = settings.time_range_s
    where = str(setup_xml) if setup_xml is not None else str(static_trc)
    scaler, placer = tool.getModelScaler(), tool.getMarkerPlacer()
    ranges = {part: scale_tool.time_range(part) for part in (scaler, placer) if part.getApply()}
    ranges = {part: r if time_range_is_set(r) else None for part, r in ranges.items()}  # None where unset
    setting = f"time_range of {setup_xml}" if setup_xml is not None else "model.static_duration_s"
    pairs = scale_tool.measurement_pairs(tool)
    needed = sorted({m for p in pairs.values() for pair in p for m in pair})
    if time_range_s is not None:
        t0, t1 = map(float, time_range_s)
        if not (t0 <= t1 and t0 <= times[-1] + 1e-9 and t1 >= times[0] - 1e-9):
            raise LoperInputError(
                f"{static_trc}: time_range_s {time_range_s} lies outside the trial "
                f"({times[0]:.3f} .. {times[-1]:.3f} s) or is reversed"
            )
        window = scale_window_s(times, [(t0, t1)], source=str(static_trc), setting="the time range given")
        ranges = dict.fromkeys(ranges)
    else:
        window = scale_window_s(
            times,
            list(ranges.values()),
            settings.static_duration_s,
            source=str(static_trc),
            setting=setting,
            markers_m=X,
            labels=labels,
            needed=needed,
            max_motion_rms_m=settings.max_motion_rms_m,
            lab_labels=lab_labels,
        )
    lacking = [m for m in needed if m not in labels]
    if lacking:
        raise LoperInputError(
            f"{where}: measurement marker(s) {lacking} are not in the static trial {static_trc}"
            f"{unknown_markers_hint(labels, scale_tool.object_names(generic.getMarkerSet()), lab_labels)}"
        )
    pose = static_pose(
        times,
        X,
        labels,
        window_s=window,
        needed=needed,
        lab_labels=lab_labels,
        source=str(static_trc),
        setting=setting,
        max_motion_rms_m=settings.max_motion_rms_m,
    )
    log_static_pose(pose, str(static_trc), window)
    factors = measurement_scale_factors(generic, pairs, pose.markers_m, pose.labels)
    require_scale_factors(factors, str(static_trc), settings.factor_range)
    return ScalingPose(window, ranges, pose)


def scaling_mass_kg(
    generic, mass_kg: float | None, recording, plates, window: tuple[float, float], settings: ModelSettings
) -> tuple[float, str]:
    """The subject's mass (kg) and where it came from: ``mass_kg`` when given, else the force plates of the
    static trial's ``recording`` over ``window`` (s), seen along the vertical of ``settings.rotation_deg``
    with the generic model's gravity (:func:`loper_analysis.motion.body_size.body_mass_kg`)."""
    gravity = float(np.linalg.norm(generic.getGravity().to_numpy()))
    return body_mass_kg(mass_kg, recording, plates, window, lab_up(settings.rotation_deg), gravity)


def scaled_subject(
    scaled,
    mass: tuple[float, str],
    settings: ModelSettings,
    height_m: float | None,
    stored: tuple[Mapping[str, float], str],
    *,
    model_source: str,
    static_trc: str,
) -> tuple[float, float, str, float]:
    """The subject of a scaled model, checked: the configured bodies exist
    (:func:`loper_analysis.motion.segments.check_segment_bodies`) and the model's stature fits the height.

    Parameters
    ----------
    scaled : opensim.Model
        The model ScaleTool wrote.
    mass : (float, str)
        The subject's mass (kg) and where it came from (:func:`scaling_mass_kg`).
    settings : ModelSettings
        ``segment_bodies``: the bodies the model must have, whose hip height gives its stature.
    height_m : float, optional
        The subject's height (m); None: the static trial's stored height, else the model's stature.
    stored : (mapping, str)
        The static trial's ``PROCESSING`` values (Nexus: ``Height`` mm) and its file name; empty without one.
    model_source, static_trc : str
        The scaled model and the static trial, in messages.

    Returns
    -------
    (float, float, str, float)
        Mass (kg), height (m), where they came from, the model's stature (m).

    Raises
    ------
    LoperInputError
        A configured body missing; a stature too far from the height
        (:func:`loper_analysis.motion.body_size.require_stature`).
    """
    from loper_analysis.motion.segments import check_segment_bodies

    segment_bodies = settings.segment_bodies
    check_segment_bodies(scaled, segment_bodies, source=model_source)
    stature = model_stature_m(scaled, segment_bodies)
    height = body_height_m(height_m, stored[0], stature, stored[1])
    require_stature(height, stature, static_trc)
    return mass[0], height[0], f"mass: {mass[1]}; height: {height[1]}", stature
