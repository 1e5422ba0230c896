"""Failures at run time end with one line naming the file, the setting and the value, and leave earlier
results as they were: a job log that cannot be written (a full disk), a report cut short while it was
written, a filter cut-off the Butterworth low-pass cannot use at the file's rate, a YAML syntax error in
the configuration.

A full disk is simulated by making the atomic writer's file write (or its staging directory) raise
``OSError(ENOSPC)``; the report's command is a real child process that writes half a page and fails. One
Snakemake dry run checks the configuration file's syntax error as the console shows it.
"""

from __future__ import annotations

import errno
import hashlib
import logging
import pathlib
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.cli import main as cli_main
from loper_analysis.device.loadcell import LoadcellSettings
from loper_analysis.errors import LoperInputError
from loper_analysis.filtering import DC_GAIN_TOLERANCE, check_cutoff, lowpass, lowpass_finite_runs
from loper_analysis.gait.trial_events import EventSettings
from loper_analysis.io.c3d_writer import write_c3d
from loper_analysis.io.robot_log import write_robot_log
from loper_analysis.layout import fill
from loper_analysis.schema import check_yaml_file
from loper_analysis.stages import study_paths
from loper_analysis.stages.events import step as event_steps
from loper_analysis.stages.logs import rule_log
from loper_analysis.stages.markers import step as marker_steps
from loper_analysis.stages.markers.step import MarkerSettings
from loper_analysis.stages.report import step as report
from tests.stages.events.loadcell_step import loadcell
from tests.workflow_copy import snakemake

PATHS = study_paths()

ENOSPC = "[Errno 28] No space left on device"
POINT_RATE, ANALOG_RATE = 128.0, 1024.0


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _entries(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir())


