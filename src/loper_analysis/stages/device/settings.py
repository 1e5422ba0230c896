"""The device stage's settings (config ``device.*``: the controller and plant, the free leg, the tests, their
analysis)."""

from __future__ import annotations

import math
from collections.abc import Mapping

from loper_analysis.device.analysis import DeviceAnalysisSettings, FRFSettings, StepSettings
from loper_analysis.device.controller import DeviceParameters, FreeLeg
from loper_analysis.device.trials import DeviceTestSettings
from loper_analysis.stages.device.step import DeviceSettings
from loper_analysis.swing_leg.rods import ShankRod

__all__ = ["NEEDS", "read_settings"]

NEEDS: tuple[str, ...] = ()


def read_settings(config: Mapping) -> DeviceSettings:
    """The device's settings of a validated config: ``device.parameters``, ``device.leg`` (``mass_kg``,
    ``damping_ns_per_m``, ``stiffness_n_per_m``), ``device.tests`` and ``device.analysis`` (the Welch window,
    the step windows in s and the bandwidth's reference band in Hz), ``device.subject`` and
    ``device.mat_column_map``; the second rod's point (``device.shank_rod.attachment_fraction`` of the shank's
    length from the knee) and push (``direction_deg`` from the shank's forward normal, toward the ankle positive;
    converted to rad)."""
    d = config["device"]
    tests, a = d["tests"], d["analysis"]
    return DeviceSettings(
        parameters=DeviceParameters(**d["parameters"]),
        leg=FreeLeg(**d["leg"]),
        tests=DeviceTestSettings(**{**tests, "step_amplitudes_n": tuple(tests["step_amplitudes_n"])}),
        analysis=DeviceAnalysisSettings(
            frf=FRFSettings(window_samples=a["welch_window_samples"], overlap_samples=a["welch_overlap_samples"]),
            steps=StepSettings(
                before_s=a["step_before_s"], after_s=a["step_after_s"], steady_window_s=tuple(a["steady_window_s"])
            ),
            reference_band_hz=tuple(a["bandwidth_reference_band_hz"]),
        ),
        subject=d["subject"],
        mat_column_map=d["mat_column_map"],
        shank_rod=ShankRod(
            attachment_fraction=d["shank_rod"]["attachment_fraction"],
            direction_rad=math.radians(d["shank_rod"]["direction_deg"]),
        ),
    )
