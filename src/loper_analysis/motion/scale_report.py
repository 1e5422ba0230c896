"""How good a scaling is: the scale report, with the checks that tell a model built wrong from one built right.

Marker placement moves markers onto the static trial, so the marker errors after it are small by
construction and say nothing about the static pose the markers were placed in. A model whose generic
markers fit the subject badly is solved into a wrong static pose (a hip at -22 degrees, a
hyperextended knee), and placing the markers there builds that error into every joint angle of the
walking trials as an offset, while their IK marker error may even drop. The report therefore gives:

* the marker errors *before* placement (the static pose the marker placer solved, with the scaled
  generic markers) beside those after it;
* the static pose's joint angles in our convention (and the lab's own static angles where the file
  holds them);
* the scale factors of every body.

And it warns (rows of kind ``warning``) about a static pose whose hip, knee or ankle flexion lies beyond
:data:`MAX_STATIC_FLEXION_RAD`, a static pose more than :data:`MAX_STATIC_LAB_DIFF_RAD` from the lab's
own (each limit per joint, set by the spread of seven clinical labs), and a body whose scale factor
differs from a neighbour's (the body it is jointed to) by more than :data:`MAX_NEIGHBOUR_FACTOR_RATIO`,
each warning naming the setting to check.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, SIDES
from loper_analysis.motion.ik import IK_SOLVER, OPENSIM_ACCURACY, TREE_STEP_TOLERANCE
from loper_analysis.motion.model_settings import ModelSettings

__all__ = [
    "MAX_NEIGHBOUR_FACTOR_RATIO",
    "MAX_STATURE_CHANGE",
    "STOP_STATURE_CHANGE",
    "MAX_STATIC_FLEXION_RAD",
    "MAX_STATIC_LAB_DIFF_RAD",
    "SCALE_FLOAT_FORMAT",
    "SCALE_REPORT_COLUMNS",
    "StaticFit",
    "neighbour_factor_warnings",
    "joint_centre_rows",
    "jointed_bodies",
    "scale_report",
    "scale_run_report",
    "scaled_model_report",
    "static_fit",
    "static_pose_warnings",
    "stature_change",
    "stature_warnings",
]

#: Significant digits of the scale report.
SCALE_FLOAT_FORMAT = "%.8g"
#: A static pose's flexion beyond +- this per joint (rad) is warned about: a subject standing so is unusual, or the
#: calibration bends the pose. The seven clinical labs' own Plug-in Gait static poses span hip -1 to +36 degrees
#: (the hip's flexion includes the pelvis's tilt, 5 to 28 degrees; a child's is large), knee -11 to +19, ankle -4 to
#: +10; the limits lie 5 degrees beyond.
MAX_STATIC_FLEXION_RAD: dict[str, float] = {
    "hip": float(np.radians(40.0)),
    "knee": float(np.radians(25.0)),
    "ankle": float(np.radians(15.0)),
}
#: A static pose's joint angle further than this from the lab's own static angle (rad) is warned about. The joint-
#: centre calibration gives the seven clinical labs' static hip and knee within 1.9 degrees of their own (ankle within
#: 5.2: Plug-in Gait turns the ankle by the tibial torsion a lab enters); a calibration on the template's marker places
#: gave 6 to 17 degrees at hip and knee.
MAX_STATIC_LAB_DIFF_RAD: dict[str, float] = {
    "hip": float(np.radians(5.0)),
    "knee": float(np.radians(5.0)),
    "ankle": float(np.radians(10.0)),
}
#: Neighbouring bodies whose scale factors differ by more than this ratio are warned about (20 %).
MAX_NEIGHBOUR_FACTOR_RATIO: float = 1.2
#: A scaled model whose stature (estimated from its hip height) differs from the subject's given height by more
#: than this share is warned about (12 %: the estimate alone is off by up to 9 % on correct subjects) ...
MAX_STATURE_CHANGE: float = 0.12
#: ... and by more than this share refused (25 %: another subject's static trial, or a wrong height).
STOP_STATURE_CHANGE: float = 0.25
#: Columns of the scale report (:func:`scale_report`).
SCALE_REPORT_COLUMNS: tuple[str, ...] = (
    "kind",
    "name",
    "label",
    "scale_factor_x",
    "scale_factor_y",
    "scale_factor_z",
    "marker_weight",
    "marker_error_before_m",
    "marker_error_m",
    "marker_error_rms_m",
    "marker_error_max_m",
    "worst_marker",
    "angle_rad",
    "lab_angle_rad",
    "n_frames",
    "mass_kg",
    "height_m",
    "source",
)


@dataclass(frozen=True)
class StaticFit:
    """Marker errors of the static trial's mean pose on one model (m) and the pose's joint angles (rad).

    ``errors_m``: marker -> distance to the model's marker; ``angles_rad``: our angle (``hip_left``, ...)
    -> value, from the coordinate map.
    """

    errors_m: dict[str, float]
    angles_rad: dict[str, float]


def static_pose_warnings(
    angles_rad: Mapping[str, float],
    lab_angles_rad: Mapping[str, float] | None = None,
    setting: str = "model.scale_setup",
) -> list[tuple[str, str]]:
    """(name, warning) for each joint of a static pose beyond :data:`MAX_STATIC_FLEXION_RAD`, or further than
    :data:`MAX_STATIC_LAB_DIFF_RAD` from the lab's own static angle."""
    out = []
    for side in SIDES:
        for joint in JOINTS:
            key = f"{joint}_{side}"
            value = angles_rad.get(key)
            if value is None or not np.isfinite(value):
                continue
            limit = MAX_STATIC_FLEXION_RAD[joint]
            if abs(value) > limit:
                out.append(
                    (
                        f"static_pose_{key}",
                        f"static pose: {key} {np.degrees(value):+.1f} deg, beyond +-{np.degrees(limit):.0f} deg: the "
                        "subject did not stand upright, or the model does not fit the static trial (the joint "
                        f"centres' landmarks in markers.label_map, the marker set of {setting}); the offset goes "
                        "into every joint angle of the walking trials",
                    )
                )
            lab = (lab_angles_rad or {}).get(key)
            if lab is not None and np.isfinite(lab) and abs(value - lab) > MAX_STATIC_LAB_DIFF_RAD[joint]:
                out.append(
                    (
                        f"static_pose_{key}_lab",
                        f"static pose: {key} {np.degrees(value):+.1f} deg where the lab's own model gives "
                        f"{np.degrees(lab):+.1f} deg: an offset of {np.degrees(value - lab):+.1f} deg goes into every "
                        f"joint angle (beyond {np.degrees(MAX_STATIC_LAB_DIFF_RAD[joint]):.0f} deg; check the joint "
                        f"centres' landmarks in markers.label_map, the lab's stored widths and the marker set of "
                        f"{setting})",
                    )
                )
    return out


