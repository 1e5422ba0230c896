"""Bad input on the device's side: robot records that would give wrong numbers without an error.

Two faults pass every other check of the load-cell step:

* a sync signal inverted in one record (an active-low robot output): the rising edges of the inverted
  record are the pulses' ends, their intervals match the other record's, and the clock map comes out
  off by the pulse width (10 ms);
* a perturbation trial whose robot log has no perturbation flags: the force shows the pulses, but no
  stride counts as perturbed and the trial ends as ``too_few_strides``.

Each refusal goes through the file step of rule ``events_loadcell``
(:func:`loper_analysis.stages.events.step.events_loadcell`) with the rule's settings from the config, and
must name the file, the field and the values, and leave the outputs of an earlier run as they were. The
good records pass with the numbers they gave before: the clock map of the edges alone, within 1 ms
of the simulated clocks.
"""

from __future__ import annotations

import logging
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from loper_analysis.device.clock_sync import clock_map, high_times, rising_edges
from loper_analysis.device.loadcell import LoadcellSettings
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.trial_events import EventSettings
from loper_analysis.stages.events import step as event_steps
from loper_analysis.stages.settings import stage_settings
from loper_analysis.synthetic.sync import pulse_train_at, sync_pulse_starts

ROOT = Path(__file__).resolve().parents[2]
DURATION_S = 12.0
OUTPUTS = ("events", "contacts", "force", "native")


def _settings() -> tuple[EventSettings, LoadcellSettings]:
    """The settings rule events_loadcell passes to the step (built in inputs.smk from config/config.yaml)."""
    cfg = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    return stage_settings(cfg, "events").events, stage_settings(cfg, "events").loadcell


@pytest.fixture(scope="module")
def trial(tmp_path_factory):
    """One perturbation trial (a pulse every stride) and the same walk in minimal-impedance mode."""
    from loper_analysis.device.controller import DeviceParameters
    from loper_analysis.io.c3d_writer import write_recording
    from loper_analysis.io.robot_log import write_robot_log
    from loper_analysis.motion.model import build_lower_body_model, segment_parameters_from_model
    from loper_analysis.synthetic.trials import (
        LabSettings,
        PerturbationSettings,
        simulate_walking_trial,
        walking_recording,
    )

    raw = tmp_path_factory.mktemp("raw")
    lab = LabSettings()
    model = build_lower_body_model(1.75, 70.0)
    params = segment_parameters_from_model(model)
    pert = PerturbationSettings(onset_s=0.05, impedance=(40.0, 2.0, 1.0, 0.05, 8.0, 0.3), every_strides=(1, 1))
    walk = simulate_walking_trial(
        DURATION_S,
        lab,
        5,
        1.75,
        params,
        timing_cv=0.03,
        amplitude_cv=0.05,
        device=DeviceParameters(),
        perturbation=pert,
    )
    still = simulate_walking_trial(
        DURATION_S, lab, 5, 1.75, params, timing_cv=0.03, amplitude_cv=0.05, device=DeviceParameters()
    )
    assert len(walk.schedule) >= 4
    np.testing.assert_array_equal(still.sync_starts_s, walk.sync_starts_s)  # one sync train: one C3D for both
    rec = walking_recording(model, walk, 70.0, lab, 15, source=str(raw / "pert050-1.c3d"))
    write_recording(raw / "pert050-1.c3d", rec)
    write_robot_log(raw / "pert050-1.loper.tsv", walk.robot, lab.robot_rate_hz, {"clock": "robot"})
    write_robot_log(raw / "walk-device.loper.tsv", still.robot, lab.robot_rate_hz, {"clock": "robot"})
    scale = 1 + 1e-6 * lab.clock_drift_ppm
    return {
        "raw": raw,
        "lab": lab,
        "walk": walk,
        "still": still,
        "rec": rec,
        # t_mocap = offset + scale * t_robot (simulate_walking_trial: t_mocap = -clock_offset_s + scale t_robot)
        "offset_s": -lab.clock_offset_s,
        "scale": scale,
        "onsets_robot_s": (walk.schedule["onset_s"].to_numpy(float) + lab.clock_offset_s) / scale,
    }


