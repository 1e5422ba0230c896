"""A workflow job's log: its messages, warnings and full error, its time split, written atomically."""

from __future__ import annotations

import errno
import logging
import os
import pstats
import re

import pytest

from loper_analysis import timing
from loper_analysis.errors import LoperInputError
from loper_analysis.stages import logs
from loper_analysis.stages.logs import PROFILE_VARIABLE, TIMING_PREFIX, rule_log, write_log
from tests.test_timing import FakeClock


def _entries(directory):
    return sorted(p.name for p in directory.iterdir())


@pytest.fixture
def clock(monkeypatch):
    fake = FakeClock()
    monkeypatch.setattr(timing, "time", fake)
    monkeypatch.setattr(logs, "time", fake)
    monkeypatch.setattr(timing, "_state", {"depth": 0, "seconds": 0.0, "import_seconds": 0.0, "first_epoch_s": None})
    return fake


def _job_time(line: str) -> dict[str, float]:
    """The job-time line read back as numbers."""
    assert line.startswith(TIMING_PREFIX + " ")
    return {k: float(v) for k, v in re.findall(r"(\w+)=([0-9.]+)", line[len(TIMING_PREFIX) :])}


def test_a_successful_job_s_log_ends_with_its_time_split(tmp_path, clock):
    log_path = tmp_path / "job.log"
    with rule_log(log_path) as log:
        clock.now += 4.0  # start-up before the first file is touched: not in the split
        with timing.io_clock():
            clock.now += 1.25
            with timing.library_import():
                clock.now += 0.5
        clock.now += 2.0  # compute
        log.info("fitted 12 strides")
    lines = log_path.read_text().splitlines()
    assert lines[0].endswith("INFO loper_analysis.rule: fitted 12 strides")
    assert _job_time(lines[-1]) == {"after_first_io_s": 3.75, "io_s": 1.25, "library_import_s": 0.5}
    assert lines[-1] == "job time: after_first_io_s=3.750 io_s=1.250 library_import_s=0.500"


def test_a_job_that_touched_no_file_has_no_time_after_its_first_access(clock):
    clock.now += 7.0
    assert _job_time(logs.timing_line()) == {"after_first_io_s": 0.0, "io_s": 0.0, "library_import_s": 0.0}


def test_rule_log_restores_the_root_logger_it_borrowed(tmp_path):
    root = logging.getLogger()
    handlers, level = list(root.handlers), root.level
    with rule_log(tmp_path / "job.log") as log:
        assert root.level == logging.INFO
        assert len(root.handlers) == len(handlers) + 1
        log.debug("below INFO: not kept")
    assert root.handlers == handlers
    assert root.level == level
    assert "below INFO" not in (tmp_path / "job.log").read_text()


def test_write_log_writes_the_text_or_names_the_os_error(tmp_path):
    assert write_log(tmp_path / "logs" / "a.log", "line 1\nline 2\n") is None
    assert (tmp_path / "logs" / "a.log").read_text() == "line 1\nline 2\n"
    blocker = tmp_path / "blocker"
    blocker.write_text("a file where a directory should be")
    target = blocker / "b.log"  # its directory cannot be made: a file of that name exists
    assert (
        write_log(target, "never written")
        == f"{target}: could not write the log: [Errno {errno.EEXIST}] {os.strerror(errno.EEXIST)}"
    )
    assert _entries(tmp_path) == ["blocker", "logs"]


def _busy_function_for_the_profile():
    return sum(i * i for i in range(1000))


def test_a_profile_is_written_beside_the_log_when_asked_for(tmp_path, monkeypatch):
    monkeypatch.setenv(PROFILE_VARIABLE, "1")
    with rule_log(tmp_path / "job.log"):
        assert _busy_function_for_the_profile() == 332833500
    assert _entries(tmp_path) == ["job.log", "job.log.prof"]
    names = {func[2] for func in pstats.Stats(str(tmp_path / "job.log.prof")).stats}
    assert "_busy_function_for_the_profile" in names
    monkeypatch.setenv(PROFILE_VARIABLE, "0")
    with rule_log(tmp_path / "other.log"):
        _busy_function_for_the_profile()
    assert _entries(tmp_path) == ["job.log", "job.log.prof", "other.log"]


def test_rule_log_writes_the_messages_and_the_full_error_when_the_job_fails(tmp_path):
    log_path = tmp_path / "logs" / "job.log"
    with pytest.raises(SystemExit) as info:
        with rule_log(log_path) as log:
            log.info("reading the trial")
            logging.getLogger("loper_analysis.stages.strides.step").warning("a gap of 12 frames")
            raise LoperInputError("pert050-1.c3d: POINT:UNITS not declared")
    text = log_path.read_text()
    assert "INFO loper_analysis.rule: reading the trial" in text
    assert "WARNING loper_analysis.stages.strides.step: a gap of 12 frames" in text
    assert "ERROR loper_analysis.rule: LoperInputError: pert050-1.c3d: POINT:UNITS not declared" in text
    assert "Traceback (most recent call last)" in text
    assert _entries(log_path.parent) == ["job.log"]
    # the job ends with the error in one line (what the console shows), the traceback stays in the log
    assert str(info.value.code) == f"pert050-1.c3d: POINT:UNITS not declared (traceback in {log_path})"
    assert isinstance(info.value.__cause__, LoperInputError)


def test_rule_log_names_the_type_of_an_unexpected_error_and_lets_interruptions_through(tmp_path):
    with pytest.raises(SystemExit, match=r"^KeyError: 'sync_channel' \(traceback in "):
        with rule_log(tmp_path / "a.log"):
            {}["sync_channel"]
    assert "KeyError: 'sync_channel'" in (tmp_path / "a.log").read_text()
    with pytest.raises(KeyboardInterrupt):
        with rule_log(tmp_path / "b.log"):
            raise KeyboardInterrupt
    assert "ERROR loper_analysis.rule: KeyboardInterrupt" in (tmp_path / "b.log").read_text()


def test_a_sigterm_ends_the_job_with_its_log_written_and_the_handler_restored(tmp_path):
    """scancel and SLURM's time limit send SIGTERM: the rule's log must say so before the process ends."""
    import os
    import signal
    import time

    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(SystemExit, match=r"^stopped by SIGTERM: the job was cancelled"):
        with rule_log(tmp_path / "ik.log") as log:
            log.info("solving 5760 frames")
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(5)  # the signal arrives long before this ends
            log.info("never reached")
    text = (tmp_path / "ik.log").read_text()
    assert "INFO loper_analysis.rule: solving 5760 frames" in text
    assert "ERROR loper_analysis.rule: SystemExit: stopped by SIGTERM" in text
    assert "never reached" not in text
    assert signal.getsignal(signal.SIGTERM) is before
    assert _entries(tmp_path) == ["ik.log"]


def test_rule_log_captures_warnings(tmp_path):
    import warnings

    log_path = tmp_path / "job.log"
    with rule_log(log_path):
        warnings.warn("only 3 valid strides", UserWarning, stacklevel=1)
    assert "only 3 valid strides" in log_path.read_text()
