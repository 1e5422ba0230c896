"""The synthetic lab's settings (config ``synthetic.*``), with the study's design and seed, the markers' lab
axes, the load cell's sync channel and the device (its second rod's place too)."""

from __future__ import annotations

from collections.abc import Mapping

from loper_analysis.motion.trial_markers import MarkerSettings
from loper_analysis.stages.device.step import DeviceSettings
from loper_analysis.stages.events.settings import EventsSettings
from loper_analysis.stages.impedance.step import FitSettings
from loper_analysis.stages.study.settings import StudySettings
from loper_analysis.synthetic.lab_session import LabSessionSettings
from loper_analysis.synthetic.subjects import ImpedanceTruth
from loper_analysis.synthetic.trials import LabSettings
from loper_analysis.synthetic.variability import GaitVariability

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ("study", "markers", "events", "device", "impedance")


def read_settings(
    config: Mapping,
    study: StudySettings,
    markers: MarkerSettings,
    events: EventsSettings,
    device: DeviceSettings,
    impedance: FitSettings,
) -> LabSessionSettings:
    """The synthetic lab of a validated config: ``synthetic.*`` (durations in s, noise in m and N, the robot
    clock's offset in s and drift in ppm, the pulse in N and s, the variability and the device adaptation);
    the trials and seed the study's, the lab's axes the markers' rotation, the sync channel the load cell's,
    the device's parameters and its second rod's place the device's, a second rod's pulse (N,
    ``shank_pulse_force_n``); the true impedance (``stiffness_nm_per_rad``, ``damping_nms_per_rad`` per onset,
    ``between_subject_cv``) inside the fit's bounds. The rates, the robot log's margin and the belts' channel names
    keep their defaults."""
    s, fit = config["synthetic"], impedance.identification
    v, a = s["study_variability"], s["device_adaptation"]
    lab = LabSettings(
        marker_noise_sd_m=s["marker_noise_sd_m"],
        n_gaps=s["marker_gaps_per_trial"],
        max_gap_frames=s["max_gap_frames"],
        grf_noise_sd_n=s["grf_noise_sd_n"],
        clock_offset_s=s["clock_offset_s"],
        clock_drift_ppm=s["clock_drift_ppm"],
        lab_to_model_rotation_deg=markers.rotation_deg,
        sync_channel=events.loadcell.sync_channel,
    )
    return LabSessionSettings(
        seed=study.seed,
        design=study.design,
        lab=lab,
        device=device.parameters,
        static_duration_s=s["static_duration_s"],
        walking_duration_s=s["walking_duration_s"],
        timing_cv=s["timing_cv"],
        amplitude_cv=s["amplitude_cv"],
        pulse_force_n=s["pulse_force_n"],
        pulse_duration_s=s["pulse_duration_s"],
        perturb_every_strides=tuple(s["perturb_every_strides"]),
        shank_pulse_force_n=s["shank_pulse_force_n"],
        shank_rod=device.shank_rod,
        variability=s["variability"],
        study_variability=GaitVariability(
            v["amplitude_cv"], v["offset_sd_rad"], v["timing_sd_stride"], v["swing_gain"], v["knots_per_stride"]
        ),
        adaptation_amplitude_change=tuple(a["amplitude_change"]),
        adaptation_offset_rad=tuple(a["offset_rad"]),
        adaptation_swing_gain=tuple(a["swing_gain"]),
        truth=ImpedanceTruth(
            stiffness_nm_per_rad=s["stiffness_nm_per_rad"],
            damping_nms_per_rad=s["damping_nms_per_rad"],
            between_subject_cv=s["between_subject_cv"],
            stiffness_bounds_nm_per_rad=fit.stiffness_bounds_nm_per_rad,
            damping_bounds_nms_per_rad=fit.damping_bounds_nms_per_rad,
        ),
    )
