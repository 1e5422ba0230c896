"""The ``events`` step: gait events of a trial, and the robot's load cell on the motion-capture clock.

:func:`events` (a trial without the device) and :func:`events_loadcell` (the events and the load cell's forces
from one reading of a trial with the device); their settings :class:`EventSettings` and
:class:`loper_analysis.device.loadcell.LoadcellSettings`, built from the config by
:mod:`loper_analysis.stages.events.settings`.
"""

from __future__ import annotations

import logging

import pandas as pd

from loper_analysis.device.loadcell import LoadcellSettings
from loper_analysis.gait.trial_events import EventSettings, trial_events
from loper_analysis.io.atomic import PathLike, write_tsv
from loper_analysis.io.readers import read_label_maps

__all__ = ["EventSettings", "events", "events_loadcell"]

log = logging.getLogger(__name__)


def events(
    c3d_path: PathLike,
    out_tsv: PathLike,
    settings: EventSettings = EventSettings(),
    contacts_out: PathLike | None = None,
) -> pd.DataFrame:
    """Heel strikes and toe-offs of both legs, on the mocap clock (the file's own time base).

    The fields of ``settings`` (:class:`EventSettings`) name what follows. A file with force platforms
    (``FORCE_PLATFORM:USED`` > 0): each plate's
    contacts from its vertical force above the resting level, each assigned to
    a foot by the heel markers ``foot_markers`` {side: model marker, after
    ``label_map``} over the plate (:func:`loper_analysis.gait.contacts.foot_contacts`;
    ``plate_sides`` {side: plate number} is a check); flagged contacts give no
    heel strike or toe-off but a ``flagged_start``/``flagged_end`` pair that
    keeps strides from spanning them. The contact table goes to
    ``contacts_out`` when given. ``attrs["n_contacts_flagged"]`` counts them
    (:func:`loper_analysis.gait.contacts.count_flagged`).

    A file without platforms: the vertical force of each belt from the
    analog channel ``grf_channels[side]`` (N), as recorded; ``cutoff_hz``
    low-passes it first (zero-phase Butterworth; None thresholds the raw
    force: a 40 Hz filter moves a 20 N toe-off threshold by about 4.5 ms).
    """
    rec, platforms = _read_trial(c3d_path, settings)
    table, contacts = trial_events(rec, platforms, settings, read_label_maps(settings.label_map))
    return _write_events(table, contacts, out_tsv, contacts_out)


def _read_trial(c3d_path: PathLike, s: EventSettings):
    """The recording and its force platforms, from one reading of the C3D; the vertical is the lab's up
    direction that ``rotation_deg`` turns into the model's +Y (:func:`loper_analysis.motion.markers.lab_up`)."""
    from loper_analysis.io.force_platforms import read_c3d_with_platforms
    from loper_analysis.motion.markers import lab_up

    return read_c3d_with_platforms(c3d_path, lab_up(s.rotation_deg))


def _write_events(
    table: pd.DataFrame, contacts: pd.DataFrame, out_tsv: PathLike, contacts_out: PathLike | None
) -> pd.DataFrame:
    """Write the event table (and the contact table when asked); returns the event table."""
    if contacts_out is not None:
        write_tsv(contacts, contacts_out)
    write_tsv(table, out_tsv)
    log.info("events per side and kind:\n%s", table.groupby(["side", "event"]).size().to_string())
    return table


#: Significant digits of the robot-rate force table: its times need microseconds over long trials.
NATIVE_FLOAT_FORMAT = "%.12g"


def _loadcell_of(rec, log_path, s: LoadcellSettings) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The forces on the mocap frames and at the robot rate, of a C3D already read and a robot log."""
    from loper_analysis.device.loadcell import robot_log_frames_and_native
    from loper_analysis.io.robot_log import read_robot_log

    c3d_path, sync_channel = rec.source, s.sync_channel
    frame, meta = read_robot_log(log_path)
    rate = float(meta["sample_rate_hz"])
    from loper_analysis.filtering import check_cutoff  # the robot log's forces are low-passed at its own rate

    check_cutoff(
        rate,
        s.cutoff_hz,
        s.order,
        setting="markers.filter.cutoff_hz",
        rate_name="the log's sample_rate_hz",
        source=str(log_path),
    )
    out, native = robot_log_frames_and_native(
        frame,
        rate,
        rec.analog(sync_channel),
        rec.analog_rate_hz,
        rec.time_s,
        cutoff_hz=s.cutoff_hz,
        order=s.order,
        source=f"{log_path} / {c3d_path}",
        sync_channel=sync_channel,
        pulse_force_n=s.pulse_force_n,
        shank_pulse_force_n=s.shank_pulse_force_n,
    )
    cm = out.attrs.get("clock_map")
    if cm is not None:
        log.info("%s: clock map %s", log_path, cm)
    return out, native


def _write_loadcell(
    out: pd.DataFrame, native: pd.DataFrame, out_tsv: PathLike, native_out: PathLike | None
) -> pd.DataFrame:
    """Write the forces on the mocap frames (and at the robot rate when asked); returns the former."""
    write_tsv(out, out_tsv)
    log.info("%d frames on the mocap clock", len(out))
    if native_out is not None:
        write_tsv(native, native_out, NATIVE_FLOAT_FORMAT)
        log.info("%d robot samples on the mocap clock", len(native))
    return out


def events_loadcell(
    c3d_path: PathLike,
    log_path: PathLike,
    events_out: PathLike,
    contacts_out: PathLike,
    force_out: PathLike,
    native_out: PathLike,
    event_settings: EventSettings = EventSettings(),
    loadcell_settings: LoadcellSettings = LoadcellSettings(),
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """:func:`events` of one trial with the device and the robot log's forces on the mocap frames (sync-pulse clock
    map, low-pass, mocap rate), from one reading of its C3D.

    ``loadcell_settings`` (:class:`LoadcellSettings`): the C3D's sync channel, the forces' low-pass and the study's
    perturbation force, which the desired pulses are checked against. ``native_out``: the same filtered forces at
    the robot log's own rate, on the mocap clock. The records are refused, among others, for sync pulses whose high
    times disagree between the robot log and the C3D (an inverted sync), a sync signal of noise, desired pulses far
    from the perturbation force (forces in kN) or force pulses without perturbation flags
    (:func:`loper_analysis.device.loadcell.robot_log_frames_and_native`).

    Nothing is written unless both succeed. Returns the event table and the force table on the mocap frames.
    """
    rec, platforms = _read_trial(c3d_path, event_settings)
    table, contacts = trial_events(rec, platforms, event_settings, read_label_maps(event_settings.label_map))
    forces = _loadcell_of(rec, log_path, loadcell_settings)  # both computed before anything is written
    _write_events(table, contacts, events_out, contacts_out)
    return table, _write_loadcell(*forces, force_out, native_out)
