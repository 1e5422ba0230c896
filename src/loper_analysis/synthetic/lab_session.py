"""The simulated gait lab's settings: how it records a subject's session (:class:`SyntheticLabSettings`) and
how the subjects walk (:class:`LabSessionSettings`), from the whole validated config (section ``synthetic``,
with ``seed``, ``trials``, ``device.parameters``, ``markers.lab_to_model_rotation_deg`` and
``events.sync_channel``)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from loper_analysis.device.controller import DeviceParameters
from loper_analysis.study_design import SEED, StudyDesign
from loper_analysis.swing_leg.rods import ShankRod
from loper_analysis.synthetic.subjects import ImpedanceTruth
from loper_analysis.synthetic.trials import LabSettings, PerturbationSettings
from loper_analysis.synthetic.variability import GaitVariability
from loper_analysis.synthetic.walking import AMPLITUDE_CV, TIMING_CV

__all__ = [
    "ADAPTATION_AMPLITUDE_CHANGE",
    "ADAPTATION_OFFSET_RAD",
    "ADAPTATION_SWING_GAIN",
    "STATIC_TRIAL_DURATION_S",
    "STUDY_VARIABILITY",
    "VARIABILITY",
    "WALKING_TRIAL_DURATION_S",
    "LabSessionSettings",
    "SyntheticLabSettings",
]

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
        Rates, noise, gaps, robot clock, lab axes and sync channel (the synthetic stage's reader,
        :mod:`loper_analysis.stages.synthetic.settings`).
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
    shank_pulse_force_n : float
        A second rod's pulse just above the ankle (N, with the thigh's; 0: no second rod), where ``shank_rod``
        (:class:`~loper_analysis.swing_leg.rods.ShankRod`, the device's) places and points it.
    truth : ImpedanceTruth or None
        The subjects' true impedance (:class:`~loper_analysis.synthetic.subjects.ImpedanceTruth`), drawn once per
        subject into its ``truth.yaml``; the session reads that file, so the truth is no part of its settings'
        repr (a rule's rerun trigger) or equality.
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
    shank_pulse_force_n: float = 0.0
    shank_rod: ShankRod = ShankRod()
    truth: ImpedanceTruth | None = field(default=None, repr=False, compare=False)

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
            self.shank_pulse_force_n,
        )

    def attached_shank_rod(self) -> ShankRod | None:
        """The second rod every trial with the device carries, None without one (``shank_pulse_force_n`` 0)."""
        return self.shank_rod if self.shank_pulse_force_n else None


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