def neighbour_factor_warnings(
    factors: Mapping[str, Sequence[float]],
    neighbours: Sequence[tuple[str, str]],
    between_centres: Collection[str] = (),
) -> list[tuple[str, str]]:
    """(name, warning) for each pair of jointed bodies whose (mean) scale factors differ by more than
    :data:`MAX_NEIGHBOUR_FACTOR_RATIO`; bodies a measurement did not scale are skipped. Two bodies both scaled
    between joint centres (``between_centres``) differ in the subject's proportions, not by a marker placed
    elsewhere: the warning says so."""
    out = []
    for parent, child in neighbours:
        if parent not in factors or child not in factors:
            continue
        a, b = float(np.mean(factors[parent])), float(np.mean(factors[child]))
        if a > 0 and b > 0 and max(a, b) / min(a, b) > MAX_NEIGHBOUR_FACTOR_RATIO:
            said = (
                f"scale factors of neighbouring bodies differ by {100 * (max(a, b) / min(a, b) - 1):.0f} %: "
                f"{parent} {a:.3f}, {child} {b:.3f} (more than {100 * (MAX_NEIGHBOUR_FACTOR_RATIO - 1):.0f} %): "
            )
            if parent in between_centres and child in between_centres:
                said += (
                    "both between the static trial's joint centres: the subject's proportions are not the model's "
                    "(the model's masses and inertias follow each factor); if unexpected, check the leg lengths "
                    "and widths the static trial stores and the hip centre's method in this report"
                )
            else:
                said += (
                    "a marker of the measurement placed elsewhere on the subject than on the model? (the "
                    "measurements and marker set of model.scale_setup)"
                )
            out.append((f"scale_{parent}_{child}", said))
    return out


def stature_change(height_m: float, model_height_m: float) -> float:
    """The scaled model's stature (m) relative to the subject's given height (m), minus 1 (NaN when either is
    not finite)."""
    if not (np.isfinite(height_m) and np.isfinite(model_height_m)) or height_m <= 0:
        return float("nan")
    return float(model_height_m / height_m - 1.0)