def _outputs(tmp_path: Path) -> dict[str, Path]:
    out = tmp_path / "results"
    return {
        "events": out / "t.events.tsv",
        "contacts": out / "t.contacts.tsv",
        "force": out / "t.force.tsv",
        "native": out / "t.force_native.tsv",
    }


def _step(c3d: Path, log: Path, outputs: dict[str, Path]):
    """The file step of rule events_loadcell, with the rule's settings."""
    events, loadcell = _settings()
    return event_steps.events_loadcell(
        c3d, log, outputs["events"], outputs["contacts"], outputs["force"], outputs["native"], events, loadcell
    )


def _refused(tmp_path: Path, c3d: Path, log: Path, words) -> str:
    """The step refuses; its message names every one of ``words``; an earlier run's outputs stay byte-identical."""
    outputs = _outputs(tmp_path)
    outputs["force"].parent.mkdir(parents=True, exist_ok=True)
    for name, path in outputs.items():
        path.write_bytes(f"earlier run: {name}\n".encode())
    before = {p.name: p.read_bytes() for p in outputs["force"].parent.iterdir()}
    with pytest.raises(LoperInputError) as info:
        _step(c3d, log, outputs)
    message = str(info.value)
    for word in words:
        assert word in message, (word, message)
    assert {p.name: p.read_bytes() for p in outputs["force"].parent.iterdir()} == before
    return message


def _edges_only_map(c3d: Path, log: Path):
    """The clock map from the rising edges alone, without the polarity check."""
    from loper_analysis.io.c3d import read_c3d
    from loper_analysis.io.robot_log import read_robot_log

    rec, (frame, meta) = read_c3d(c3d), read_robot_log(log)
    rate = float(meta["sample_rate_hz"])
    robot = rising_edges(frame["sync_v"].to_numpy(), rate)
    robot = np.interp(robot * rate, np.arange(len(frame)), frame["time_s"].to_numpy())
    return clock_map(robot, rec.time_s[0] + rising_edges(rec.analog("sync"), rec.analog_rate_hz))


def _log_with(trial, tmp_path: Path, name: str, source: str = "walk", **columns) -> Path:
    from loper_analysis.io.robot_log import write_robot_log

    path = tmp_path / name
    write_robot_log(path, trial[source].robot.assign(**columns), trial["lab"].robot_rate_hz)
    return path


# --------------------------------------------------------------------------- good records pass unchanged


@pytest.mark.parametrize("log_name", ["pert050-1.loper.tsv", "walk-device.loper.tsv"])
def test_good_records_pass(trial, tmp_path, caplog, log_name):
    """A perturbation trial with its flags and a minimal-impedance trial: the clock map of the edges alone (the
    numbers before the checks), within 1 ms and 50 ppm of the simulated clocks (12 s: ~14 edges); every flag
    kept, nothing warned."""
    outputs = _outputs(tmp_path)
    with caplog.at_level(logging.WARNING, logger="loper_analysis.device.loadcell"):
        _, force = _step(trial["raw"] / "pert050-1.c3d", trial["raw"] / log_name, outputs)
    assert not [r for r in caplog.records if r.name == "loper_analysis.device.loadcell"]
    assert all(p.is_file() for p in outputs.values())
    cm = force.attrs["clock_map"]
    assert cm == _edges_only_map(trial["raw"] / "pert050-1.c3d", trial["raw"] / log_name)
    assert abs(cm.offset_s - trial["offset_s"]) < 1e-3
    assert abs(cm.scale - trial["scale"]) < 50e-6
    n_flags = int((np.diff(force["perturbation"].to_numpy()) == 1).sum())
    assert n_flags == (len(trial["walk"].schedule) if log_name.startswith("pert") else 0)


