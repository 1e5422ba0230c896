"""The validation stage's settings (config ``validation.*``), with the fit's window, starts and bounds and the
study's seed."""

from __future__ import annotations

from collections.abc import Mapping

from loper_analysis.impedance.identification.validation import ValidationSettings
from loper_analysis.stages.impedance.step import FitSettings
from loper_analysis.stages.study.settings import StudySettings

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ("study", "impedance")

#: Keys of config ``validation`` taken as they are.
_AS_THEY_ARE = (
    "sample_rate_hz",
    "swing_duration_s",
    "onset_s",
    "pulse_force_n",
    "pulse_duration_s",
    "pulse_rise_time_s",
    "pulse_overshoot_pct",
    "force_rate_hz",
    "force_direction_deg",
    "noise_peak_to_peak",
    "truth_substeps",
    "subject_height_m",
    "subject_mass_kg",
    "attachment_fraction_of_thigh",
    "n_chunks",
)


def read_settings(config: Mapping, study: StudySettings, impedance: FitSettings) -> ValidationSettings:
    """The validation study's settings of a validated config: ``validation.*`` (levels in N·m/rad and
    N·m·s/rad, rates in Hz, times in s, the pulse in N); the window, starts, substeps, tolerances,
    initial-state degree and bounds the fit's, the seed the study's."""
    v, fit = config["validation"], impedance.identification
    k_lo, k_hi = fit.stiffness_bounds_nm_per_rad
    d_lo, d_hi = fit.damping_bounds_nms_per_rad
    return ValidationSettings(
        stiffness_levels_nm_per_rad=tuple(v["stiffness_levels_nm_per_rad"]),
        damping_levels_nms_per_rad=tuple(v["damping_levels_nms_per_rad"]),
        **{key: v[key] for key in _AS_THEY_ARE},
        seed=study.seed,
        window=impedance.response.window,
        n_starts=fit.n_starts,
        n_substeps=fit.n_substeps,
        tolerance=fit.tolerance,
        merge_tolerance=fit.merge_tolerance,
        initial_state_degree=fit.initial_state_degree,
        lower=(k_lo, d_lo) * 3,
        upper=(k_hi, d_hi) * 3,
    )