def stature_warnings(height_m: float, model_height_m: float, height_source: str) -> list[tuple[str, str]]:
    """(name, warning) when the scaled model's stature differs from the given height by more than
    :data:`MAX_STATURE_CHANGE`."""
    change = stature_change(height_m, model_height_m)
    if not np.isfinite(change) or abs(change) <= MAX_STATURE_CHANGE:
        return []
    return [
        (
            "stature",
            f"the scaled model stands {model_height_m:.2f} m tall where the subject's height is {height_m:.2f} m "
            f"({height_source}; {100 * change:+.0f} %, more than {100 * MAX_STATURE_CHANGE:.0f} %): is the static "
            "trial this subject's, and the height in the subject sheet (height_m) right?",
        )
    ]


def scale_report(
    bodies: Sequence[str],
    factors: Mapping[str, Sequence[float]],
    weights: Mapping[str, float],
    after: StaticFit,
    before: StaticFit | None,
    n_frames: int,
    subject: tuple[float, float, str],
    *,
    lab_labels: Mapping[str, str] | None = None,
    lab_angles_rad: Mapping[str, float] | None = None,
    warnings: Sequence[tuple[str, str]] = (),
) -> pd.DataFrame:
    """The scale report: one row per body, marker, angle of the static pose and warning, and for the subject.

    Parameters
    ----------
    bodies : sequence of str
        The scaled model's bodies.
    factors : mapping
        Body -> (x, y, z) factors OpenSim's model scaler applied (1 where it scaled nothing).
    weights : mapping
        Weighted marker -> weight.
    after : StaticFit
        The static mean pose on the final model (after marker placement).
    before : StaticFit or None
        The same on the scaled model before placement (the pose the marker placer solved); None without
        placement.
    n_frames : int
        Frames averaged into the static pose.
    subject : (float, float, str)
        Mass (kg), height (m) and where they came from.
    lab_labels : mapping, optional
        Model marker -> the lab's label.
    lab_angles_rad : mapping, optional
        Our angle -> the lab's own static angle (rad).
    warnings : sequence of (str, str)
        (name, text) rows of kind ``warning``.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`SCALE_REPORT_COLUMNS`. Rows (``kind``): ``subject``; ``body``; ``marker``
        (``marker_error_before_m`` and ``marker_error_m``); ``markers`` (``before placement`` and ``after
        placement``, or ``after scaling`` alone without placement: RMS, largest, worst marker); ``pose``
        (``angle_rad`` of the static pose the markers were placed in, ``lab_angle_rad``); ``warning``
        (``source`` holds the text).
    """
    mass_kg, height_m, source = subject
    rows = [{"kind": "subject", "name": "subject", "mass_kg": mass_kg, "height_m": height_m, "source": source}]
    for name in bodies:
        fx, fy, fz = factors.get(name, (1.0, 1.0, 1.0))
        rows.append({"kind": "body", "name": name, "scale_factor_x": fx, "scale_factor_y": fy, "scale_factor_z": fz})
    for name, error in after.errors_m.items():
        rows.append(
            {
                "kind": "marker",
                "name": name,
                "label": (lab_labels or {}).get(name, name),
                "marker_weight": weights.get(name, np.nan),
                "marker_error_before_m": np.nan if before is None else before.errors_m.get(name, np.nan),
                "marker_error_m": error,
            }
        )
    final = "after scaling" if before is None else "after placement"  # no marker placement: only scaled
    for stage, fit in (("before placement", before), (final, after)):
        if fit is None or not fit.errors_m:
            continue
        e = np.array(list(fit.errors_m.values()))
        rows.append(
            {
                "kind": "markers",
                "name": stage,
                "marker_error_rms_m": float(np.sqrt(np.mean(e**2))),
                "marker_error_max_m": float(e.max()),
                "worst_marker": max(fit.errors_m, key=fit.errors_m.get),
                "n_frames": n_frames,
            }
        )
    pose = (before or after).angles_rad
    for key, value in pose.items():
        lab = (lab_angles_rad or {}).get(key, np.nan)
        rows.append({"kind": "pose", "name": key, "angle_rad": value, "lab_angle_rad": lab})
    rows += [{"kind": "warning", "name": name, "source": text} for name, text in warnings]
    return pd.DataFrame(rows, columns=list(SCALE_REPORT_COLUMNS))


def _names(object_set) -> list[str]:
    return [object_set.get(i).getName() for i in range(object_set.getSize())]


def _map_coordinate(entry) -> str:
    return entry["coordinate"] if isinstance(entry, Mapping) else entry[0]


