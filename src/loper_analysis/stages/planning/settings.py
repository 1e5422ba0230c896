"""The planning stage's settings (config ``planning.*``): the planned pulse, stride counts and targets, with
what the fit would do (the impedance stage's), the load cell's low-pass (the markers'), the device and the
study's onsets."""

from __future__ import annotations

from collections.abc import Mapping

from loper_analysis.motion.trial_markers import MarkerSettings
from loper_analysis.planning.pilot_plan import PlanningSettings
from loper_analysis.planning.window import PlanSettings
from loper_analysis.stages.device.step import DeviceSettings
from loper_analysis.stages.impedance.step import FitSettings
from loper_analysis.stages.study.settings import StudySettings

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ("study", "markers", "device", "impedance")


def read_settings(
    config: Mapping, study: StudySettings, markers: MarkerSettings, device: DeviceSettings, impedance: FitSettings
) -> PlanningSettings:
    """The planner's settings of a validated config: the rule ``planning`` and ``loper-analysis plan`` both take
    theirs from here. ``planning.strides``, ``targets``, ``pilot_subject``, the second rod's
    ``shank_pulse_force_n`` (N; the rod's point and push the device's) and the pulse ``pulse_force_n`` (N),
    ``pulse_duration_s`` (s); the onsets the study's; the fit window, substeps, projected components, null-pair
    minimum, interval scatter, inter-joint couplings, bounds (N·m/rad, N·m·s/rad), counterfactual and
    null-trial ratio the fit's; the load cell's low-pass (Hz, order) the markers' (as the events stage filters the
    force); the force's rate and the device the device's."""
    p, fit = config["planning"], impedance.identification
    plan = PlanSettings(
        pulse_force_n=p["pulse_force_n"],
        pulse_duration_s=p["pulse_duration_s"],
        shank_pulse_force_n=p["shank_pulse_force_n"],
        shank_rod=device.shank_rod,
        couplings=fit.couplings,
        window=impedance.response.window,
        initial_state_degree=fit.initial_state_degree,
        n_substeps=fit.n_substeps,
        null_pair_components=fit.null_pair_components,
        min_null_pairs=fit.min_null_pairs,
        interval_scatter=fit.interval_scatter,
        stiffness_bounds_nm_per_rad=fit.stiffness_bounds_nm_per_rad,
        damping_bounds_nms_per_rad=fit.damping_bounds_nms_per_rad,
        force_cutoff_hz=markers.cutoff_hz,
        force_order=markers.order,
        force_rate_hz=float(device.parameters.sample_rate_hz),
    )
    return PlanningSettings(
        onsets_ms=study.design.perturbation_onsets_ms,
        strides=tuple(p["strides"]),
        targets=tuple(p["targets"]),
        plan=plan,
        response=impedance.response,
        device=device.parameters,
        max_null_trial_ratio=fit.max_null_trial_ratio,
        pilot_subject=p["pilot_subject"],
    )
