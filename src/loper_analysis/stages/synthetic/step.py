"""File steps of the simulated gait lab: a synthetic subject's truth file and raw files (C3D, robot logs).

:func:`lab_session` records a synthetic subject's session as the workflow's raw files
(:class:`LabSessionFiles`) with the settings of :class:`loper_analysis.synthetic.lab_session.LabSessionSettings`
(built from the validated config by :mod:`loper_analysis.stages.synthetic.settings`). A session as a lab exports
it (QTM files,
MATLAB logs) is the tests' own (``tests/lab_export_session.py``). The lab never writes over a file it did not
write itself (:mod:`loper_analysis.io.generated`).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike
from loper_analysis.io.c3d_writer import write_recording
from loper_analysis.io.generated import generated, refuse_foreign_files
from loper_analysis.io.robot_log import write_robot_log
from loper_analysis.io.truth import read_truth, write_truth
from loper_analysis.study_design import StudyDesign
from loper_analysis.synthetic.lab_session import LabSessionSettings
from loper_analysis.synthetic.subjects import ImpedanceTruth

__all__ = ["LabSessionFiles", "lab_session", "truth"]

log = logging.getLogger(__name__)

#: The synthetic lab's manifest of the files it wrote: ``{raw folder}/synthetic_lab.generated.sha256``.
WRITER = "synthetic_lab"


@dataclass(frozen=True)
class LabSessionFiles:
    """The files of :func:`lab_session`.

    Attributes
    ----------
    truth_yaml : path
        The subject's ``truth.yaml`` (read: true K, D per onset and joint).
    static_c3d : path
        The static trial's C3D file (written).
    c3d : mapping of str to path
        Walking trial -> its C3D file (written), in the order the trials are recorded.
    robot_logs : mapping of str to path
        Trial walked with the device -> its robot log (written); a walking trial without one is walked
        without the device.
    """

    truth_yaml: PathLike
    static_c3d: PathLike
    c3d: Mapping[str, PathLike]
    robot_logs: Mapping[str, PathLike]

    def __post_init__(self) -> None:
        extra = [t for t in self.robot_logs if t not in self.c3d]
        if extra:
            raise LoperInputError(f"robot logs of trials without a C3D file: {', '.join(extra)}")

    @classmethod
    def in_design_order(
        cls,
        design: StudyDesign,
        truth_yaml: PathLike,
        static_c3d: PathLike,
        c3d: Sequence[PathLike],
        robot_logs: Sequence[PathLike],
    ) -> LabSessionFiles:
        """The files as the rule lists them: one C3D per walking trial of ``design``
        (:meth:`StudyDesign.walking_trials`) and a robot log per trial with the robot, each in that order."""
        trials = design.walking_trials()
        return cls(
            truth_yaml,
            static_c3d,
            dict(zip(trials, c3d, strict=True)),
            dict(zip([t for t in trials if design.with_robot(t)], robot_logs, strict=True)),
        )


def truth(out_yaml: PathLike, row: Mapping, truth: ImpedanceTruth, seed: int) -> dict:
    """``truth.yaml`` of a synthetic subject: its anthropometrics and true K, D per onset and joint, drawn from
    ``truth`` with the study's ``seed``.

    ``row`` is the subject's row of the subject sheet with its anthropometrics
    (:func:`loper_analysis.synthetic.subjects.subject_anthropometry`).
    """
    impedance = truth.of(row["subject"], seed)
    write_truth(out_yaml, row, impedance)
    log.info("truth of %s: %s", row["subject"], impedance)
    return impedance


def lab_session(subject: str, row: Mapping, files: LabSessionFiles, settings: LabSessionSettings) -> None:
    """One session of the simulated gait lab: the static trial and every walking trial of a synthetic subject.

    ``row`` holds the subject's ``height_m`` and ``mass_kg``; ``files`` the
    truth to read and the files to write: a C3D file per walking trial (in
    that order) and a robot log per trial with the device. A trial's pulses
    start at its onset in ``settings.design`` (none for walking without
    pulses) and are answered with the subject's true K and D at that onset.

    With ``settings.variability == "study"`` the subject walks with the
    study-level variability (``study_variability``), adapts its gait to the
    device (``adaptation_*``, drawn per subject) and its left swing leg
    answers the measured minimal-impedance force with the mean over the
    onsets of its true K and D (with the onset's own in perturbation trials);
    ``"gentle"`` is the earlier lab.

    Each file written is entered with its checksum in the folder's ``synthetic_lab.generated.sha256``
    (:mod:`loper_analysis.io.generated`); a file already there must be one of them.

    Raises
    ------
    LoperInputError
        A file to write is already there and the workflow did not write it (a recording): named with its folder,
        before anything is written.
    """

    from loper_analysis.synthetic.trials import subject_static_recording, subject_walking_trial
    from loper_analysis.synthetic.variability import lab_variability

    s = settings
    refuse_foreign_files([files.static_c3d, *files.c3d.values(), *files.robot_logs.values()], "the synthetic lab")
    height_m, mass_kg = row["height_m"], row["mass_kg"]
    with generated(files.static_c3d, WRITER, "C3D file") as tmp:
        write_recording(tmp, subject_static_recording(subject, height_m, mass_kg, s.static_duration_s, s.lab, s.seed))
    log.info("static trial of %s: %s", subject, files.static_c3d)
    true = read_truth(files.truth_yaml)
    variability, adaptation, minimal_impedance = lab_variability(s.variability_settings(), s.seed, subject, true)
    if variability is not None:
        log.info("%s: device adaptation %s; minimal-impedance walking with %s", subject, adaptation, minimal_impedance)
    for trial, c3d in files.c3d.items():
        onset_ms = s.design.onset_ms(trial)
        perturbation = None
        if onset_ms is not None:
            impedance = tuple(true[onset_ms][j][name] for j in JOINTS for name in ("K", "D"))
            perturbation = s.perturbation(onset_ms, impedance)
        robot_log = files.robot_logs.get(trial)
        walk, recording = subject_walking_trial(
            subject,
            trial,
            height_m,
            mass_kg,
            s.walking_duration_s,
            timing_cv=s.timing_cv,
            amplitude_cv=s.amplitude_cv,
            lab=s.lab,
            device=s.device if robot_log is not None else None,
            seed=s.seed,
            perturbation=perturbation,
            variability=variability,
            adaptation=adaptation,
            minimal_impedance=minimal_impedance,
            shank_rod=s.attached_shank_rod(),
        )
        with generated(c3d, WRITER, "C3D file") as tmp:
            write_recording(tmp, recording)
        if robot_log is not None:
            with generated(robot_log, WRITER, "robot log") as tmp:
                write_robot_log(tmp, walk.robot, s.lab.robot_rate_hz, {"clock": "robot"})
        log.info("%s: true events:\n%s", trial, walk.mocap_events().to_string(index=False))
        log.info("%s: perturbations:\n%s", trial, walk.schedule.to_string(index=False))