def _half_written_enospc(monkeypatch) -> None:
    """Every file write of the atomic writer writes half its bytes, then the disk is full."""

    def write_bytes(self, data):
        with open(self, "wb") as f:
            f.write(data[: len(data) // 2])
        raise OSError(errno.ENOSPC, "No space left on device", str(self))

    monkeypatch.setattr(pathlib.Path, "write_bytes", write_bytes)


def _no_staging_directory(monkeypatch) -> None:
    """The atomic writer cannot even make its staging directory: the disk is full."""

    def mkdtemp(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(tempfile, "mkdtemp", mkdtemp)


# ---------------------------------------------------------------- 1. the job's log on a full disk


@pytest.fixture
def old_log(tmp_path) -> Path:
    path = tmp_path / "logs" / "markers.log"
    path.parent.mkdir()
    path.write_text("2024-05-01 10:00:00,000 INFO loper_analysis.rule: the previous run's log\n")
    return path


def test_a_job_whose_log_cannot_be_written_fails_with_one_line_and_keeps_the_old_log(old_log, monkeypatch, capsys):
    before = _digest(old_log)
    handlers = list(logging.getLogger().handlers)
    _half_written_enospc(monkeypatch)
    with pytest.raises(SystemExit) as info:
        with rule_log(old_log) as log:
            log.info("800 frames at 128 Hz")
    assert str(info.value.code) == f"{old_log}: could not write the log: {ENOSPC} (the log's text is above)"
    assert _digest(old_log) == before  # neither a 0-byte nor a half log replaced it
    assert _entries(old_log.parent) == ["markers.log"]  # no staging directory left
    err = capsys.readouterr().err
    assert "INFO loper_analysis.rule: 800 frames at 128 Hz" in err and "job time:" in err  # the log's text
    assert "Traceback" not in err
    assert logging.getLogger().handlers == handlers  # cleaned up all the same


def test_a_failed_job_whose_log_cannot_be_written_keeps_its_own_error_first(old_log, monkeypatch, capsys):
    before = _digest(old_log)
    _no_staging_directory(monkeypatch)
    with pytest.raises(SystemExit) as info:
        with rule_log(old_log):
            raise LoperInputError("data/raw/R01/walk.c3d: POINT:UNITS not declared")
    assert str(info.value.code) == (
        f"data/raw/R01/walk.c3d: POINT:UNITS not declared (traceback above; {old_log}: "
        f"could not write the log: {ENOSPC})"
    )
    assert isinstance(info.value.__cause__, LoperInputError)
    assert _digest(old_log) == before
    err = capsys.readouterr().err
    assert err.count("Traceback (most recent call last)") == 1  # the job's own, from the log's text; no second
    assert "ERROR loper_analysis.rule: LoperInputError: data/raw/R01/walk.c3d: POINT:UNITS not declared" in err


def test_an_interrupted_job_whose_log_cannot_be_written_stays_interrupted(old_log, monkeypatch, capsys):
    _half_written_enospc(monkeypatch)
    with pytest.raises(KeyboardInterrupt):
        with rule_log(old_log):
            raise KeyboardInterrupt
    err = capsys.readouterr().err
    assert f"{old_log}: could not write the log: {ENOSPC}" in err
    assert _entries(old_log.parent) == ["markers.log"]


def test_the_job_process_exits_1_with_one_line_on_stderr(old_log):
    """As Snakemake runs a script: the process's status and its standard error, with the disk full."""
    before = _digest(old_log)
    script = (
        "import errno, pathlib\n"
        "def full(self, data):\n"
        "    raise OSError(errno.ENOSPC, 'No space left on device', str(self))\n"
        "pathlib.Path.write_bytes = full\n"
        "from loper_analysis.stages import rule_log\n"
        f"with rule_log({str(old_log)!r}) as log:\n"
        "    log.info('grf: 2 force platforms')\n"
    )
    res = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert res.returncode == 1
    lines = res.stderr.strip().splitlines()
    assert lines[-1] == f"{old_log}: could not write the log: {ENOSPC} (the log's text is above)"
    assert "INFO loper_analysis.rule: grf: 2 force platforms" in res.stderr and "Traceback" not in res.stderr
    assert _digest(old_log) == before


# ---------------------------------------------------------------- 2. the report written beside its target


@pytest.fixture
def old_report(tmp_path) -> Path:
    path = tmp_path / "results" / "report.html"
    path.parent.mkdir()
    path.write_text("<!DOCTYPE html><html><body>the previous report</body></html>\n")
    return path


def _python(code: str):
    """A report command: this Python running ``code`` with the report's path as ``sys.argv[1]``."""
    return lambda path: [sys.executable, "-c", code, str(path)]


HALF_THEN_FAIL = "import sys\nopen(sys.argv[1], 'w').write('<!DOCTYPE html><html><body><p>half of the ')\nsys.exit(3)\n"
HALF_THEN_SUCCEED = "import sys\nopen(sys.argv[1], 'w').write('<!DOCTYPE html><html><body><p>cut')\n"
WHOLE = "import sys\nopen(sys.argv[1], 'w').write('<!DOCTYPE html><html><body>new</body></html>\\n')\n"


def test_a_report_command_that_fails_halfway_leaves_the_old_report_and_no_temporary_file(old_report):
    before = _digest(old_report)
    with pytest.raises(LoperInputError) as info:
        report.write_report(old_report, _python(HALF_THEN_FAIL))
    assert str(info.value) == (
        f"{old_report}: the report command failed with exit status 3 (its messages are "
        "above): the previous report is kept"
    )
    assert _digest(old_report) == before
    assert _entries(old_report.parent) == ["report.html"]


def test_a_report_cut_short_by_a_command_that_succeeds_is_refused(old_report):
    before = _digest(old_report)
    with pytest.raises(
        LoperInputError,
        match=re.escape(
            f"{old_report}: the report (33 bytes) does not end with </html>: it was cut short: the previous report "
            "is kept"
        ),
    ):
        report.write_report(old_report, _python(HALF_THEN_SUCCEED))
    assert _digest(old_report) == before
    assert _entries(old_report.parent) == ["report.html"]


def test_a_whole_report_replaces_the_old_one(old_report):
    assert report.write_report(old_report, _python(WHOLE)) == old_report
    assert old_report.read_text() == "<!DOCTYPE html><html><body>new</body></html>\n"
    assert _entries(old_report.parent) == ["report.html"]


def test_the_report_subcommand_runs_snakemake_report_beside_the_target(old_report, monkeypatch, capsys):
    """``loper-analysis report TARGET ARGS``: the command line it runs (Snakemake's stood in for by a child
    that records its arguments and writes a whole page), then the move; a failing one exits 2 with one line."""
    calls = []
    snakemake_report_command = report.snakemake_report_command

    def command(snakemake_args=()):
        real = snakemake_report_command(snakemake_args)

        def argv(path):
            calls.append(real(path))
            return _python(WHOLE)(path)

        return argv

    monkeypatch.setattr(report, "snakemake_report_command", command)
    # Snakemake stood in: its results too count as built (the check of missing results has its own test)
    monkeypatch.setattr(report, "missing_results", lambda snakemake_args=(), cwd=None: [])
    (old_report.parent / "lab.yaml").write_text("seed: 7\n")
    lab = old_report.parent / "lab.yaml"
    assert cli_main(["report", str(old_report), "--configfile", str(lab), "--cores", "1"]) == 0
    (argv,) = calls
    staging = Path(argv[4])
    assert argv[:4] == [sys.executable, "-m", "snakemake", "--report"] and argv[5:] == [
        "--configfile",
        str(lab),
        "--cores",
        "1",
    ]
    assert staging.name == "report.html" and staging.parent.parent == old_report.parent  # beside the target
    assert staging.parent.name.startswith(".report.html.") and not staging.parent.exists()
    assert old_report.read_text().endswith("new</body></html>\n")
    assert capsys.readouterr().out == f"{old_report}: report written (0.0 MB)\n"

    monkeypatch.setattr(report, "snakemake_report_command", lambda args=(): _python(HALF_THEN_FAIL))
    before = _digest(old_report)
    assert cli_main(["report", str(old_report)]) == 2
    assert capsys.readouterr().err == (
        f"loper-analysis report: {old_report}: the report command failed with exit "
        "status 3 (its messages are above): the previous report is kept\n"
    )
    assert _digest(old_report) == before and _entries(old_report.parent) == ["lab.yaml", "report.html"]


def test_the_report_subcommand_names_a_config_file_with_a_syntax_error_before_running_snakemake(old_report, capsys):
    bad = old_report.parent / "lab.yaml"
    bad.write_text("filter:\n  cutoff_hz: [40.0\n  order: 4\n")
    before = _digest(old_report)
    assert cli_main(["report", str(old_report), "--configfile", str(bad)]) == 2
    assert capsys.readouterr().err == (
        f"loper-analysis report: {bad}: line 3, column 8: YAML syntax error: expected ',' or ']', but got ':' "
        "(while parsing a flow sequence that starts at line 2, column 14)\n"
    )
    assert _digest(old_report) == before


# ---------------------------------------------------------------- 3a/b. filter cut-offs at the file's rate


def test_cutoffs_the_filter_cannot_use_are_refused_naming_the_setting_the_value_and_the_rate():
    x = np.random.default_rng(1).normal(size=600)
    kw = {"setting": "markers.filter.cutoff_hz", "rate_name": "POINT:RATE", "source": "walk.c3d"}
    cases = [
        (
            1e-9,
            "walk.c3d: markers.filter.cutoff_hz = 1e-09 Hz is too low for POINT:RATE = 128 Hz (Nyquist 64 Hz): an "
            "order-4 Butterworth at 1.6e-11 of the Nyquist frequency is numerically unsound (its gain at 0 Hz is "
            "inf, not 1); raise markers.filter.cutoff_hz",
        ),
        (
            64.0,
            "walk.c3d: markers.filter.cutoff_hz must lie in 0 .. 64 Hz (below the Nyquist frequency of POINT:RATE = "
            "128 Hz), got 64 Hz",
        ),
        (
            0.0,
            "walk.c3d: markers.filter.cutoff_hz must be a positive, finite frequency below the Nyquist frequency "
            "64 Hz of POINT:RATE = 128 Hz, got 0.0",
        ),
        (
            float("inf"),
            "walk.c3d: markers.filter.cutoff_hz must be a positive, finite frequency below the Nyquist "
            "frequency 64 Hz of POINT:RATE = 128 Hz, got inf",
        ),
    ]
    for cutoff, message in cases:
        for filt in (lowpass, lowpass_finite_runs):
            with pytest.raises(LoperInputError) as info:
                filt(x, POINT_RATE, cutoff, 4, **kw)
            assert str(info.value) == message, (filt.__name__, cutoff)


@pytest.mark.parametrize("order", [1, 2, 4, 8])
def test_every_cutoff_the_check_accepts_filters_to_finite_samples_with_unit_gain_at_0_hz(order):
    """The real limit of scipy's Butterworth at the orders the config allows: a cut-off is accepted exactly when
    the filter is sound, and then a constant passes unchanged; the refusals start about 1e-7 of Nyquist."""
    x = np.full(400, 5.0)
    refused = []
    for fraction in 10.0 ** -np.arange(1, 13):
        cutoff = fraction * 0.5 * ANALOG_RATE
        try:
            check_cutoff(ANALOG_RATE, cutoff, order)
        except LoperInputError as exc:
            refused.append(fraction)
            assert "cutoff_hz = " in str(exc) and "is too low for sample_rate_hz = 1024 Hz" in str(exc)
            continue
        y = lowpass(x, ANALOG_RATE, cutoff, order)
        assert np.all(np.isfinite(y)) and np.max(np.abs(y - 5.0)) < 5.0 * 2 * DC_GAIN_TOLERANCE, (order, fraction)
    if order == 1:
        assert refused == []  # one real pole: sound down to 1e-12 of Nyquist
    else:  # refused from 1e-7 (order 2) or 1e-8 (orders 4, 8) of Nyquist down, every lower one too
        assert 1e-9 in refused and max(refused) <= 1.01e-7
        assert refused == [f for f in 10.0 ** -np.arange(1, 13) if f <= max(refused) * 1.01]


@pytest.fixture(scope="module")
def belt_c3d(tmp_path_factory) -> Path:
    """A treadmill trial without force platforms: three markers at 128 Hz and the belts' vertical forces at 1024 Hz."""
    d = tmp_path_factory.mktemp("belts")
    n = 256
    t = np.arange(n) / POINT_RATE
    markers = np.stack(
        [
            np.stack([0.3 + 0.01 * np.sin(t), 0.2 + 0.0 * t, 0.95 + 0.0 * t], -1),  # lab Z up: the pelvis high,
            np.stack([0.3 + 0.0 * t, 0.5 + 0.0 * t, 0.9 + 0.01 * np.cos(t)], -1),
            np.stack([0.6 + 0.0 * t, 0.2 + 0.0 * t, 0.05 + 0.0 * t], -1),  # the heel low (the subject stands)
        ],
        axis=1,
    )
    ta = np.arange(n * 8) / ANALOG_RATE
    fz = 400.0 * np.clip(np.sin(2 * np.pi * ta), 0, None)
    return write_c3d(
        d / "walk-nodevice.c3d",
        ["LASI", "RASI", "LHEE"],
        markers,
        POINT_RATE,
        ["Fz_left", "Fz_right"],
        np.stack([fz, fz[::-1]], -1),
        ["N", "N"],
        ANALOG_RATE,
    )


@pytest.mark.parametrize(
    ("cutoff", "words"),
    [
        (
            600.0,
            "events.grf_cutoff_hz must lie in 0 .. 512 Hz (below the Nyquist frequency of ANALOG:RATE = 1024 Hz), "
            "got 600 Hz",
        ),
        (
            1e-9,
            "events.grf_cutoff_hz = 1e-09 Hz is too low for ANALOG:RATE = 1024 Hz (Nyquist 512 Hz): an order-4 "
            "Butterworth at 2e-12 of the Nyquist frequency is numerically unsound (its gain at 0 Hz is inf, not 1); "
            "raise events.grf_cutoff_hz",
        ),
    ],
    ids=["above-nyquist", "singular"],
)
def test_grf_cutoff_is_named_by_its_config_key_and_the_event_table_is_kept(belt_c3d, tmp_path, cutoff, words):
    out = tmp_path / "walk-nodevice.events.tsv"
    out.write_text("side\tevent\ttime_s\tsample\nleft\theel_strike\t0.5\t64\n")
    before = _digest(out)
    with pytest.raises(LoperInputError) as info:
        event_steps.events(
            belt_c3d, out, EventSettings(grf_channels={"left": "Fz_left", "right": "Fz_right"}, cutoff_hz=cutoff)
        )
    assert str(info.value) == f"{belt_c3d} (analog channel Fz_left): {words}"
    assert "LinAlgError" not in str(info.value)
    assert _digest(out) == before and _entries(tmp_path) == ["walk-nodevice.events.tsv"]


@pytest.mark.parametrize(
    ("cutoff", "words"),
    [
        (
            100.0,
            "markers.filter.cutoff_hz must lie in 0 .. 64 Hz (below the Nyquist frequency of POINT:RATE = 128 Hz), "
            "got 100 Hz",
        ),
        (1e-9, "markers.filter.cutoff_hz = 1e-09 Hz is too low for POINT:RATE = 128 Hz (Nyquist 64 Hz)"),
    ],
    ids=["above-nyquist", "singular"],
)
def test_marker_cutoff_is_named_by_its_config_key_and_the_trc_is_kept(belt_c3d, tmp_path, cutoff, words):
    trc = tmp_path / "walk-nodevice.trc"
    trc.write_text("PathFileType\t4\t(X/Y/Z)\twalk-nodevice.trc\n")
    before = _digest(trc)
    with pytest.raises(LoperInputError) as info:
        marker_steps.markers(belt_c3d, trc, tmp_path / "gaps.tsv", MarkerSettings(cutoff_hz=cutoff))
    assert str(info.value).startswith(f"{belt_c3d}: markers: {words}")
    assert _digest(trc) == before and _entries(tmp_path) == ["walk-nodevice.trc"]


def test_load_cell_cutoff_above_the_robot_logs_nyquist_names_the_log_and_the_config_key(belt_c3d, tmp_path):
    """markers.filter.cutoff_hz also low-passes the robot log's forces, at the log's own rate (here 60 Hz)."""
    rate = 60.0
    n = 120
    log_path = tmp_path / "walk-nodevice.loper.tsv"
    write_robot_log(
        log_path,
        pd.DataFrame(
            {
                "time_s": np.arange(n) / rate,
                "force_desired_n": 0.0,
                "force_measured_n": 0.0,
                "motor_angle_rad": 0.0,
                "motor_velocity_rad_s": 0.0,
                "sync_v": 0.0,
                "perturbation": 0,
                "safety_state": 0,
            }
        ),
        rate,
    )
    out = tmp_path / "walk-nodevice.force.tsv"
    out.write_text("time_s\tforce_measured_n\n0\t0\n")
    before = _digest(out)
    with pytest.raises(LoperInputError) as info:
        loadcell(belt_c3d, log_path, out, LoadcellSettings(sync_channel="Fz_left", cutoff_hz=40.0))
    assert str(info.value) == (
        f"{log_path}: markers.filter.cutoff_hz must lie in 0 .. 30 Hz (below the Nyquist frequency of "
        "the log's sample_rate_hz = 60 Hz), got 40 Hz"
    )
    assert _digest(out) == before


# ---------------------------------------------------------------- 3c. a YAML syntax error in the configuration


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "filter:\n  cutoff_hz: [40.0\n  order: 4\n",
            "line 3, column 8: YAML syntax error: expected ',' or ']', but got ':' (while parsing a flow sequence that "
            "starts at line 2, column 14)",
        ),
        (
            "seed: 7\n\tsubjects: config/subjects.tsv\n",
            "line 2, column 1: YAML syntax error: found character '\\t' that cannot start any token "
            "(while scanning for the next token)",
        ),
        (
            "seed: 7\nsubjects: 'config/subjects.tsv\n",
            "line 3, column 1: YAML syntax error: found unexpected end of stream (while scanning a quoted scalar that "
            "starts at line 2, column 11)",
        ),
        (
            "- seed\n",
            "the config file must hold keys at its top level (key: value), found a sequence at line 1, column 1",
        ),
        ("", "the config file must hold keys at its top level (key: value), found nothing"),
    ],
    ids=["unclosed-list", "tab", "unclosed-quote", "a-list", "empty"],
)
def test_a_config_file_that_does_not_parse_is_named_with_its_line_and_column(tmp_path, text, message):
    path = tmp_path / "lab.yaml"
    path.write_text(text)
    with pytest.raises(LoperInputError) as info:
        check_yaml_file(path)
    assert str(info.value) == f"{path}: {message}"


