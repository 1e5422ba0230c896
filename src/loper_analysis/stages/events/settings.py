"""The events stage's settings: the gait events' (config ``events.*``) and the load cell's
(``events.sync_channel``), with the markers' rotation and low-pass, the ground reactions' resting level and
the planned pulse."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from loper_analysis.device.loadcell import LoadcellSettings
from loper_analysis.gait.grf_settings import GRFSettings
from loper_analysis.gait.trial_events import EventSettings
from loper_analysis.motion.trial_markers import MarkerSettings
from loper_analysis.planning.pilot_plan import PlanningSettings

__all__ = ["NEEDS", "EventsSettings", "read_settings"]

NEEDS: tuple[str, ...] = ("markers", "grf", "planning")


@dataclass(frozen=True)
class EventsSettings:
    """``events``: the gait events' settings (:class:`~loper_analysis.gait.trial_events.EventSettings`);
    ``loadcell``: the robot log on the mocap clock (:class:`~loper_analysis.device.loadcell.LoadcellSettings`)."""

    events: EventSettings = field(default_factory=EventSettings)
    loadcell: LoadcellSettings = field(default_factory=LoadcellSettings)


def read_settings(
    config: Mapping, markers: MarkerSettings, grf: GRFSettings, planning: PlanningSettings
) -> EventsSettings:
    """The settings of a validated config: ``events.*`` (thresholds in N, durations in s); the GRF's low-pass
    order, the rotation and the load cell's low-pass are the markers', the resting-level rule the ground
    reactions', the pulse the load cell's pulses are checked against the planned one (N), the second rod's
    against its planned pulse (N; 0: the logs must hold no shank pulses)."""
    e = config["events"]
    events = EventSettings(
        grf_channels=e["grf_channels"],
        threshold_on_n=e["threshold_on_n"],
        threshold_off_n=e["threshold_off_n"],
        min_stance_s=e["min_stance_s"],
        min_swing_s=e["min_swing_s"],
        cutoff_hz=e["grf_cutoff_hz"],
        order=markers.order,
        foot_markers=e["foot_markers"],
        plate_sides=e["plate_sides"],
        rotation_deg=markers.rotation_deg,
        band_n=grf.band_n,
        max_rest_n=grf.max_rest_n,
    )
    loadcell = LoadcellSettings(
        e["sync_channel"],
        markers.cutoff_hz,
        markers.order,
        planning.plan.pulse_force_n,
        planning.plan.shank_pulse_force_n,
    )
    return EventsSettings(events=events, loadcell=loadcell)
