"""The I/O clock behind the job-time split (timing.py, stages/logs.py, benchmarks/rule_times.py).

A fake clock drives the module, so every number is exact.
"""

import importlib.util
from pathlib import Path

import pytest

from loper_analysis import timing
from loper_analysis.stages.logs import timing_line

ROOT = Path(__file__).resolve().parents[1]


class FakeClock:
    """time.perf_counter and time.time that advance only when told."""

    def __init__(self):
        self.now = 1000.0

    def perf_counter(self):
        return self.now

    def time(self):
        return self.now


@pytest.fixture
def clock(monkeypatch):
    fake = FakeClock()
    monkeypatch.setattr(timing, "time", fake)
    monkeypatch.setattr(timing, "_state", {"depth": 0, "seconds": 0.0, "import_seconds": 0.0, "first_epoch_s": None})
    return fake


def test_nested_io_counts_once_and_library_imports_are_start_up(clock):
    assert timing.io_times() == (0.0, 0.0, None)
    clock.now += 5.0  # start-up: no file touched yet
    with timing.library_import():  # before the first file access: start-up anyway, not counted
        clock.now += 0.7
    with timing.io_clock():
        clock.now += 1.0
        with timing.io_clock():  # a reader calling a reader
            clock.now += 2.0
        with timing.library_import():  # OpenSim imported inside a reader
            clock.now += 0.5
    clock.now += 3.0  # compute
    with timing.library_import():  # scipy.signal imported while computing
        clock.now += 0.25
    assert timing.io_times() == (3.0, 0.75, 1005.7)


def test_timed_io_counts_a_reader_even_when_it_raises(clock):
    @timing.timed_io
    def reader():
        clock.now += 0.5
        raise ValueError("unreadable")

    with pytest.raises(ValueError, match="unreadable"):
        reader()
    assert timing.io_times() == (0.5, 0.0, 1000.0)


def test_the_log_line_and_its_split_into_start_up_io_and_compute(clock):
    clock.now += 2.0
    with timing.io_clock():
        clock.now += 1.5
    with timing.library_import():
        clock.now += 0.5
    clock.now += 4.0
    line = timing_line(end_epoch_s=clock.now)
    assert line == "job time: after_first_io_s=6.000 io_s=1.500 library_import_s=0.500"
    spec = importlib.util.spec_from_file_location("rule_times", ROOT / "benchmarks/rule_times.py")
    rule_times = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(rule_times)
    # Snakemake saw 8.3 s: 2.3 s before the first file access (launch included) + 6 s after it
    split = rule_times.job_split(8.3, "2026-01-01 INFO x: done\n" + line + "\n")
    assert split == pytest.approx({"startup_s": 2.8, "io_s": 1.5, "compute_s": 4.0})
    assert all(v != v for v in rule_times.job_split(8.3, "no timing line").values())  # NaN: not split
