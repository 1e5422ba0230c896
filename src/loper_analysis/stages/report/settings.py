"""The report stage's settings: the run's headline settings the front page lists, each taken from the stage
that reads its key; the calibration table of the truth verdicts (``report.calibration``, the report's own key);
the fingerprint of the run's design, from the settings of the stages that decide the fits."""

from __future__ import annotations

from collections.abc import Mapping

from loper_analysis.motion.trial_markers import MarkerSettings
from loper_analysis.report.calibration import CALIBRATED_STAGES, design_fingerprint
from loper_analysis.report.front_page import RunSettings
from loper_analysis.report.front_page_settings import FrontPageSettings
from loper_analysis.stages.impedance.step import FitSettings
from loper_analysis.stages.study.settings import StudySettings
from loper_analysis.synthetic.lab_session import LabSessionSettings

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ("study", "markers", "impedance", "synthetic")


def read_settings(
    config: Mapping,
    study: StudySettings,
    markers: MarkerSettings,
    impedance: FitSettings,
    synthetic: LabSessionSettings,
) -> FrontPageSettings:
    """The front page's settings: the perturbations (onsets in ms, repeats, leg) the study's; the low-pass (Hz,
    order) the markers'; the fit window (s), bounds (N·m/rad, N·m·s/rad), starts, noise model and projected
    components the fit's; the seed the study's; the synthetic lab's variability, trial duration (s) and pulse
    (N, s) the lab's; ``report.calibration`` (a path or null); the design fingerprint of the synthetic lab's, the
    markers' and the fit's settings (:data:`loper_analysis.report.calibration.CALIBRATED_STAGES`, the seed left
    out)."""
    design, window, fit = study.design, impedance.response.window, impedance.identification
    calibration = config["report"]["calibration"]
    decide = {"synthetic": synthetic, "markers": markers, "impedance": impedance}
    return FrontPageSettings(
        RunSettings(
            seed=study.seed,
            perturbation_onsets_ms=design.perturbation_onsets_ms,
            perturbation_repeats=design.perturbation_repeats,
            perturbed_side=design.perturbed_side,
            filter_cutoff_hz=markers.cutoff_hz,
            filter_order=markers.order,
            window_before_s=window.before_s,
            window_after_s=window.after_s,
            stiffness_bounds_nm_per_rad=fit.stiffness_bounds_nm_per_rad,
            damping_bounds_nms_per_rad=fit.damping_bounds_nms_per_rad,
            n_starts=fit.n_starts,
            noise_model=fit.noise_model,
            null_pair_components=fit.null_pair_components,
            synthetic_variability=synthetic.variability,
            synthetic_walking_duration_s=synthetic.walking_duration_s,
            pulse_force_n=synthetic.pulse_force_n,
            pulse_duration_s=synthetic.pulse_duration_s,
        ),
        calibration=None if calibration is None else str(calibration),
        design_fingerprint=design_fingerprint({name: decide[name] for name in CALIBRATED_STAGES}),
    )