def _inverted_c3d(trial, tmp_path) -> Path:
    """The trial's C3D with its sync channel inverted (5 V - v)."""
    from loper_analysis.io.c3d_writer import write_recording

    rec = trial["rec"]
    analogs = rec.analogs.copy()
    k = rec.analog_labels.index(trial["lab"].sync_channel)
    analogs[:, k] = 5.0 - analogs[:, k]
    c3d = tmp_path / "inverted.c3d"
    write_recording(c3d, replace(rec, analogs=analogs, source=str(c3d)))
    return c3d


def test_both_records_inverted_pass_with_the_same_clock_map(trial, tmp_path):
    """Both records inverted: their rising edges are both the pulses' ends, the high times agree (~1 s), and the
    clock map is the true one: the check compares the records, not a convention of polarity."""
    c3d = _inverted_c3d(trial, tmp_path)
    log = _log_with(trial, tmp_path, "inverted.loper.tsv", sync_v=5.0 - trial["walk"].robot["sync_v"])
    _, force = _step(c3d, log, _outputs(tmp_path))
    cm = force.attrs["clock_map"]
    assert abs(cm.offset_s - trial["offset_s"]) < 1e-3 and abs(cm.scale - trial["scale"]) < 50e-6


# --------------------------------------------------------------------------- inverted sync


def _high_times_ms(message: str) -> tuple[float, float]:
    m = re.search(
        r"high for ([\d.]+) ms \(duty ratio [\d.]+\) in robot log column 'sync_v' but for ([\d.]+) ms "
        r"\(duty ratio [\d.]+\) in mocap sync channel 'sync'",
        message,
    )
    assert m, message
    return float(m.group(1)), float(m.group(2))


def test_inverted_robot_sync_is_refused(trial, tmp_path):
    """An active-low robot sync output: high ~1 s per pulse in the log against 10 ms in the C3D."""
    log = _log_with(trial, tmp_path, "active-low.loper.tsv", sync_v=5.0 - trial["walk"].robot["sync_v"])
    message = _refused(
        tmp_path,
        trial["raw"] / "pert050-1.c3d",
        log,
        [
            str(log),
            "pert050-1.c3d",
            "robot log column 'sync_v'",
            "mocap sync channel 'sync'",
            "the robot's sync looks inverted (active-low)",
        ],
    )
    robot_ms, mocap_ms = _high_times_ms(message)
    assert 490.0 < robot_ms < 1500.0  # the gaps between the 10 ms pulses (0.5 .. 1.5 s)
    assert abs(mocap_ms - 10.0) < 1.0


def test_inverted_mocap_sync_is_refused(trial, tmp_path):
    """The other way round: the C3D's channel sees the sync inverted; the message says which record."""
    c3d = _inverted_c3d(trial, tmp_path)
    log = trial["raw"] / "pert050-1.loper.tsv"
    message = _refused(
        tmp_path,
        c3d,
        log,
        [
            str(log),
            str(c3d),
            "robot log column 'sync_v'",
            "mocap sync channel 'sync'",
            "the mocap channel sees the sync inverted",
        ],
    )
    robot_ms, mocap_ms = _high_times_ms(message)
    assert abs(robot_ms - 10.0) < 1.0 and 490.0 < mocap_ms < 1500.0


def test_high_times_of_a_train_and_of_its_inverse():
    """high_times: each pulse's width (within a sample), and ``interval - width`` for the inverted train."""
    fs = 1000.0
    starts = sync_pulse_starts(30.0, 7)
    x = pulse_train_at(np.arange(30000) / fs, starts, 0.01)
    r = rising_edges(x, fs)
    np.testing.assert_allclose(high_times(x, fs, r), 0.01, atol=1.01e-3)
    inv = 5.0 - x
    ri = rising_edges(inv, fs)
    h = high_times(inv, fs, ri)
    assert np.isnan(h[-1])  # the inverted record ends high: no falling edge after its last rising edge
    np.testing.assert_allclose(h[:-1], np.diff(starts)[: h.size - 1] - 0.01, atol=1.01e-3)