def static_fit(
    model,
    pose,
    weights,
    coords,
    coordinate_map,
    *,
    tree_step_tolerance: float = TREE_STEP_TOLERANCE,
    opensim_accuracy: float = OPENSIM_ACCURACY,
    solver: str = IK_SOLVER,
) -> StaticFit:
    """Marker errors of the static trial's mean pose on ``model`` and the pose's joint angles: IK with the
    marker placer's weights and tasks of the window's mean, as OpenSim's marker placer takes it.

    Parameters
    ----------
    model : opensim.Model
    pose : loper_analysis.motion.static_trial.StaticPose
        The scaling window (its markers complete: missing frames hold the marker's mean).
    weights, coords : dict
        Marker -> weight; coordinate -> (weight, value or None).
    coordinate_map : mapping
        Our angle -> model coordinate and sign; angles whose coordinate the model lacks are left out.
    tree_step_tolerance, opensim_accuracy : float
        The tree solver's step tolerance (rad or m) and OpenSim's solver's unitless accuracy.
    solver : str
        IK solver (:func:`loper_analysis.motion.ik.inverse_kinematics`).
    """
    from loper_analysis.motion.ik import inverse_kinematics, joint_angle_table

    mean_pose = pose.markers_m.mean(axis=0, keepdims=True)
    result = inverse_kinematics(
        model,
        pose.time_s[:1],
        mean_pose,
        pose.labels,
        marker_weights=weights,
        coordinate_tasks=coords,
        tree_step_tolerance=tree_step_tolerance,
        opensim_accuracy=opensim_accuracy,
        solver=solver,
    )
    errors = dict(zip(result.marker_names, (float(e) for e in result.marker_errors_m[0])))
    frame = result.frame()
    known = {k: v for k, v in coordinate_map.items() if _map_coordinate(v) in frame.columns}
    angles = joint_angle_table(frame, known).drop(columns="time_s").iloc[0] if known else pd.Series(dtype=float)
    return StaticFit(errors, {k.removesuffix("_rad"): float(v) for k, v in angles.items() if k.endswith("_rad")})


def jointed_bodies(model) -> list[tuple[str, str]]:
    """(parent body, child body) of every joint between two bodies of an ``opensim.Model``."""
    joints = model.getJointSet()
    bodies = set(_names(model.getBodySet()))
    out = []
    for i in range(joints.getSize()):
        j = joints.get(i)
        parent = j.getParentFrame().findBaseFrame().getName()
        child = j.getChildFrame().findBaseFrame().getName()
        if parent in bodies and child in bodies:
            out.append((parent, child))
    return out


def scaled_model_report(
    scaled,
    unplaced,
    pose,
    scaling: tuple[Mapping[str, Sequence[float]], tuple | None],
    subject: tuple[float, float, str],
    *,
    coordinate_map: Mapping | None = None,
    tree_step_tolerance: float = TREE_STEP_TOLERANCE,
    opensim_accuracy: float = OPENSIM_ACCURACY,
    solver: str = IK_SOLVER,
    lab_labels: Mapping[str, str] | None = None,
    lab_static: Mapping[str, float] | None = None,
    model_height_m: float = float("nan"),
    between_centres: Collection[str] = (),
) -> pd.DataFrame:
    """The scale report (:func:`scale_report`) of a scaled model, with its checks.

    Parameters
    ----------
    scaled : opensim.Model
        The final model (after marker placement).
    unplaced : opensim.Model or None
        The scaled model before marker placement (None: no placement).
    pose : loper_analysis.motion.static_trial.StaticPose
        The scaling window.
    scaling : (dict, tuple or None)
        Body -> factors OpenSim applied; the marker placer's (marker weights, coordinate tasks), None when it
        does not apply (every marker of the window then weighs 1).
    subject : (float, float, str)
        Mass (kg), height (m), where they came from.
    coordinate_map : mapping, optional
        ``ik.coordinate_map``; None: :data:`loper_analysis.motion.ik.DEFAULT_COORDINATE_MAP`.
    tree_step_tolerance, opensim_accuracy : float
        The static pose's IK tolerances: the tree solver's step (rad or m, ``ik.tree_step_tolerance``) and
        OpenSim's solver's unitless accuracy (``ik.opensim_accuracy``).
    solver : str
        IK solver of the static pose (``ik.ik_solver``).
    lab_labels, lab_static : mapping, optional
        Model marker -> the lab's label; our angle -> the lab's own static angle (rad).
    model_height_m : float
        The scaled model's stature (m; :func:`loper_analysis.motion.body_size.model_height_m`), compared with
        the subject's height (:func:`stature_warnings`); NaN: not compared.
    between_centres : collection of str
        The bodies scaled between joint centres (:func:`neighbour_factor_warnings`).

    Returns
    -------
    pandas.DataFrame
        :func:`scale_report`'s table, with the warnings of :func:`static_pose_warnings`,
        :func:`neighbour_factor_warnings` and :func:`stature_warnings` as rows (and logged by the caller).
    """
    from loper_analysis.motion.ik import DEFAULT_COORDINATE_MAP

    factors, tasks = scaling
    model_markers = set(_names(scaled.getMarkerSet()))
    weights, coords = tasks if tasks is not None else ({m: 1.0 for m in pose.labels if m in model_markers}, {})
    weights = {m: w for m, w in weights.items() if w > 0 and m in model_markers and m in pose.labels}
    cmap = DEFAULT_COORDINATE_MAP if coordinate_map is None else coordinate_map
    ik = {"tree_step_tolerance": tree_step_tolerance, "opensim_accuracy": opensim_accuracy, "solver": solver}
    after = static_fit(scaled, pose, weights, coords, cmap, **ik)
    before = None if unplaced is None else static_fit(unplaced, pose, weights, coords, cmap, **ik)
    scaled_factors = {b: f for b, f in factors.items() if not np.allclose(f, 1.0)}
    warnings = static_pose_warnings((before or after).angles_rad, lab_static)
    warnings += neighbour_factor_warnings(scaled_factors, jointed_bodies(scaled), between_centres)
    warnings += stature_warnings(subject[1], model_height_m, subject[2])
    return scale_report(
        _names(scaled.getBodySet()),
        factors,
        weights,
        after,
        before,
        len(pose.time_s),
        subject,
        lab_labels=lab_labels,
        lab_angles_rad=lab_static,
        warnings=warnings,
    )


