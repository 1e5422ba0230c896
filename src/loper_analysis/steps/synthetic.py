"""File steps of the simulated gait lab: a synthetic subject's truth file and raw files (C3D, robot logs)."""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence

from ..constants import JOINTS
from ..io.atomic import PathLike, write_yaml
from ..io.c3d_writer import write_recording
from ..io.readers import read_yaml
from ..io.robot_log import write_robot_log

__all__ = ["truth", "lab_session"]

log = logging.getLogger(__name__)


def truth(out_yaml: PathLike, row: Mapping, stiffness_nm_per_rad: Mapping, damping_nms_per_rad: Mapping,
          between_subject_cv: float, stiffness_bounds, damping_bounds, seed: int) -> dict:
    """``truth.yaml`` of a synthetic subject: its anthropometrics and true K, D per onset and joint.

    ``row`` is the subject's row of the subject sheet with its anthropometrics
    (:func:`loper_analysis.synthetic.subjects.subject_anthropometry`).
    """
    from ..synthetic.subjects import TRUTH_HEADER, true_impedance, truth_document

    impedance = true_impedance(row["subject"], seed, stiffness_nm_per_rad, damping_nms_per_rad, between_subject_cv,
                               stiffness_bounds, damping_bounds)
    write_yaml(out_yaml, truth_document(row, impedance), TRUTH_HEADER)
    log.info("truth of %s: %s", row["subject"], impedance)
    return impedance


def lab_session(subject: str, row: Mapping, truth_yaml: PathLike, static_out: PathLike, trials: Sequence[str],
                onsets_ms: Sequence[int | None], c3d_outs: Sequence[PathLike], log_outs: Sequence[PathLike],
                no_device: str, settings: Mapping, lab: Mapping, device: Mapping, seed: int) -> None:
    """One session of the simulated gait lab: the static trial and every walking trial of a synthetic subject.

    ``trials`` with their perturbation onsets (ms, None for walking without
    pulses) and C3D files; ``log_outs`` are the robot logs of the trials with
    the device (every trial but ``no_device``), in order. ``settings`` is the
    config's ``synthetic`` section, ``lab`` the keyword arguments of
    :class:`~loper_analysis.synthetic.trials.LabSettings`, ``device`` those of
    :class:`~loper_analysis.device.controller.DeviceParameters`.
    """
    from ..device.controller import DeviceParameters
    from ..synthetic.subjects import truth_from_document
    from ..synthetic.trials import (
        LabSettings,
        PerturbationSettings,
        subject_static_recording,
        subject_walking_trial,
    )

    s = settings
    lab_settings, device_parameters = LabSettings(**lab), DeviceParameters(**device)
    height_m, mass_kg = row["height_m"], row["mass_kg"]
    write_recording(static_out, subject_static_recording(subject, height_m, mass_kg, s["static_duration_s"],
                                                         lab_settings, seed))
    log.info("static trial of %s: %s", subject, static_out)
    true = truth_from_document(read_yaml(truth_yaml, "truth file"), str(truth_yaml))
    logs = iter(log_outs)
    for trial, c3d, onset_ms in zip(trials, c3d_outs, onsets_ms, strict=True):
        perturbation = None
        if onset_ms is not None:
            impedance = tuple(true[onset_ms][j][name] for j in JOINTS for name in ("K", "D"))
            perturbation = PerturbationSettings(onset_ms / 1000.0, impedance, s["pulse_force_n"], s["pulse_duration_s"],
                                                tuple(s["perturb_every_strides"]))
        robot_log = None if trial == no_device else next(logs)
        walk, recording = subject_walking_trial(
            subject, trial, height_m, mass_kg, s["walking_duration_s"], s["timing_cv"], s["amplitude_cv"],
            lab_settings, device_parameters if robot_log is not None else None, seed, perturbation,
        )
        write_recording(c3d, recording)
        if robot_log is not None:
            write_robot_log(robot_log, walk.robot, lab_settings.robot_rate_hz, {"clock": "robot"})
        log.info("%s: true events:\n%s", trial, walk.mocap_events().to_string(index=False))
        log.info("%s: perturbations:\n%s", trial, walk.schedule.to_string(index=False))