def test_clock_map_compares_high_times_only_when_given():
    """Without high times the shifted edges of an inverted record give a map off by the pulse width (the old
    silent result); with them the map is refused, naming both high times."""
    fs = 1000.0
    starts = sync_pulse_starts(40.0, 9)
    t = np.arange(40000) / fs
    robot = 5.0 - pulse_train_at(t, starts, 0.01)
    mocap = pulse_train_at(t, starts, 0.01)  # same clock: the true offset is 0
    r, m = rising_edges(robot, fs), rising_edges(mocap, fs)
    assert abs(clock_map(r, m).offset_s + 0.01) < 0.5e-3
    with pytest.raises(
        LoperInputError,
        match=r"rec A: sync pulses high for \d+\.\d ms .* in robot X but for "
        r"10\.\d ms .* in mocap Y .*the robot's sync looks inverted",
    ):
        clock_map(
            r,
            m,
            source="rec A",
            robot_high_s=high_times(robot, fs, r),
            mocap_high_s=high_times(mocap, fs, m),
            robot_name="robot X",
            mocap_name="mocap Y",
        )
    good = clock_map(m, m, robot_high_s=high_times(mocap, fs, m), mocap_high_s=high_times(mocap, fs, m))
    assert abs(good.offset_s) < 1e-9
    wide = pulse_train_at(t, starts, 0.2)  # same edges, 200 ms pulses: not inverted, but not the same pulses
    with pytest.raises(LoperInputError, match=r"high for 10\.\d ms .* but for 200\.\d ms .*do not see the same sync"):
        clock_map(m, m, robot_high_s=high_times(mocap, fs, m), mocap_high_s=high_times(wide, fs, m))


# --------------------------------------------------------------------------- perturbation flags


def _times_in(message: str) -> np.ndarray:
    m = re.search(r"at t = (\d+\.\d+(?:, \d+\.\d+)*)(?:, \.\.\.)? s \(robot clock\)", message)
    assert m, message
    return np.array([float(v) for v in m.group(1).split(", ")])


def test_perturbation_log_without_flags_is_refused(trial, tmp_path):
    """Flag column all zero, force pulses as recorded: the message names file, field, 0 flags, the pulse count
    and the pulses' first times (each within 30 ms after its true onset on the robot clock)."""
    log = _log_with(trial, tmp_path, "noflags.loper.tsv", perturbation=0)
    n = len(trial["walk"].schedule)
    message = _refused(
        tmp_path,
        trial["raw"] / "pert050-1.c3d",
        log,
        [
            str(log),
            "column 'perturbation' flags 0 pulse(s)",
            f"column 'force_measured_n' shows {n} force pulse(s)",
            "no stride would count as perturbed",
        ],
    )
    times = _times_in(message)
    expected = trial["onsets_robot_s"][: times.size]
    assert times.size == min(n, 5)
    assert np.all((times - expected >= 0) & (times - expected < 0.03)), (times, expected)


def test_perturbation_log_with_most_flags_missing_is_refused(trial, tmp_path):
    """Only the first pulse flagged: 1 flag against n pulses, the unflagged ones named from the second on."""
    robot = trial["walk"].robot
    flag = robot["perturbation"].to_numpy().copy()
    second = np.flatnonzero(np.diff(flag) == 1)[1] + 1
    flag[second:] = 0
    log = _log_with(trial, tmp_path, "oneflag.loper.tsv", perturbation=flag)
    n = len(trial["walk"].schedule)
    message = _refused(
        tmp_path,
        trial["raw"] / "pert050-1.c3d",
        log,
        [
            str(log),
            "column 'perturbation' flags 1 pulse(s)",
            f"shows {n} force pulse(s)",
            f"{n - 1} of them without a flag",
        ],
    )
    assert abs(_times_in(message)[0] - trial["onsets_robot_s"][1]) < 0.03


def test_one_missing_flag_is_a_warning(trial, tmp_path, caplog):
    """One pulse of several unflagged: the step runs (the other strides are good), with a warning naming it."""
    robot = trial["walk"].robot
    flag = robot["perturbation"].to_numpy().copy()
    last = np.flatnonzero(np.diff(flag) == 1)[-1] + 1
    flag[last:] = 0
    log = _log_with(trial, tmp_path, "lastflag.loper.tsv", perturbation=flag)
    with caplog.at_level(logging.WARNING, logger="loper_analysis.device.loadcell"):
        _step(trial["raw"] / "pert050-1.c3d", log, _outputs(tmp_path))
    n = len(trial["walk"].schedule)
    text = "\n".join(r.getMessage() for r in caplog.records if r.name == "loper_analysis.device.loadcell")
    assert f"flags {n - 1} pulse(s)" in text and "1 of them without a flag" in text and str(log) in text


