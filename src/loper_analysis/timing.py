"""Wall time a process spends reading and writing files, for the start-up / I/O / compute split of a job.

Every reader of :mod:`loper_analysis.io` runs under :func:`timed_io` and
every write under the atomic writer's :func:`~loper_analysis.io.atomic.staged`,
which uses :func:`io_clock`. Nested calls (a reader calling another) count
once. :func:`io_times` gives the total and the moment of the first file
access; :func:`loper_analysis.stages.rule_log` writes them to the job's log,
and ``benchmarks/rule_times.py`` turns them into the split.
"""

from __future__ import annotations

import contextlib
import functools
import time
from collections.abc import Callable, Iterator
from typing import TypeVar

__all__ = ["io_clock", "io_times", "library_import", "timed_io"]

F = TypeVar("F", bound=Callable)

_state = {"depth": 0, "seconds": 0.0, "import_seconds": 0.0, "first_epoch_s": None}


@contextlib.contextmanager
def io_clock() -> Iterator[None]:
    """Count the wall time of the body as file I/O (once, however deeply nested)."""
    if _state["depth"]:
        _state["depth"] += 1
        try:
            yield
        finally:
            _state["depth"] -= 1
        return
    if _state["first_epoch_s"] is None:
        _state["first_epoch_s"] = time.time()
    start = time.perf_counter()
    _state["depth"] = 1
    try:
        yield
    finally:
        _state["depth"] = 0
        _state["seconds"] += time.perf_counter() - start


@contextlib.contextmanager
def library_import() -> Iterator[None]:
    """Count the body (the first import of a heavy library: OpenSim, ezc3d, scipy.signal) as start-up, not I/O or
    compute."""
    start = time.perf_counter()
    try:
        yield
    finally:
        spent = time.perf_counter() - start
        if _state["first_epoch_s"] is not None:  # before the first file access it is start-up anyway
            _state["import_seconds"] += spent
        if _state["depth"]:
            _state["seconds"] -= spent  # the enclosing I/O clock adds the whole span when it stops


def timed_io(func: F) -> F:
    """Decorator: the function's wall time is file I/O (:func:`io_clock`)."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with io_clock():
            return func(*args, **kwargs)

    return wrapper  # type: ignore[return-value]


def io_times() -> tuple[float, float, float | None]:
    """Seconds of file I/O so far in this process, seconds of library imports made inside readers and writers,
    and the epoch time (s) of the first file access (None: none yet)."""
    return _state["seconds"], _state["import_seconds"], _state["first_epoch_s"]
