"""File steps of the simulated gait lab: a synthetic subject's truth file and raw files (C3D, robot logs)."""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence

from loper_analysis.constants import JOINTS
from loper_analysis.io.atomic import PathLike
from loper_analysis.io.c3d_writer import write_recording
from loper_analysis.io.robot_log import write_robot_log
from loper_analysis.io.truth import read_truth, write_truth

__all__ = ["lab_export_session", "lab_session", "truth"]

log = logging.getLogger(__name__)


def truth(
    out_yaml: PathLike,
    row: Mapping,
    stiffness_nm_per_rad: Mapping,
    damping_nms_per_rad: Mapping,
    between_subject_cv: float,
    stiffness_bounds,
    damping_bounds,
    seed: int,
) -> dict:
    """``truth.yaml`` of a synthetic subject: its anthropometrics and true K, D per onset and joint.

    ``row`` is the subject's row of the subject sheet with its anthropometrics
    (:func:`loper_analysis.synthetic.subjects.subject_anthropometry`).
    """
    from loper_analysis.synthetic.subjects import true_impedance

    impedance = true_impedance(
        row["subject"],
        seed,
        stiffness_nm_per_rad,
        damping_nms_per_rad,
        between_subject_cv,
        stiffness_bounds,
        damping_bounds,
    )
    write_truth(out_yaml, row, impedance)
    log.info("truth of %s: %s", row["subject"], impedance)
    return impedance


def lab_session(
    subject: str,
    row: Mapping,
    truth_yaml: PathLike,
    static_out: PathLike,
    trials: Sequence[str],
    onsets_ms: Sequence[int | None],
    c3d_outs: Sequence[PathLike],
    log_outs: Sequence[PathLike],
    no_device: str,
    settings: Mapping,
    lab: Mapping,
    device: Mapping,
    seed: int,
) -> None:
    """One session of the simulated gait lab: the static trial and every walking trial of a synthetic subject.

    ``trials`` with their perturbation onsets (ms, None for walking without
    pulses) and C3D files; ``log_outs`` are the robot logs of the trials with
    the device (every trial but ``no_device``), in order. ``settings`` is the
    config's ``synthetic`` section, ``lab`` the keyword arguments of
    :class:`~loper_analysis.synthetic.trials.LabSettings`, ``device`` those of
    :class:`~loper_analysis.device.controller.DeviceParameters`.

    With ``settings["variability"] == "study"`` the subject walks with the
    study-level variability (``study_variability``), adapts its gait to the
    device (``device_adaptation``, drawn per subject) and its left swing leg
    answers the measured minimal-impedance force with the mean over the
    onsets of its true K and D (with the onset's own in perturbation trials);
    ``"gentle"`` is the earlier lab.
    """

    from loper_analysis.device.controller import DeviceParameters
    from loper_analysis.synthetic.trials import (
        LabSettings,
        PerturbationSettings,
        subject_static_recording,
        subject_walking_trial,
    )
    from loper_analysis.synthetic.variability import lab_variability

    s = settings
    lab_settings, device_parameters = LabSettings(**lab), DeviceParameters(**device)
    height_m, mass_kg = row["height_m"], row["mass_kg"]
    write_recording(
        static_out, subject_static_recording(subject, height_m, mass_kg, s["static_duration_s"], lab_settings, seed)
    )
    log.info("static trial of %s: %s", subject, static_out)
    true = read_truth(truth_yaml)
    logs = iter(log_outs)
    variability, adaptation, minimal_impedance = lab_variability(s, seed, subject, true)
    if variability is not None:
        log.info("%s: device adaptation %s; minimal-impedance walking with %s", subject, adaptation, minimal_impedance)
    for trial, c3d, onset_ms in zip(trials, c3d_outs, onsets_ms, strict=True):
        perturbation = None
        if onset_ms is not None:
            impedance = tuple(true[onset_ms][j][name] for j in JOINTS for name in ("K", "D"))
            perturbation = PerturbationSettings(
                onset_ms / 1000.0,
                impedance,
                s["pulse_force_n"],
                s["pulse_duration_s"],
                tuple(s["perturb_every_strides"]),
            )
        robot_log = None if trial == no_device else next(logs)
        walk, recording = subject_walking_trial(
            subject,
            trial,
            height_m,
            mass_kg,
            s["walking_duration_s"],
            s["timing_cv"],
            s["amplitude_cv"],
            lab_settings,
            device_parameters if robot_log is not None else None,
            seed,
            perturbation,
            variability=variability,
            adaptation=adaptation,
            minimal_impedance=minimal_impedance,
        )
        write_recording(c3d, recording)
        if robot_log is not None:
            write_robot_log(robot_log, walk.robot, lab_settings.robot_rate_hz, {"clock": "robot"})
        log.info("%s: true events:\n%s", trial, walk.mocap_events().to_string(index=False))
        log.info("%s: perturbations:\n%s", trial, walk.schedule.to_string(index=False))


