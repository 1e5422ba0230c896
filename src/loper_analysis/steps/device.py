"""File steps of the device tests: simulate a trial to a robot log, analyse logs read from disk, summarise, draw."""

from __future__ import annotations

import logging
import zlib
from collections.abc import Mapping, Sequence

import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike, write_figure, write_tsv
from loper_analysis.io.readers import read_tsv
from loper_analysis.io.robot_log import read_robot_log, write_robot_log

__all__ = ["DEVICE_FLOAT_FORMAT", "device_trial", "log_from_mat", "frf", "steps", "summary", "figures"]

log = logging.getLogger(__name__)

#: Significant digits of the device tables.
DEVICE_FLOAT_FORMAT = "%.10g"


def device_trial(
    out_path: PathLike, subject: str, trial: str, device: Mapping, leg: Mapping, tests: Mapping, seed: int
) -> pd.DataFrame:
    """Simulate one device-test trial of a synthetic subject and write it as a robot log.

    ``device``, ``leg`` and ``tests`` are the keyword arguments of
    :class:`~loper_analysis.device.controller.DeviceParameters`,
    :class:`~loper_analysis.device.controller.FreeLeg` and
    :class:`~loper_analysis.device.trials.DeviceTestSettings`; the seed is
    derived from ``seed``, the subject and the trial. Returns the safety
    events (time, state, name).
    """
    from loper_analysis.device.controller import DeviceParameters, FreeLeg, safety_events
    from loper_analysis.device.trials import DeviceTestSettings, simulate_device_trial

    parameters = DeviceParameters(**device)
    settings = DeviceTestSettings(**{**tests, "step_amplitudes_n": tuple(tests["step_amplitudes_n"])})
    trial_seed = [seed, zlib.crc32(subject.encode()), zlib.crc32(trial.encode())]
    frame = simulate_device_trial(trial, parameters, FreeLeg(**leg), settings, trial_seed)
    write_robot_log(out_path, frame, parameters.sample_rate_hz, {"trial": trial, "source": "synthetic"})
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


def frf(
    log_path: PathLike, out_tsv: PathLike, sample_rate_hz: float, window_samples: int, overlap_samples: int
) -> pd.DataFrame:
    """FRF of the broadband trial -> TSV (frequency_hz, gain, phase_deg, coherence)."""
    from loper_analysis.device.analysis import frequency_response

    robot, _ = read_robot_log(log_path, sample_rate_hz)
    table = frequency_response(
        robot["force_desired_n"].to_numpy(),
        robot["force_measured_n"].to_numpy(),
        sample_rate_hz,
        window_samples=window_samples,
        overlap_samples=overlap_samples,
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
    before_s: float,
    after_s: float,
    steady_window_s,
) -> pd.DataFrame:
    """Step metrics per amplitude and the averaged responses of the step trial."""
    from loper_analysis.device.analysis import step_averages, step_table

    robot, _ = read_robot_log(log_path, sample_rate_hz)
    fd = robot["force_desired_n"].to_numpy()
    fm = robot["force_measured_n"].to_numpy()
    try:
        average = step_averages(fd, fm, sample_rate_hz, tuple(amplitudes_n), before_s, after_s)
        metrics = step_table(average, tuple(steady_window_s))
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