def joint_centre_rows(report: pd.DataFrame, methods: Mapping[str, str]) -> pd.DataFrame:
    """The scale report with a row of kind ``joint_centre`` per joint centre of the calibration, ``source`` saying
    how the static trial's centre was found (:func:`loper_analysis.motion.joint_centres.static_joint_centres`),
    before the warnings."""
    if not methods:
        return report
    rows = pd.DataFrame(
        [{"kind": "joint_centre", "name": name, "source": how} for name, how in methods.items()],
        columns=list(SCALE_REPORT_COLUMNS),
    )
    warnings = report["kind"] == "warning"
    return pd.concat([report[~warnings], rows, report[warnings]], ignore_index=True)


def scale_run_report(
    run,
    generic,
    pose,
    subject: tuple[float, float, str, float],
    settings: ModelSettings,
    *,
    lab_labels: Mapping[str, str] | None = None,
    lab_angles: pd.DataFrame | None = None,
    between_centres: Collection[str] = (),
) -> pd.DataFrame:
    """The scale report (:func:`scaled_model_report`) of one run of OpenSim's ScaleTool.

    Parameters
    ----------
    run : loper_analysis.io.scale_tool.ScaleToolRun
        What the tool wrote: the final model, the model before marker placement, the scale factors, the marker
        placer's tasks and the window (s).
    generic : opensim.Model
        The generic model: the markers placed when the placer ran without scaling.
    pose : loper_analysis.motion.static_trial.StaticPose
        The scaling window.
    subject : (float, float, str, float)
        Mass (kg), height (m), where they came from, the model's stature (m)
        (:func:`loper_analysis.motion.scaling.scaled_subject`).
    settings : ModelSettings
        ``coordinate_map``, ``tree_step_tolerance``, ``opensim_accuracy`` and ``solver`` of the static pose's
        IK.
    lab_labels : mapping, optional
        Model marker -> the lab's label.
    lab_angles : pandas.DataFrame, optional
        The lab's own joint angles of the static trial (``time_s`` and ``*_rad`` columns), averaged over the
        run's window (:func:`loper_analysis.motion.lab_angles.window_means`).
    between_centres : collection of str
        The bodies scaled between joint centres (:func:`neighbour_factor_warnings`).

    Returns
    -------
    pandas.DataFrame
        :func:`scaled_model_report`'s table, its warnings as rows of kind ``warning``.
    """
    from loper_analysis.motion.lab_angles import window_means

    unplaced = run.unplaced
    if unplaced is None and run.tasks is not None:
        unplaced = generic  # placement without scaling: the generic markers are the ones placed
    lab_static = None if lab_angles is None else window_means(lab_angles, run.window_s)
    return scaled_model_report(
        run.scaled,
        unplaced,
        pose,
        (run.factors, run.tasks),
        subject[:3],
        coordinate_map=settings.coordinate_map,
        tree_step_tolerance=settings.tree_step_tolerance,
        opensim_accuracy=settings.opensim_accuracy,
        solver=settings.solver,
        lab_labels=lab_labels,
        lab_static=lab_static,
        model_height_m=subject[3],
        between_centres=between_centres,
    )
