"""File steps of the device tests: simulate a trial to a robot log, analyse logs read from disk, summarise, draw."""

from __future__ import annotations

import logging
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import pandas as pd

from loper_analysis.device.analysis import DeviceAnalysisSettings, FRFSettings, StepSettings
from loper_analysis.device.controller import DeviceParameters, FreeLeg
from loper_analysis.device.trials import DeviceTestSettings
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike, write_figure, write_tsv
from loper_analysis.io.generated import generated, refuse_foreign_files
from loper_analysis.io.readers import read_tsv
from loper_analysis.io.robot_log import read_robot_log, write_robot_log
from loper_analysis.swing_leg.rods import ShankRod

__all__ = [
    "DEVICE_FLOAT_FORMAT",
    "DeviceSettings",
    "device_trial",
    "log_from_mat",
    "frf",
    "steps",
    "summary",
    "figures",
]

log = logging.getLogger(__name__)

#: Significant digits of the device tables.
DEVICE_FLOAT_FORMAT = "%.10g"


@dataclass(frozen=True)
class DeviceSettings:
    """The device stage's settings: ``parameters`` (the controller and plant,
    :class:`~loper_analysis.device.controller.DeviceParameters`), ``leg`` (the free-hanging leg of the tests,
    :class:`~loper_analysis.device.controller.FreeLeg`), ``tests`` (the desired-force profiles,
    :class:`~loper_analysis.device.trials.DeviceTestSettings`), ``analysis`` (FRF, steps and the bandwidth's
    reference band, :class:`~loper_analysis.device.analysis.DeviceAnalysisSettings`), ``subject`` (whose raw
    folder holds the device tests' logs; None: no device tests) and ``mat_column_map`` (robot-log column -> the
    variable of a robot's ``.mat`` export holding it; None: no ``.mat`` export read); ``shank_rod`` (where a second
    rod just above the ankle pushes, :class:`~loper_analysis.swing_leg.rods.ShankRod`; whether it pushes is the
    study's design, ``planning.shank_pulse_force_n``)."""

    parameters: DeviceParameters = field(default_factory=DeviceParameters)
    leg: FreeLeg = field(default_factory=FreeLeg)
    tests: DeviceTestSettings = field(default_factory=DeviceTestSettings)
    analysis: DeviceAnalysisSettings = field(default_factory=DeviceAnalysisSettings)
    subject: str | None = None
    mat_column_map: Mapping[str, str] | None = None
    shank_rod: ShankRod = field(default_factory=ShankRod)


def device_trial(
    out_path: PathLike,
    subject: str,
    trial: str,
    device: DeviceParameters,
    leg: FreeLeg,
    tests: DeviceTestSettings,
    seed: int,
) -> pd.DataFrame:
    """Simulate one device-test trial of a synthetic subject and write it as a robot log.

    ``device``: the controller and plant; ``leg``: the free-hanging leg; ``tests``: the desired-force
    profiles; the seed is derived from ``seed``, the subject and the trial. Returns the safety
    events (time, state, name).

    Raises
    ------
    LoperInputError
        ``out_path`` holds a file the workflow did not generate (a recording): nothing is written
        (:func:`loper_analysis.io.generated.refuse_foreign_files`).
    """
    from loper_analysis.device.controller import safety_events
    from loper_analysis.device.trials import simulate_device_trial

    refuse_foreign_files([out_path], f"the simulated device test {trial}")  # before the work
    trial_seed = [seed, zlib.crc32(subject.encode()), zlib.crc32(trial.encode())]
    frame = simulate_device_trial(trial, device, leg, tests, trial_seed)
    with generated(out_path, trial, "robot log") as tmp:  # its checksum in {trial}.generated.sha256
        write_robot_log(tmp, frame, device.sample_rate_hz, {"trial": trial, "source": "synthetic"})
    events = safety_events(frame)
    log.info("wrote %s (seed %s)", out_path, trial_seed)
    log.info("safety state changes (time_s, state, name):\n%s", events.to_string(index=False))
    return events


