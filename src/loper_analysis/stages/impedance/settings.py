"""The impedance stage's settings (config ``impedance.*``), with the strides' outlier rule and the study's
seed."""

from __future__ import annotations

import copy
from collections.abc import Mapping

from loper_analysis.gait.stride_settings import StrideSettings
from loper_analysis.impedance.identification.impedance import IdentificationSettings
from loper_analysis.impedance.responses import ResponseSettings
from loper_analysis.impedance.responses.response_window import ResponseWindow
from loper_analysis.stages.device.step import DeviceSettings
from loper_analysis.stages.impedance.step import FitSettings
from loper_analysis.stages.study.settings import StudySettings

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ("study", "strides", "device")


def read_settings(
    config: Mapping, study: StudySettings, strides: StrideSettings, device: DeviceSettings
) -> FitSettings:
    """The fit's settings of a validated config: the response window (``impedance.window_before_s``,
    ``window_after_s``, ``initial_state_span_s``, s), the counterfactual and every other key of
    ``identification`` (bounds in N·m/rad and N·m·s/rad; the inter-joint ``couplings``); the IQR rule and
    fewest kept strides are the strides', the seed the study's, a second rod's place and push the device's
    (``device.shank_rod``)."""
    ident = config["impedance"]
    window = ResponseWindow(
        before_s=ident["window_before_s"],
        after_s=ident["window_after_s"],
        initial_state_span_s=ident["initial_state_span_s"],
    )
    response = ResponseSettings(
        window=window,
        whisker=strides.whisker,
        max_fraction=strides.max_fraction,
        min_strides=strides.min_valid,
        counterfactual=ident["counterfactual"],
    )
    identification = IdentificationSettings(
        noise_model=ident["noise_model"],
        interval_scatter=ident["interval_scatter"],
        null_pair_components=ident["null_pair_components"],
        min_null_pairs=ident["min_null_pairs"],
        initial_state_degree=ident["initial_state_degree"],
        n_starts=ident["n_starts"],
        n_substeps=ident["n_substeps"],
        tolerance=ident["tolerance"],
        merge_tolerance=ident["merge_tolerance"],
        stiffness_bounds_nm_per_rad=tuple(ident["stiffness_bounds_nm_per_rad"]),
        damping_bounds_nms_per_rad=tuple(ident["damping_bounds_nms_per_rad"]),
        max_ci_fraction=ident["max_ci_fraction"],
        plausible_ranges=copy.deepcopy(ident["plausible_ranges"]),
        min_vaf_pct=ident["min_vaf_pct"],
        max_null_trial_ratio=ident["max_null_trial_ratio"],
        averaging_correction=ident["averaging_correction"],
        couplings=tuple(ident["couplings"]),
        seed=study.seed,
    )
    return FitSettings(response=response, identification=identification, shank_rod=device.shank_rod)