def test_the_configs_the_project_ships_parse(repo_root):
    for path in [repo_root / "config/config.yaml", *sorted((repo_root / "examples").glob("*/config.yaml"))]:
        check_yaml_file(path)


def test_a_syntax_error_in_config_yaml_stops_snakemake_with_the_file_line_and_column(workflow_dir):
    """Snakemake's own message ("Config file is not valid JSON or YAML") names neither the file nor the line."""
    work = workflow_dir
    config = work / "config/config.yaml"
    lines = config.read_text().splitlines(keepends=True)
    k = next(i for i, line in enumerate(lines) if line.startswith("    cutoff_hz: 40.0"))
    lines[k] = lines[k].replace("cutoff_hz: 40.0", "cutoff_hz: [40.0")
    config.write_text("".join(lines))
    earlier = work / fill(PATHS.markers.trc, subject="R01", trial="walk")
    earlier.parent.mkdir(parents=True)
    earlier.write_text("an earlier result\n")
    res = snakemake(work, "-n", timeout=120)
    console = res.stdout + res.stderr
    assert res.returncode == 1, console
    message = (
        f"config/config.yaml: line {k + 2}, column {lines[k + 1].index(':') + 1}: "
        f"YAML syntax error: expected ',' or ']', but got ':' (while parsing a flow sequence that starts at "
        f"line {k + 1}, column {lines[k].index('[') + 1})"
    )
    assert console.count(message) == 1, console
    assert "not valid JSON or YAML" not in console
    assert earlier.read_text() == "an earlier result\n"
    results = work / PATHS.results_dir
    assert sorted(p.relative_to(results).as_posix() for p in results.rglob("*")) == [
        "markers",
        "markers/R01",
        "markers/R01/walk.trc",
    ]