def test_mat_export_without_its_flag_variable_is_refused(trial, tmp_path):
    """A MATLAB export whose column map leaves the flag out (zeros): converted by rule device_log_from_mat's
    step, then refused by the load-cell step."""
    from loper_analysis.stages.device.step import log_from_mat
    from tests.io.robot_log_mat_files import write_robot_log_mat

    names = yaml.safe_load((ROOT / "config/config.yaml").read_text())["device"]["mat_column_map"]
    column_map = {**names, "perturbation": None}  # the lab's map, the flag left out
    mat = tmp_path / "pert050-1.mat"
    write_robot_log_mat(mat, trial["walk"].robot, trial["lab"].robot_rate_hz, names)
    log = tmp_path / "converted" / "pert050-1.loper.tsv"
    log_from_mat(mat, log, column_map, trial["lab"].robot_rate_hz)
    _refused(
        tmp_path,
        trial["raw"] / "pert050-1.c3d",
        log,
        [str(log), "column 'perturbation' flags 0 pulse(s)", "device.mat_column_map.perturbation"],
    )


# --------------------------------------------------------------------------- the load cell's unit


@pytest.mark.parametrize(
    ("factor", "words"),
    [
        (1e-3, ["is 0.000", "is the load cell logged in kN (ratio about 0.001)?"]),
        (20.0, ["is 1", "is the load cell logged uncalibrated (a voltage, in mV or V), or in another unit?"]),
    ],
    ids=["kN", "mV"],
)
def test_a_load_cell_logged_in_another_unit_is_refused_from_the_pulses(trial, tmp_path, factor, words):
    """During the flagged pulses the measured force follows the desired one (ratio 0.9-1 in the simulated robot);
    a load cell in kN or uncalibrated (mV, about 20 times the newtons here) is named with its ratio."""
    from loper_analysis.device.loadcell import require_force_unit

    robot = trial["walk"].robot
    on = robot["perturbation"].to_numpy() == 1
    assert 0.85 < require_force_unit(robot["force_desired_n"], robot["force_measured_n"], on) < 1.1
    log = _log_with(trial, tmp_path, "units.loper.tsv", force_measured_n=factor * robot["force_measured_n"])
    message = _refused(
        tmp_path,
        trial["raw"] / "pert050-1.c3d",
        log,
        [
            f"{log} / ",
            ": column 'force_measured_n' is ",
            "times column 'force_desired_n' during the ",
            "accepted 0.5 .. 2",
        ],
    )
    for word in words:
        assert word in message
    ratio = float(message.split("column 'force_measured_n' is ")[1].split(" times")[0])
    assert ratio == pytest.approx(factor * 0.95, rel=0.1)