def lab_export_session(
    out_dir: PathLike,
    subject: str,
    model_osim: PathLike,
    marker_set_xml: PathLike,
    label_map_tsv: PathLike,
    trials: Sequence[str],
    onsets_ms: Sequence[int | None],
    no_device: str,
    height_m: float,
    mass_kg: float,
    duration_s: float,
    seed: int,
    impedance: Sequence[float] = (55.0, 3.5, 3.0, 0.1, 8.0, 0.3),
    static_name: str = "static",
    static_duration_s: float = 2.0,
    lab: Mapping | None = None,
    device: Mapping | None = None,
    export: Mapping | None = None,
    timing_cv: float = 0.03,
    amplitude_cv: float = 0.05,
    pulse_force_n: float = 40.0,
    pulse_duration_s: float = 0.1,
    perturb_every_strides: Sequence[int] = (3, 5),
    brace_fraction: float = 0.8,
) -> dict:
    """One subject's session as the lab exports it (QTM C3D + MATLAB robot logs), into ``out_dir``.

    Writes ``{static_name}.c3d`` and per trial ``{trial}.c3d``, plus
    ``{trial}.mat`` for every trial but ``no_device``
    (:func:`loper_analysis.synthetic.lab_export.qtm_walking_export`, variables
    :data:`~loper_analysis.synthetic.lab_export.ROBOT_LOG_MAT_VARIABLES`, time
    in s). The markers are those of ``label_map_tsv`` (columns ``label``,
    ``marker``) on the model ``model_osim`` with the marker set
    ``marker_set_xml``, plus the two brace markers ``LBRA_P`` and ``LBRA_D``
    on the left thigh (:func:`loper_analysis.synthetic.lab_export.add_brace_markers`,
    centred at ``brace_fraction`` of the thigh length; their labels are their
    names unless the map lists them); the kinematics are simulated for a
    subject of ``height_m`` and ``mass_kg``, and the perturbation responses
    with the swing-leg segment table of ``model_osim`` itself
    (:func:`loper_analysis.motion.segments.segments_from_model`, left leg,
    rod attachment at ``brace_fraction``), so that a fit with the table of the
    same model scaled by factors of 1 meets the exact truth. ``onsets_ms`` gives each trial's
    perturbation onset (ms after left toe-off; None: no pulses), answered with
    ``impedance`` (K_hip, D_hip, K_knee, D_knee, K_ankle, D_ankle in N·m/rad
    and N·m·s/rad). ``lab``, ``device`` and ``export`` are keyword arguments
    of :class:`~loper_analysis.synthetic.trials.LabSettings`,
    :class:`~loper_analysis.device.controller.DeviceParameters` and
    :class:`~loper_analysis.synthetic.lab_export.QTMExportSettings`. Seeded by
    ``seed``, subject and trial: the same arguments give the same files.

    Returns
    -------
    dict
        ``{static_name: LabExport, trial: (WalkingTrial, LabExport), ...}``:
        the truth behind the files (coordinates, forces, events, perturbations).
    """
    import zlib
    from pathlib import Path

    import numpy as np

    from loper_analysis.device.controller import DeviceParameters
    from loper_analysis.io.osim import quiet_opensim, read_model
    from loper_analysis.io.readers import read_tsv
    from loper_analysis.io.robot_log_mat import write_robot_log_mat
    from loper_analysis.motion.segments import segments_from_model
    from loper_analysis.synthetic.lab_export import (
        ROBOT_LOG_MAT_VARIABLES,
        QTMExportSettings,
        add_brace_markers,
        qtm_static_export,
        qtm_walking_export,
    )
    from loper_analysis.synthetic.trials import (
        LabSettings,
        PerturbationSettings,
        simulate_walking_trial,
    )

    def seeded(*names: str) -> np.random.SeedSequence:
        return np.random.SeedSequence([int(seed), *(zlib.crc32(n.encode()) for n in (subject, *names))])

    out = Path(out_dir)
    lab_settings = LabSettings(**(lab or {}))
    settings = QTMExportSettings(**(export or {}))
    model = read_model(model_osim)
    model.updateMarkerSet(quiet_opensim().MarkerSet(str(marker_set_xml)))
    table = read_tsv(label_map_tsv, "label map", ("label", "marker"), dtype=str)
    label_map = dict(zip(table["marker"], table["label"]))
    params = segments_from_model(model, "l", attachment_fraction=brace_fraction, source=str(model_osim))
    add_brace_markers(model, params.attachment_m)
    label_map = {**label_map, **{m: m for m in ("LBRA_P", "LBRA_D") if m not in label_map}}
    results: dict = {}
    static = qtm_static_export(
        model,
        label_map,
        mass_kg,
        static_duration_s,
        lab_settings,
        seeded("qtm", static_name),
        settings,
        source=f"{subject} {static_name}",
    )
    write_recording(out / f"{static_name}.c3d", static.recording, **static.writer_extras())
    results[static_name] = static
    for trial, onset_ms in zip(trials, onsets_ms, strict=True):
        perturbation = None
        if onset_ms is not None:
            perturbation = PerturbationSettings(
                onset_ms / 1000.0, tuple(impedance), pulse_force_n, pulse_duration_s, tuple(perturb_every_strides)
            )
        device_parameters = None if trial == no_device else DeviceParameters(**(device or {}))
        sim_seed, file_seed = seeded("qtm", trial).spawn(2)
        walk = simulate_walking_trial(
            duration_s,
            lab_settings,
            sim_seed,
            height_m,
            params,
            timing_cv,
            amplitude_cv,
            device_parameters,
            perturbation,
        )
        exported = qtm_walking_export(
            model, walk, label_map, mass_kg, lab_settings, file_seed, settings, f"{subject} {trial}"
        )
        write_recording(out / f"{trial}.c3d", exported.recording, **exported.writer_extras())
        if walk.robot is not None:
            write_robot_log_mat(out / f"{trial}.mat", walk.robot, lab_settings.robot_rate_hz, ROBOT_LOG_MAT_VARIABLES)
        log.info("%s %s: lab export in %s (first frame %d)", subject, trial, out, settings.first_frame)
        results[trial] = (walk, exported)
    return results
