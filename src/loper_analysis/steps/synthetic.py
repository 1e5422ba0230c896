"""File steps of the simulated gait lab: a synthetic subject's truth file and raw files (C3D, robot logs).

:func:`lab_session` records a synthetic subject's session as the workflow's raw files
(:class:`LabSessionSettings`, :class:`LabSessionFiles`); :func:`lab_export_session` records one as a lab
exports it, QTM C3D files and MATLAB robot logs (:class:`LabExportSettings`, :class:`LabExportFiles`). Both
settings share the recording settings of :class:`SyntheticLabSettings`; ``from_config`` builds them from the
whole validated config (section ``synthetic``, with ``seed``, ``trials``, ``device.parameters``,
``markers.lab_to_model_rotation_deg`` and ``events.sync_channel``).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

from loper_analysis.constants import JOINTS
from loper_analysis.device.controller import DeviceParameters
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike
from loper_analysis.io.c3d_writer import write_recording
from loper_analysis.io.robot_log import write_robot_log
from loper_analysis.io.truth import read_truth, write_truth
from loper_analysis.study_design import SEED, StudyDesign
from loper_analysis.swing_leg.dynamics import BRACE_ATTACHMENT_FRACTION
from loper_analysis.synthetic.lab_export import QTMExportSettings
from loper_analysis.synthetic.trials import LabSettings, PerturbationSettings
from loper_analysis.synthetic.variability import GaitVariability
from loper_analysis.synthetic.walking import AMPLITUDE_CV, TIMING_CV

__all__ = [
    "ADAPTATION_AMPLITUDE_CHANGE",
    "ADAPTATION_OFFSET_RAD",
    "ADAPTATION_SWING_GAIN",
    "LAB_EXPORT_IMPEDANCE",
    "STATIC_TRIAL_DURATION_S",
    "STUDY_VARIABILITY",
    "VARIABILITY",
    "WALKING_TRIAL_DURATION_S",
    "LabExportFiles",
    "LabExportSettings",
    "LabSessionFiles",
    "LabSessionSettings",
    "SyntheticLabSettings",
    "lab_export_session",
    "lab_session",
    "truth",
]

log = logging.getLogger(__name__)

#: Duration of a synthetic static trial (s; config ``synthetic.static_duration_s``).
STATIC_TRIAL_DURATION_S: float = 2.0
#: Duration of a synthetic walking trial (s; config ``synthetic.walking_duration_s``).
WALKING_TRIAL_DURATION_S: float = 45.0
#: Variability model of the synthetic subjects, ``"study"`` or ``"gentle"`` (config ``synthetic.variability``;
#: :mod:`loper_analysis.synthetic.variability`).
VARIABILITY: str = "study"
#: The study-level stride-to-stride variability (config ``synthetic.study_variability``).
STUDY_VARIABILITY = GaitVariability(
    amplitude_cv=(0.03, 0.095, 0.05),
    offset_sd_rad=(0.004, 0.012, 0.014),
    timing_sd=(0.017, 0.013, 0.004),
    swing_gain=(1.0, 1.0, 2.3),
    knots_per_stride=4,
)
#: Typical gait adaptation to the device, per joint (hip, knee, ankle): relative change of the joint's excursion
#: (config ``synthetic.device_adaptation.amplitude_change``) ...
ADAPTATION_AMPLITUDE_CHANGE: tuple[float, float, float] = (0.05, 0.14, 0.08)
#: ... its offset (rad; ``synthetic.device_adaptation.offset_rad``) ...
ADAPTATION_OFFSET_RAD: tuple[float, float, float] = (0.009, 0.022, 0.008)
#: ... and the growth of both from mid-stance to mid-swing (``synthetic.device_adaptation.swing_gain``).
ADAPTATION_SWING_GAIN: tuple[float, float, float] = (2.4, 1.0, 3.2)
#: K, D per joint (K_hip, D_hip, K_knee, D_knee, K_ankle, D_ankle in N·m/rad and N·m·s/rad) a subject of
#: :func:`lab_export_session` answers the pulses with: the config's group truth at 50 ms
#: (``synthetic.stiffness_nm_per_rad``, ``synthetic.damping_nms_per_rad``).
LAB_EXPORT_IMPEDANCE: tuple[float, ...] = (55.0, 3.5, 3.0, 0.1, 8.0, 0.3)


@dataclass(frozen=True)
class SyntheticLabSettings:
    """How the simulated lab records a subject's session (config ``synthetic`` and the keys named below).

    Attributes
    ----------
    seed : int
        Master seed (``seed``); with the subject and trial it seeds every file.
    design : StudyDesign
        The trials (``trials``): the static trial's name, the trial walked without the device
        (``no_device``) and each trial's perturbation onset (:meth:`StudyDesign.onset_ms`).
    lab : LabSettings
        Rates, noise, gaps, robot clock, lab axes and sync channel (:meth:`LabSettings.from_config`).
    device : DeviceParameters
        The simulated LOPER (``device.parameters``).
    static_duration_s, walking_duration_s : float
        Duration of the static trial and of each walking trial (s).
    timing_cv : float
        Stride-to-stride CV of the stride duration.
    amplitude_cv : float
        Gentle lab: CV of the joint-angle amplitudes per stride, leg and joint.
    pulse_force_n, pulse_duration_s : float
        The perturbation: rectangular desired force (N, forward) and its duration (s).
    perturb_every_strides : (int, int)
        A perturbation every ``min`` to ``max`` strides (uniform at random).
    """

    seed: int = SEED
    design: StudyDesign = StudyDesign()
    lab: LabSettings = LabSettings()
    device: DeviceParameters = DeviceParameters()
    static_duration_s: float = STATIC_TRIAL_DURATION_S
    walking_duration_s: float = WALKING_TRIAL_DURATION_S
    timing_cv: float = TIMING_CV
    amplitude_cv: float = AMPLITUDE_CV
    pulse_force_n: float = PerturbationSettings.force_n
    pulse_duration_s: float = PerturbationSettings.duration_s
    perturb_every_strides: tuple[int, int] = PerturbationSettings.every_strides

    @classmethod
    def from_config(cls, config: Mapping) -> SyntheticLabSettings:
        """The settings of the whole validated config (a subclass's own fields keep their defaults)."""
        s = config["synthetic"]
        return cls(
            seed=config["seed"],
            design=StudyDesign.from_config(config["trials"]),
            lab=LabSettings.from_config(config),
            device=DeviceParameters(**config["device"]["parameters"]),
            static_duration_s=s["static_duration_s"],
            walking_duration_s=s["walking_duration_s"],
            timing_cv=s["timing_cv"],
            amplitude_cv=s["amplitude_cv"],
            pulse_force_n=s["pulse_force_n"],
            pulse_duration_s=s["pulse_duration_s"],
            perturb_every_strides=tuple(s["perturb_every_strides"]),
        )

    def perturbation(self, onset_ms: int | None, impedance: Sequence[float]) -> PerturbationSettings | None:
        """The pulses of a trial with onset ``onset_ms`` (ms after toe-off; None: no pulses), answered with
        ``impedance`` (K_hip, D_hip, K_knee, D_knee, K_ankle, D_ankle in N·m/rad and N·m·s/rad)."""
        if onset_ms is None:
            return None
        return PerturbationSettings(
            onset_ms / 1000.0,
            tuple(impedance),
            self.pulse_force_n,
            self.pulse_duration_s,
            tuple(self.perturb_every_strides),
        )


@dataclass(frozen=True)
class LabSessionSettings(SyntheticLabSettings):
    """Settings of :func:`lab_session`: the recording (:class:`SyntheticLabSettings`) and the subjects' gait.

    Attributes
    ----------
    variability : {"study", "gentle"}
        ``study``: the subject walks with ``study_variability``, adapts its gait to the device (drawn per subject
        from the ``adaptation_*`` values) and its left swing leg answers the measured minimal-impedance force;
        ``gentle``: the earlier lab (``amplitude_cv``; only the pulses act).
    study_variability : GaitVariability
        The study-level stride-to-stride variability (``synthetic.study_variability``).
    adaptation_amplitude_change, adaptation_offset_rad, adaptation_swing_gain : (3,) float
        ``synthetic.device_adaptation``: typical relative change of each joint's excursion, offset (rad) and their
        growth toward mid-swing (:func:`loper_analysis.synthetic.variability.device_adaptation`).
    """

    variability: str = VARIABILITY
    study_variability: GaitVariability = STUDY_VARIABILITY
    adaptation_amplitude_change: tuple[float, float, float] = ADAPTATION_AMPLITUDE_CHANGE
    adaptation_offset_rad: tuple[float, float, float] = ADAPTATION_OFFSET_RAD
    adaptation_swing_gain: tuple[float, float, float] = ADAPTATION_SWING_GAIN

    @classmethod
    def from_config(cls, config: Mapping) -> LabSessionSettings:
        """The settings of the whole validated config."""
        s = config["synthetic"]
        v, a = s["study_variability"], s["device_adaptation"]
        return replace(
            super().from_config(config),
            variability=s["variability"],
            study_variability=GaitVariability(
                v["amplitude_cv"], v["offset_sd_rad"], v["timing_sd_stride"], v["swing_gain"], v["knots_per_stride"]
            ),
            adaptation_amplitude_change=tuple(a["amplitude_change"]),
            adaptation_offset_rad=tuple(a["offset_rad"]),
            adaptation_swing_gain=tuple(a["swing_gain"]),
        )

    def variability_settings(self) -> dict:
        """The ``synthetic`` keys :func:`loper_analysis.synthetic.variability.lab_variability` reads."""
        v = self.study_variability
        return {
            "variability": self.variability,
            "study_variability": {
                "amplitude_cv": v.amplitude_cv,
                "offset_sd_rad": v.offset_sd_rad,
                "timing_sd_stride": v.timing_sd,
                "swing_gain": v.swing_gain,
                "knots_per_stride": v.knots_per_stride,
            },
            "device_adaptation": {
                "amplitude_change": self.adaptation_amplitude_change,
                "offset_rad": self.adaptation_offset_rad,
                "swing_gain": self.adaptation_swing_gain,
            },
        }


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


@dataclass(frozen=True)
class LabExportSettings(SyntheticLabSettings):
    """Settings of :func:`lab_export_session`: the recording (:class:`SyntheticLabSettings`; the gentle lab) and
    the export.

    Attributes
    ----------
    export : QTMExportSettings
        How the files look (first frame, label prefix, gaps, plates and channels).
    brace_fraction : float
        The brace markers' centre and the rod attachment along the left thigh (fraction of its length from the
        hip; ``opensim.brace_attachment_fraction``).
    """

    export: QTMExportSettings = QTMExportSettings()
    brace_fraction: float = BRACE_ATTACHMENT_FRACTION

    @classmethod
    def from_config(cls, config: Mapping) -> LabExportSettings:
        """The settings of the whole validated config (``export`` keeps its defaults: no config key)."""
        return replace(super().from_config(config), brace_fraction=config["opensim"]["brace_attachment_fraction"])


@dataclass(frozen=True)
class LabExportFiles:
    """The files of :func:`lab_export_session`.

    Attributes
    ----------
    out_dir : path
        Folder of the session's files (written).
    model_osim : path
        The OpenSim model whose markers and segments the subject has (read).
    marker_set_xml : path
        The model's marker set (read).
    label_map_tsv : path
        The lab's labels of the model's markers (read; columns ``label``, ``marker``).
    """

    out_dir: PathLike
    model_osim: PathLike
    marker_set_xml: PathLike
    label_map_tsv: PathLike


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
    """

    from loper_analysis.synthetic.trials import subject_static_recording, subject_walking_trial
    from loper_analysis.synthetic.variability import lab_variability

    s = settings
    height_m, mass_kg = row["height_m"], row["mass_kg"]
    write_recording(
        files.static_c3d,
        subject_static_recording(subject, height_m, mass_kg, s.static_duration_s, s.lab, s.seed),
    )
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
            s.timing_cv,
            s.amplitude_cv,
            s.lab,
            s.device if robot_log is not None else None,
            s.seed,
            perturbation,
            variability=variability,
            adaptation=adaptation,
            minimal_impedance=minimal_impedance,
        )
        write_recording(c3d, recording)
        if robot_log is not None:
            write_robot_log(robot_log, walk.robot, s.lab.robot_rate_hz, {"clock": "robot"})
        log.info("%s: true events:\n%s", trial, walk.mocap_events().to_string(index=False))
        log.info("%s: perturbations:\n%s", trial, walk.schedule.to_string(index=False))


def lab_export_session(
    files: LabExportFiles,
    subject: str,
    trials: Sequence[str],
    height_m: float,
    mass_kg: float,
    settings: LabExportSettings,
    impedance: Sequence[float] = LAB_EXPORT_IMPEDANCE,
) -> dict:
    """One subject's session as the lab exports it (QTM C3D + MATLAB robot logs), into ``files.out_dir``.

    Writes ``{static}.c3d`` (the static trial of ``settings.design``) and per
    trial of ``trials`` ``{trial}.c3d``, plus ``{trial}.mat`` for every trial
    but the design's ``no_device``
    (:func:`loper_analysis.synthetic.lab_export.qtm_walking_export`, variables
    :data:`~loper_analysis.synthetic.lab_export.ROBOT_LOG_MAT_VARIABLES`, time
    in s). The markers are those of ``files.label_map_tsv`` (columns ``label``,
    ``marker``) on the model ``files.model_osim`` with the marker set
    ``files.marker_set_xml``, plus the two brace markers ``LBRA_P`` and ``LBRA_D``
    on the left thigh (:func:`loper_analysis.synthetic.lab_export.add_brace_markers`,
    centred at ``settings.brace_fraction`` of the thigh length; their labels are their
    names unless the map lists them); the kinematics are simulated for a
    subject of ``height_m`` and ``mass_kg``, and the perturbation responses
    with the swing-leg segment table of the model itself
    (:func:`loper_analysis.motion.segments.segments_from_model`, left leg,
    rod attachment at ``settings.brace_fraction``), so that a fit with the table of the
    same model scaled by factors of 1 meets the exact truth. A trial's pulses
    start at its onset in ``settings.design`` (ms after left toe-off; none for
    walking without pulses) and are answered with ``impedance`` (K_hip, D_hip,
    K_knee, D_knee, K_ankle, D_ankle in N·m/rad and N·m·s/rad). Seeded by
    ``settings.seed``, subject and trial: the same arguments give the same files.

    Returns
    -------
    dict
        ``{static: LabExport, trial: (WalkingTrial, LabExport), ...}``:
        the truth behind the files (coordinates, forces, events, perturbations).
    """
    import zlib
    from pathlib import Path

    import numpy as np

    from loper_analysis.io.osim import quiet_opensim, read_model
    from loper_analysis.io.readers import read_tsv
    from loper_analysis.io.robot_log_mat import write_robot_log_mat
    from loper_analysis.motion.segments import segments_from_model
    from loper_analysis.synthetic.lab_export import (
        ROBOT_LOG_MAT_VARIABLES,
        add_brace_markers,
        qtm_static_export,
        qtm_walking_export,
    )
    from loper_analysis.synthetic.trials import simulate_walking_trial

    def seeded(*names: str) -> np.random.SeedSequence:
        return np.random.SeedSequence([int(settings.seed), *(zlib.crc32(n.encode()) for n in (subject, *names))])

    out = Path(files.out_dir)
    lab_settings, export = settings.lab, settings.export
    static_name = settings.design.static
    model = read_model(files.model_osim)
    model.updateMarkerSet(quiet_opensim().MarkerSet(str(files.marker_set_xml)))
    table = read_tsv(files.label_map_tsv, "label map", ("label", "marker"), dtype=str)
    label_map = dict(zip(table["marker"], table["label"]))
    params = segments_from_model(model, "l", attachment_fraction=settings.brace_fraction, source=str(files.model_osim))
    add_brace_markers(model, params.attachment_m)
    label_map = {**label_map, **{m: m for m in ("LBRA_P", "LBRA_D") if m not in label_map}}
    results: dict = {}
    static = qtm_static_export(
        model,
        label_map,
        mass_kg,
        settings.static_duration_s,
        lab_settings,
        seeded("qtm", static_name),
        export,
        source=f"{subject} {static_name}",
    )
    write_recording(out / f"{static_name}.c3d", static.recording, **static.writer_extras())
    results[static_name] = static
    for trial in trials:
        perturbation = settings.perturbation(settings.design.onset_ms(trial), impedance)
        device_parameters = None if trial == settings.design.no_device else settings.device
        sim_seed, file_seed = seeded("qtm", trial).spawn(2)
        walk = simulate_walking_trial(
            settings.walking_duration_s,
            lab_settings,
            sim_seed,
            height_m,
            params,
            settings.timing_cv,
            settings.amplitude_cv,
            device_parameters,
            perturbation,
        )
        exported = qtm_walking_export(
            model, walk, label_map, mass_kg, lab_settings, file_seed, export, f"{subject} {trial}"
        )
        write_recording(out / f"{trial}.c3d", exported.recording, **exported.writer_extras())
        if walk.robot is not None:
            write_robot_log_mat(out / f"{trial}.mat", walk.robot, lab_settings.robot_rate_hz, ROBOT_LOG_MAT_VARIABLES)
        log.info("%s %s: lab export in %s (first frame %d)", subject, trial, out, export.first_frame)
        results[trial] = (walk, exported)
    return results