@pytest.mark.parametrize(
    ("factor", "ratio", "cause"),
    [
        (1e-3, 1e-3, "the log's forces look like kN instead of N (ratio about 0.001)"),
        (1e3, 1e3, "the log's forces look like mN instead of N (ratio about 1000)"),
    ],
    ids=["kN", "mN"],
)
def test_both_force_columns_in_another_unit_are_refused_from_the_configured_pulse(
    trial, tmp_path, factor, ratio, cause
):
    """Both force columns in kN (pulses of 0.04 where the study applies 40 N): measured over desired stays ~1, and
    the desired pulses stayed below the 1 N from which that ratio is judged, so nothing stopped the log until the
    fit failed on its VAF. The desired pulses' amplitude against the configured perturbation force
    (planning.pulse_force_n, 40 N) names the log, the column, both amplitudes and the unit."""
    from loper_analysis.device.loadcell import require_force_unit, require_pulse_amplitude

    robot = trial["walk"].robot
    on = robot["perturbation"].to_numpy() == 1
    assert require_pulse_amplitude(robot["force_desired_n"], on, 40.0) == pytest.approx(1.0, abs=0.01)
    fd, fm = factor * robot["force_desired_n"], factor * robot["force_measured_n"]
    if factor < 1:  # the unit check of the measured force alone cannot judge these pulses
        assert np.isnan(require_force_unit(fd, fm, on))
    log = _log_with(trial, tmp_path, "units.loper.tsv", force_desired_n=fd, force_measured_n=fm)
    message = _refused(
        tmp_path,
        trial["raw"] / "pert050-1.c3d",
        log,
        [
            f"{log} / ",
            ": column 'force_desired_n': the perturbation pulses reach ",
            "times the configured perturbation force of 40 N (planning.pulse_force_n; accepted 0.1 .. 10 times)",
            cause,
            "must hold newtons",
        ],
    )
    amplitude = float(message.split("pulses reach ")[1].split(" ")[0])
    assert amplitude == pytest.approx(40.0 * factor, rel=0.01)
    got = float(message.split("), ")[1].split(" times")[0])
    assert got == pytest.approx(ratio, rel=0.01)


def test_a_minimal_impedance_log_has_no_pulses_to_judge(trial):
    """Without flagged samples the desired force's amplitude is not judged (nothing is asked of the robot)."""
    from loper_analysis.device.loadcell import require_pulse_amplitude

    robot = trial["still"].robot
    assert np.isnan(require_pulse_amplitude(1e-3 * robot["force_desired_n"], robot["perturbation"], 40.0))


# --------------------------------------------------------------------------- a sync channel of noise


def _noise_c3d(trial, tmp_path, seed: int) -> Path:
    """The trial's C3D with its sync channel replaced by seeded noise about the train's mid level (2.5 +- 1 V)."""
    from loper_analysis.io.c3d_writer import write_recording

    rec = trial["rec"]
    analogs = rec.analogs.copy()
    k = rec.analog_labels.index(trial["lab"].sync_channel)
    analogs[:, k] = np.random.default_rng(seed).normal(2.5, 1.0, analogs.shape[0])
    c3d = tmp_path / "noise.c3d"
    write_recording(c3d, replace(rec, analogs=analogs, source=str(c3d)))
    return c3d


_NO_TRAIN = [
    "no pulse train: ",
    " crossings of the halfway level ",
    "levels not two-valued",
    "a pulse train at least 8",
]


@pytest.mark.parametrize("seed", [1, 2])
def test_a_mocap_sync_channel_of_noise_is_refused_as_no_pulse_train(trial, tmp_path, seed):
    """The C3D's sync channel holds noise (an unplugged cable): named as such, with the channel and the file,
    before the edges are matched (it was blamed on 'different trains')."""
    c3d = _noise_c3d(trial, tmp_path, seed)
    message = _refused(
        tmp_path,
        c3d,
        trial["raw"] / "pert050-1.loper.tsv",
        [str(c3d), "mocap sync channel 'sync': ", *_NO_TRAIN, "the channel holds noise", "unplugged sync cable"],
    )
    assert "different trains" not in message
    crossings = int(message.split("no pulse train: ")[1].split(" ")[0])
    assert crossings > 1000  # ~0.5 of 12 s x 1024 samples; the train has ~2 per second
    separation = float(message.split("apart, a pulse train")[0].split("lie only ")[1].split(" ")[0])
    assert 1.5 < separation < 4.0


def test_a_robot_sync_of_noise_is_refused_as_no_pulse_train(trial, tmp_path):
    """The robot log's sync_v holds noise: the log and its column are named."""
    n = len(trial["walk"].robot)
    noise = np.random.default_rng(3).uniform(0.0, 5.0, n)
    log = _log_with(trial, tmp_path, "noise.loper.tsv", sync_v=noise)
    _refused(
        tmp_path,
        trial["raw"] / "pert050-1.c3d",
        log,
        [f"{log} / ", "robot log column 'sync_v': ", *_NO_TRAIN, "unplugged sync cable"],
    )
