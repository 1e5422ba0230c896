"""Marker-set templates: a lab's usual marker set placed on a model OpenSim distributes, with everything
scaling and inverse kinematics need.

A template (``src/loper_analysis/templates/*.yaml``, read by :mod:`loper_analysis.io.marker_templates`)
gives, for one marker set on one model:

* each marker's body and location in the body's frame (m; right side, the left mirrored) and its role
  (*anatomical*: a bony landmark; *technical*: wands, clusters, trunk), which sets its weight;
* the subject calibration through joint centres (``joint_centres``): virtual markers at the model's hip, knee
  and ankle centres and a direction marker for the pelvis and each foot
  (:func:`~loper_analysis.motion.centre_markers.joint_centre_places`), matched to
  the centres the static trial's markers give (:mod:`loper_analysis.motion.joint_centres`);
* the measurements that scale each body (marker pairs: between joint centres where the static trial gives them),
  the marker weights of each role, the coordinates held by tasks (subtalar and mtp), the heel markers that assign
  force-plate contacts to feet, the coordinates of our joint angles and the marker groups a file must hold for the
  template to fit.

From a template and a subject's labels this module builds the OpenSim objects: the marker set of the
markers present (:func:`template_marker_set`), a ScaleTool whose measurements use the pairs present and
whose marker placer weights the markers present (:func:`template_scale_tool`), the IK tasks of the
walking trials' markers (:func:`template_ik_tasks`) and the coordinate map with the signs the model's
kinematics need (:func:`template_coordinate_map`). :func:`template_fit` tells how well a file's labels
fit a template.

Why joint centres: the template's places of the anatomical markers are gait2392's, not the subject's. A static
pose fitted to them bends the joints to reconcile the two (a knee flexed by 10 degrees more than the lab's own
Plug-in Gait gives), and moving the markers onto the static trial afterwards builds that bend into every walking
angle. Fitted through the centres instead (segment lengths from the distances between centres, the pose from the
centres and the two direction markers), the static pose is the subject's, and every marker, anatomical ones
included, is then moved to where the static trial has it. Without the centres' landmarks the static pose is fitted
to the template's places, anatomical markers kept there.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import pandas as pd

from loper_analysis.constants import SIDE_SUFFIX, SIDES
from loper_analysis.errors import LoperInputError
from loper_analysis.motion.centre_markers import (
    JointCentreSpec,
    calibration_centres,
    centre_names,
    joint_centre_places,
    joint_centre_spec,
)
from loper_analysis.motion.label_matching import LabelMatch, match_labels

__all__ = [
    "ROLES",
    "MarkerTemplate",
    "TemplateFit",
    "TemplateMarker",
    "derived_markers",
    "measured_scale_tool",
    "scale_measurement",
    "template_coordinate_map",
    "template_fit",
    "template_from_spec",
    "template_ik_tasks",
    "template_marker_set",
    "template_scale_tool",
]

#: Roles of a template marker.
ROLES: tuple[str, ...] = ("anatomical", "technical")


@dataclass(frozen=True)
class TemplateMarker:
    """One marker of a template: its name (the lab's label), the model body, its location in the body's frame (m)
    and its role (:data:`ROLES`)."""

    name: str
    body: str
    location_m: tuple[float, float, float]
    role: str


@dataclass(frozen=True)
class MarkerTemplate:
    """A marker set on a model (see the module's text).

    Attributes
    ----------
    name, title : str
        Short name (the file's stem) and a line describing it.
    model : str
        File name of the model, in the templates' folder.
    markers : tuple of TemplateMarker
        Both sides and the midline.
    side_prefix : dict
        ``{"left": "L", "right": "R"}``: how a sided marker's name starts.
    measurements : dict
        Name -> (marker pairs, bodies scaled).
    weights : dict
        Role -> marker weight (the marker placer and IK).
    coordinate_tasks : dict
        Coordinate -> value (rad) held by a task in the static pose and in walking.
    required : tuple of tuple of str
        Groups of markers; a file fits when it holds one marker of every group.
    foot_markers : dict
        Side -> heel marker.
    coordinates : dict
        Our angle (``pelvis_x``, ``pelvis_angle``, ``hip``, ``knee``, ``ankle``) -> model coordinate (``{s}``:
        side suffix).
    fallback_measurement : dict
        Measurement -> the measurement whose factor it takes when none of its pairs is present.
    joint_centres : JointCentreSpec, optional
        The subject calibration through joint centres; None: the static pose is fitted with the markers at the
        template's places, anatomical ones kept there.
    """

    name: str
    title: str
    model: str
    markers: tuple[TemplateMarker, ...]
    side_prefix: dict[str, str]
    measurements: dict[str, tuple[tuple[tuple[str, str], ...], tuple[str, ...]]]
    weights: dict[str, float]
    coordinate_tasks: dict[str, float]
    required: tuple[tuple[str, ...], ...]
    foot_markers: dict[str, str]
    coordinates: dict[str, str]
    fallback_measurement: dict[str, str]
    joint_centres: JointCentreSpec | None = None

    @property
    def marker_names(self) -> list[str]:
        """The template's marker names, in order."""
        return [m.name for m in self.markers]

    def locations(self) -> dict[str, tuple[str, tuple[float, float, float]]]:
        """Every marker: name -> (body, location in the body's frame, m)."""
        return {m.name: (m.body, tuple(m.location_m)) for m in self.markers}

    def marker(self, name: str) -> TemplateMarker:
        """The template marker of that name."""
        return next(m for m in self.markers if m.name == name)


def _location(values, where: str) -> tuple[str, tuple[float, float, float], str]:
    if not isinstance(values, Sequence) or len(values) != 5:
        raise LoperInputError(f"{where}: expected [body, x, y, z, role], got {values!r}")
    body, x, y, z, role = values
    if role not in ROLES:
        raise LoperInputError(f"{where}: role must be one of {ROLES}, got {role!r}")
    return str(body), (float(x), float(y), float(z)), str(role)


def template_from_spec(name: str, spec: Mapping, source: str) -> MarkerTemplate:
    """A :class:`MarkerTemplate` from its YAML mapping: sided markers expanded to both sides (the left mirrors Z).

    Raises
    ------
    LoperInputError
        A missing key, a marker entry that is not ``[body, x, y, z, role]``, a measurement, required group or
        heel marker naming a marker the template lacks (naming ``source`` and the key).
    """
    try:
        prefix = {side: str(spec["side_prefix"][side]) for side in SIDES}
        markers = []
        for code, values in spec["markers"].items():
            body, (x, y, z), role = _location(values, f"{source}: markers.{code}")
            for side in SIDES:
                mirror = 1.0 if side == "right" else -1.0
                markers.append(
                    TemplateMarker(prefix[side] + code, body.format(s=SIDE_SUFFIX[side]), (x, y, mirror * z), role)
                )
        for code, values in (spec.get("midline_markers") or {}).items():
            body, xyz, role = _location(values, f"{source}: midline_markers.{code}")
            markers.append(TemplateMarker(str(code), body, xyz, role))
        measurements = {
            str(m): (tuple((str(a), str(b)) for a, b in entry["pairs"]), tuple(str(b) for b in entry["bodies"]))
            for m, entry in spec["measurements"].items()
        }
        template = MarkerTemplate(
            name=name,
            title=str(spec["title"]),
            model=str(spec["model"]),
            markers=tuple(markers),
            side_prefix=prefix,
            measurements=measurements,
            weights={role: float(spec["weights"][role]) for role in ROLES},
            coordinate_tasks={str(c): float(v) for c, v in (spec.get("coordinate_tasks") or {}).items()},
            required=tuple(tuple(str(m) for m in group) for group in spec["required"]),
            foot_markers={side: str(spec["foot_markers"][side]) for side in SIDES},
            coordinates={str(k): str(v) for k, v in spec["coordinates"].items()},
            fallback_measurement={str(k): str(v) for k, v in (spec.get("fallback_measurement") or {}).items()},
            joint_centres=joint_centre_spec(spec.get("joint_centres"), prefix),
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise LoperInputError(f"{source}: not a marker-set template ({type(exc).__name__}: {exc})") from None
    names = set(template.marker_names) | set(_kad_names(template)) | set(centre_names(template.joint_centres))
    named = [m for pairs, _ in measurements.values() for pair in pairs for m in pair]
    named += [m for group in template.required for m in group] + list(template.foot_markers.values())
    unknown = sorted(set(named) - names)
    if unknown:
        raise LoperInputError(f"{source}: measurements, required or foot_markers name marker(s) {unknown} it lacks")
    return template


# ------------------------------------------------------------------ the knee alignment device

#: Markers of a knee alignment device (Plug-in Gait), after the side prefix: the axis marker and the two others.
KAD_MARKERS: tuple[str, str, str] = ("KAX", "KD1", "KD2")


def _kad_names(template: MarkerTemplate) -> list[str]:
    return [template.side_prefix[side] + code for side in SIDES for code in KAD_MARKERS]


def derived_markers(labels: Sequence[str], side_prefix: Mapping[str, str] | None = None) -> dict[str, tuple[str, ...]]:
    """Markers a trial yields without holding them: the lateral knee marker (``LKNE``) of a knee alignment
    device (``LKAX``, ``LKD1``, ``LKD2``) where the trial lacks it
    (:func:`loper_analysis.motion.knee_alignment.kad_knee_markers` computes it).

    Returns
    -------
    dict
        Derived marker -> the markers it is computed from.
    """
    prefix = side_prefix or {"left": "L", "right": "R"}
    present = set(labels)
    out = {}
    for side in SIDES:
        kad = tuple(prefix[side] + code for code in KAD_MARKERS)
        knee = prefix[side] + "KNE"
        if knee not in present and all(m in present for m in kad):
            out[knee] = kad
    return out


# ------------------------------------------------------------------ fit of a file's labels


@dataclass(frozen=True)
class TemplateFit:
    """How a file's labels fit a template (:func:`template_fit`).

    Attributes
    ----------
    template : MarkerTemplate
    match : LabelMatch
        The labels matched to the template's markers (:func:`loper_analysis.motion.label_matching.match_labels`).
    found : tuple of str
        The template markers the labels provide (derived ones included).
    missing_groups : tuple of tuple of str
        The required groups no label provides.
    """

    template: MarkerTemplate
    match: LabelMatch
    found: tuple[str, ...]
    missing_groups: tuple[tuple[str, ...], ...]

    @property
    def share(self) -> float:
        """Share of the required groups the labels provide (0 .. 1)."""
        n = len(self.template.required)
        return 1.0 if n == 0 else 1.0 - len(self.missing_groups) / n

    @property
    def fits(self) -> bool:
        """Every required group is provided."""
        return not self.missing_groups


def template_fit(labels: Sequence[str], template: MarkerTemplate) -> TemplateFit:
    """Match a file's labels (subject prefix and all) to a template's markers and check its required groups.

    The knee alignment device's markers count for the lateral knee marker they yield
    (:func:`derived_markers`).
    """
    names = template.marker_names + _kad_names(template)
    match = match_labels(labels, names)
    found = [marker for _, marker, _ in match.pairs]
    found += list(derived_markers(found, template.side_prefix))
    have = set(found)
    missing = tuple(group for group in template.required if not any(m in have for m in group))
    return TemplateFit(template, match, tuple(dict.fromkeys(found)), missing)


# ------------------------------------------------------------------ OpenSim objects


def template_marker_set(template: MarkerTemplate, names: Sequence[str] | None = None, model=None):
    """An ``opensim.MarkerSet`` of the template's markers (those of ``names`` only, when given).

    For a template with joint centres whose landmarks ``names`` holds
    (:func:`~loper_analysis.motion.centre_markers.calibration_centres`; ``model``, the template's model, is then
    required), the calibration's virtual markers are added at the model's centres
    (:func:`~loper_analysis.motion.centre_markers.joint_centre_places`) and fixed, and every other marker is free:
    the marker placer fits the static pose through the centres and then moves each marker to where the static
    trial has it. Otherwise anatomical markers are fixed (the marker placer leaves them) and technical ones free."""
    from loper_analysis.io.osim import quiet_opensim

    osim = quiet_opensim()
    keep = None if names is None else set(names)
    centres = {}
    if calibration_centres(template.joint_centres, names):
        if model is None:
            raise LoperInputError(
                f"template {template.name}: the marker set of a static trial with the joint centres' landmarks needs "
                f"the model ({template.model}) for the centres' places"
            )
        centres = joint_centre_places(
            template.joint_centres, template.locations(), model, f"template {template.name} ({template.model})"
        )
    out = osim.MarkerSet()
    places = [(m.name, m.body, m.location_m, m.role == "anatomical" and not centres) for m in template.markers]
    places += [(name, body, location, True) for name, (body, location) in centres.items()]
    for name, body, location, fixed in places:
        if keep is not None and name not in keep and name not in centres:
            continue
        marker = osim.Marker()
        marker.setName(name)
        marker.setParentFrameName(f"/bodyset/{body}")
        marker.set_location(osim.Vec3(*location))
        marker.set_fixed(fixed)
        out.cloneAndAppend(marker)
    return out


def _present_pairs(template: MarkerTemplate, present: set[str]) -> dict[str, tuple[tuple[str, str], ...]]:
    """Each measurement's pairs whose markers are present; where pairs of joint centres are present, those alone."""
    centres = set(centre_names(template.joint_centres))
    pairs = {}
    for name, entry in template.measurements.items():
        found = tuple(p for p in entry[0] if p[0] in present and p[1] in present)
        of_centres = tuple(p for p in found if p[0] in centres and p[1] in centres)
        pairs[name] = of_centres or found
    for name, other in template.fallback_measurement.items():
        if not pairs.get(name):
            pairs[name] = pairs.get(other, ())
    return pairs


def scale_measurement(name: str, pairs: Sequence[tuple[str, str]], bodies: Sequence[str]):
    """An ``opensim.Measurement``: the mean ratio of the marker ``pairs``' distances scales ``bodies`` uniformly
    (X, Y and Z)."""
    from loper_analysis.io.osim import quiet_opensim

    osim = quiet_opensim()
    m = osim.Measurement()
    m.setName(name)
    m.setApply(True)
    for a, b in pairs:
        m.getMarkerPairSet().cloneAndAppend(osim.MarkerPair(a, b))
    for body in bodies:
        scale = osim.BodyScale()
        scale.setName(body)
        axes = osim.ArrayStr()
        for axis in "XYZ":
            axes.append(axis)
        scale.setAxisNames(axes)
        m.getBodyScaleSet().cloneAndAppend(scale)
    return m


def measured_scale_tool(measurements: Mapping[str, tuple[Sequence[tuple[str, str]], Sequence[str]]]):
    """An ``opensim.ScaleTool`` whose model scaler applies ``measurements`` (name -> (marker pairs, bodies),
    :func:`scale_measurement`) with the mass distribution preserved; the marker placer is left as OpenSim
    makes it (off)."""
    from loper_analysis.io.osim import quiet_opensim

    osim = quiet_opensim()
    tool = osim.ScaleTool()
    scaler = tool.getModelScaler()
    scaler.setApply(True)
    order = osim.ArrayStr()
    order.append("measurements")
    scaler.setScalingOrder(order)
    scaler.setPreserveMassDist(True)
    for name, (pairs, bodies) in measurements.items():
        scaler.getMeasurementSet().cloneAndAppend(scale_measurement(name, pairs, bodies))
    return tool


def template_scale_tool(template: MarkerTemplate, static_markers: Sequence[str], marker_set_file: str):
    """An ``opensim.ScaleTool`` for a static trial holding ``static_markers`` (model names, derived ones
    included).

    Each measurement averages its pairs whose two markers are present (a measurement without any takes its
    fallback's pairs, or is left out: its bodies keep factor 1); mass distribution preserved. The marker
    placer fits the static pose with the present markers at their role's weight and the template's
    coordinate tasks; the marker set file is ``marker_set_file`` (relative to the setup's folder).
    """
    from loper_analysis.io.osim import quiet_opensim

    osim = quiet_opensim()
    centres = calibration_centres(template.joint_centres, static_markers)
    present = (set(static_markers) & set(template.marker_names)) | set(centres)
    measurements = {
        name: (pairs, template.measurements[name][1])
        for name, pairs in _present_pairs(template, present).items()
        if pairs
    }
    tool = measured_scale_tool(measurements)
    tool.setName(template.name)
    tool.getGenericModelMaker().setMarkerSetFileName(marker_set_file)
    placer = tool.getMarkerPlacer()
    placer.setApply(True)
    tasks = placer.getIKTaskSet()
    for m in template.markers:
        if m.name in present:
            task = osim.IKMarkerTask()
            task.setName(m.name)
            task.setApply(True)
            task.setWeight(template.joint_centres.others_weight if centres else template.weights[m.role])
            tasks.cloneAndAppend(task)
    for name in centres:
        task = osim.IKMarkerTask()
        task.setName(name)
        task.setApply(True)
        task.setWeight(template.joint_centres.weight)
        tasks.cloneAndAppend(task)
    for coordinate, value in template.coordinate_tasks.items():
        task = osim.IKCoordinateTask()
        task.setName(coordinate)
        task.setApply(True)
        task.setWeight(1000.0)
        task.setValueType(osim.IKCoordinateTask.ManualValue)
        task.setValue(value)
        tasks.cloneAndAppend(task)
    return tool


def template_ik_tasks(template: MarkerTemplate, walking_markers: Sequence[str]) -> pd.DataFrame:
    """IK tasks of walking trials holding ``walking_markers`` (model names): the template markers present at
    their role's weight, and the template's coordinate tasks; columns ``name``, ``kind``, ``weight``,
    ``value`` (rad, coordinates only) as :func:`loper_analysis.io.ik_tasks.read_ik_tasks` reads them.
    Markers of the static trial only (medial markers, a knee alignment device) are not tracked."""
    present = set(walking_markers)
    rows = [
        {"name": m.name, "kind": "marker", "weight": template.weights[m.role], "value": None}
        for m in template.markers
        if m.name in present
    ]
    rows += [
        {"name": c, "kind": "coordinate", "weight": 1000.0, "value": v} for c, v in template.coordinate_tasks.items()
    ]
    return pd.DataFrame(rows, columns=["name", "kind", "weight", "value"])


def template_coordinate_map(template: MarkerTemplate, model) -> dict[str, dict[str, object]]:
    """The coordinate map (``ik.coordinate_map``) of a template's model, each sign read from the model's
    kinematics (:func:`loper_analysis.motion.coordinate_signs.map_signs`).

    Raises
    ------
    LoperInputError
        A coordinate the model lacks or whose motion has no sagittal sign.
    """
    from loper_analysis.motion.coordinate_signs import map_signs

    names = {}
    for key, coordinate in template.coordinates.items():
        if key in ("pelvis_x", "pelvis_angle"):
            names[key] = coordinate
        else:
            for side in SIDES:
                names[f"{key}_{side}"] = coordinate.format(s=SIDE_SUFFIX[side])
    signs = map_signs(model, {k: (c, 1.0) for k, c in names.items()})
    unknown = [f"{k} ({names[k]})" for k, s in signs.items() if s is None]
    if unknown:
        raise LoperInputError(
            f"template {template.name}: the model {template.model} gives no sagittal sign for {', '.join(unknown)}"
        )
    return {k: {"coordinate": names[k], "sign": int(signs[k])} for k in names}