def log_from_mat(mat_path: PathLike, out_path: PathLike, column_map: Mapping, sample_rate_hz: float) -> pd.DataFrame:
    """Convert a robot log exported from MATLAB (.mat) into the ``loper-log 1`` format."""
    from loper_analysis.io.robot_log_mat import read_robot_log_mat

    frame, _ = read_robot_log_mat(mat_path, column_map, sample_rate_hz)
    write_robot_log(out_path, frame, sample_rate_hz, {"source": str(mat_path)})
    log.info("converted %s (%d samples)", mat_path, len(frame))
    return frame


def frf(log_path: PathLike, out_tsv: PathLike, sample_rate_hz: float, settings: FRFSettings) -> pd.DataFrame:
    """FRF of the broadband trial (robot log at ``sample_rate_hz``, Hz; Welch's method of ``settings``) -> TSV
    (frequency_hz, gain, phase_deg, coherence)."""
    from loper_analysis.device.analysis import frequency_response

    robot, _ = read_robot_log(log_path, sample_rate_hz)
    table = frequency_response(
        robot["force_desired_n"].to_numpy(),
        robot["force_measured_n"].to_numpy(),
        sample_rate_hz,
        window_samples=settings.window_samples,
        overlap_samples=settings.overlap_samples,
    )
    write_tsv(table, out_tsv, DEVICE_FLOAT_FORMAT)
    log.info("FRF: %d frequencies", len(table))
    return table


def steps(
    log_path: PathLike,
    metrics_tsv: PathLike,
    average_tsv: PathLike,
    sample_rate_hz: float,
    amplitudes_n: Sequence[float],
    settings: StepSettings,
) -> pd.DataFrame:
    """Step metrics per amplitude and the averaged responses of the step trial (robot log at ``sample_rate_hz``,
    Hz; steps of ``amplitudes_n``, N, averaged and measured as ``settings`` says)."""
    from loper_analysis.device.analysis import step_averages, step_table

    robot, _ = read_robot_log(log_path, sample_rate_hz)
    fd = robot["force_desired_n"].to_numpy()
    fm = robot["force_measured_n"].to_numpy()
    try:
        average = step_averages(fd, fm, sample_rate_hz, tuple(amplitudes_n), settings.before_s, settings.after_s)
        metrics = step_table(average, tuple(settings.steady_window_s))
    except LoperInputError as exc:
        raise LoperInputError(f"{log_path}: {exc}") from exc
    write_tsv(metrics, metrics_tsv, DEVICE_FLOAT_FORMAT)
    write_tsv(
        average[["amplitude_n", "time_s", "desired_n", "measured_n", "measured_sd_n"]], average_tsv, DEVICE_FLOAT_FORMAT
    )
    log.info("step metrics:\n%s", metrics.to_string())
    return metrics


def summary(frf_tsv: PathLike, metrics_tsv: PathLike, out_tsv: PathLike, reference_band_hz) -> pd.DataFrame:
    """The device figures beside the study's (:func:`loper_analysis.device.analysis.device_summary`)."""
    from loper_analysis.device.analysis import device_summary

    table = device_summary(read_tsv(frf_tsv, "FRF table"), read_tsv(metrics_tsv, "step metrics"), reference_band_hz)
    write_tsv(table, out_tsv, DEVICE_FLOAT_FORMAT)
    log.info("device summary:\n%s", table.to_string())
    return table


def figures(
    frf_tsv: PathLike, summary_tsv: PathLike, average_tsv: PathLike, bode_out: PathLike, steps_out: PathLike
) -> None:
    """The Bode plot (with our and the study's bandwidth) and the averaged step responses."""
    from loper_analysis.report.figures.device import bode_figure, steps_figure

    bandwidth = read_tsv(summary_tsv, "device summary").set_index("metric").loc["bandwidth_hz", "value"]
    write_figure(bode_figure(read_tsv(frf_tsv, "FRF table"), bandwidth), bode_out)
    write_figure(steps_figure(read_tsv(average_tsv, "step averages")), steps_out)
    log.info("wrote %s and %s", bode_out, steps_out)
