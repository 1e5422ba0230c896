"""The report stage's settings (:class:`FrontPageSettings`): the run's headline settings the front page lists,
composed from the settings types that read them (:meth:`FrontPageSettings.from_config`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from loper_analysis.impedance.identification.impedance import IdentificationSettings
from loper_analysis.impedance.responses.response_window import ResponseWindow
from loper_analysis.motion.trial_markers import MarkerSettings
from loper_analysis.report.front_page import RunSettings
from loper_analysis.study_design import StudyDesign
from loper_analysis.synthetic.lab_session import LabSessionSettings

__all__ = ["FrontPageSettings"]


@dataclass(frozen=True)
class FrontPageSettings:
    """The settings the front page lists: ``run``, the run's
    :class:`~loper_analysis.report.front_page.RunSettings` (the workflow's configuration)."""

    run: RunSettings

    @classmethod
    def from_config(cls, config: Mapping) -> FrontPageSettings:
        """The settings of a validated config, each taken from the settings type that reads its key.

        Parameters
        ----------
        config : mapping
            The validated configuration. The perturbations (``trials.perturbation_onsets_ms``, ms,
            ``perturbation_repeats``, ``perturbed_side``) are the study design's
            (:meth:`loper_analysis.study_design.StudyDesign.from_config`); the low-pass (``filter.cutoff_hz``, Hz,
            ``filter.order``) the walking trials'
            (:meth:`loper_analysis.motion.trial_markers.MarkerSettings.from_config`); the fit window
            (``identification.window_before_s``, ``window_after_s``, s) the response window's
            (:meth:`loper_analysis.impedance.responses.response_window.ResponseWindow.from_config`); the bounds
            (N·m/rad, N·m·s/rad),
            random starts, noise model and projected components of ``identification`` the fit's
            (:meth:`loper_analysis.impedance.identification.impedance.IdentificationSettings.from_config`); ``seed`` and
            the synthetic lab's ``variability``, ``walking_duration_s`` (s) and pulse (N, s) the lab's
            (:meth:`loper_analysis.synthetic.lab_session.LabSessionSettings.from_config`).

        Raises
        ------
        KeyError
            A key one of those types reads missing, named.
        """
        design = StudyDesign.from_config(config["trials"])
        walking = MarkerSettings.from_config(config)
        window = ResponseWindow.from_config(config)
        fit = IdentificationSettings.from_config(config)
        lab = LabSessionSettings.from_config(config)
        return cls(
            RunSettings(
                seed=lab.seed,
                perturbation_onsets_ms=design.perturbation_onsets_ms,
                perturbation_repeats=design.perturbation_repeats,
                perturbed_side=design.perturbed_side,
                filter_cutoff_hz=walking.cutoff_hz,
                filter_order=walking.order,
                window_before_s=window.before_s,
                window_after_s=window.after_s,
                stiffness_bounds_nm_per_rad=fit.stiffness_bounds_nm_per_rad,
                damping_bounds_nms_per_rad=fit.damping_bounds_nms_per_rad,
                n_starts=fit.n_starts,
                noise_model=fit.noise_model,
                null_pair_components=fit.null_pair_components,
                synthetic_variability=lab.variability,
                synthetic_walking_duration_s=lab.walking_duration_s,
                pulse_force_n=lab.pulse_force_n,
                pulse_duration_s=lab.pulse_duration_s,
            )
        )
