"""The log of a workflow job: messages, warnings and the full error, written atomically when the job ends."""

from __future__ import annotations

import contextlib
import io
import logging
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator

from loper_analysis.errors import one_line
from loper_analysis.io.atomic import write_text
from loper_analysis.timing import io_times

__all__ = ["LOG_FORMAT", "PROFILE_VARIABLE", "TIMING_PREFIX", "rule_log", "timing_line", "write_log"]

#: One line per message: time, level, logger name, message.
LOG_FORMAT = "%(asctime)s %(levelname)s %(name)s: %(message)s"
#: Start of the last line of a job's log: where its time went (``benchmarks/rule_times.py`` reads it).
TIMING_PREFIX = "job time:"


def timing_line(end_epoch_s: float | None = None) -> str:
    """The job's time split: wall seconds from its first file access to now, of which file I/O, and the
    library imports made inside readers and writers (start-up, not I/O; :mod:`loper_analysis.timing`)."""
    io_s, import_s, first = io_times()
    end = time.time() if end_epoch_s is None else end_epoch_s
    after_first = 0.0 if first is None else max(end - first, 0.0)
    return f"{TIMING_PREFIX} after_first_io_s={after_first:.3f} io_s={io_s:.3f} library_import_s={import_s:.3f}"


#: Environment variable: when set (to anything but "" or "0"), every job also writes a cProfile of its body
#: next to its log (``{log}.prof``; read it with ``python -m pstats``).
PROFILE_VARIABLE = "LOPER_PROFILE"


def _profiler():
    """A running cProfile when :data:`PROFILE_VARIABLE` asks for one, else None."""
    if os.environ.get(PROFILE_VARIABLE, "") in ("", "0"):
        return None
    import cProfile

    profiler = cProfile.Profile()
    profiler.enable()
    return profiler


def _stop_on_sigterm(signum: int, frame) -> None:
    """SIGTERM as an error: the job's log is written before the process ends."""
    raise SystemExit(
        f"stopped by {signal.Signals(signum).name}: the job was cancelled (scancel, or Snakemake "
        "interrupted), or SLURM ended it at its time limit (resource runtime)"
    )


def _os_error(exc: BaseException) -> str:
    """The OS error behind a failed write, as ``[Errno 28] No space left on device`` (else the error in one line)."""
    seen = set()
    cause: BaseException | None = exc
    while cause is not None and id(cause) not in seen:
        if isinstance(cause, OSError):
            if cause.errno is not None and cause.strerror:
                return f"[Errno {cause.errno}] {cause.strerror}"
            return str(cause) or type(cause).__name__
        seen.add(id(cause))
        cause = cause.__cause__ or cause.__context__
    return one_line(exc)


def _to_stderr(text: str) -> None:
    """Print ``text`` on standard error; a closed or broken standard error is ignored (cleanup never raises)."""
    try:
        sys.stderr.write(text if text.endswith("\n") else text + "\n")
        sys.stderr.flush()
    except Exception:  # noqa: BLE001 - nothing left to tell it to
        pass


def _dump_profile(profiler, path: str | os.PathLike) -> str | None:
    """Write the job's cProfile to ``{path}.prof`` atomically; the problem in one line when it cannot be written."""
    from loper_analysis.io.atomic import staged

    prof = f"{path}.prof"
    try:
        profiler.disable()
        with staged(prof, "profile") as tmp:
            profiler.dump_stats(str(tmp))
    except Exception as exc:  # noqa: BLE001 - a profile is a diagnostic: it never ends the job
        return f"{prof}: could not write the profile: {_os_error(exc)}"
    return None


def write_log(path: str | os.PathLike, text: str) -> str | None:
    """Write a job's log atomically (:func:`loper_analysis.io.atomic.write_text`); never raises.

    A log that cannot be written (a full disk: ``ENOSPC``, a directory that
    cannot be written) leaves the previous log at ``path`` as it was (never a
    0-byte or half-written one). Returns None when the log is written, else
    one line naming the log and the OS error, e.g.
    ``results/logs/x.log: could not write the log: [Errno 28] No space left on device``.
    """
    try:
        write_text(path, text, "log")
    except Exception as exc:  # noqa: BLE001 - reported by the caller in one line
        return f"{path}: could not write the log: {_os_error(exc)}"
    return None


@contextlib.contextmanager
def rule_log(path: str | os.PathLike) -> Iterator[logging.Logger]:
    """Collect the job's log records (INFO and up) and warnings; write them to ``path`` when the job ends.

    Yields the logger ``loper_analysis.rule``. When the body raises an
    error, the error and its traceback are logged, the log is written, and
    the job ends with :class:`SystemExit` carrying the error as one line
    (:func:`loper_analysis.errors.one_line`): Python prints that line on
    standard error and exits with status 1, so Snakemake's console shows the
    cause in one line and points to this file for the traceback. An
    interruption (``KeyboardInterrupt``, ``SystemExit``) is logged and
    propagates unchanged; so is SIGTERM (what ``scancel``, SLURM's time limit
    and an interrupted Snakemake send), turned into a :class:`SystemExit`
    that names it.

    The log of a job that succeeds ends with :func:`timing_line`: with the
    job's benchmark file it splits the job's time into start-up, file I/O and
    compute. A failed job's log ends with its error.

    The log is written atomically (:func:`write_log`) and writing it never
    raises a second error. When it cannot be written (a full disk, a
    directory that cannot be written), the previous log stays as it was, the
    log's text is printed on standard error (the only place left for it) and
    the job fails, with status 1 and one line: a job that succeeded ends with
    ``{path}: could not write the log: [Errno 28] No space left on device``;
    a job that failed ends with its own error's line followed by that one in
    parentheses; an interruption propagates unchanged after the two are
    printed. A job without its log fails rather than succeeds: the log is the
    record of what the job did (its warnings, its time), and a full disk
    would break the next jobs anyway. A profile (:data:`PROFILE_VARIABLE`)
    that cannot be written is a warning in the log, never a failure.

    Workflow scripts import only this function before entering it and
    import their step module inside it, so that even an import error ends
    up in the log.
    """
    buffer = io.StringIO()
    handler = logging.StreamHandler(buffer)
    handler.setFormatter(logging.Formatter(LOG_FORMAT))
    root = logging.getLogger()
    previous_level = root.level
    root.addHandler(handler)
    root.setLevel(logging.INFO)
    logging.captureWarnings(True)
    log = logging.getLogger("loper_analysis.rule")
    failure = None
    unwritten = None
    profiler = _profiler()
    main_thread = threading.current_thread() is threading.main_thread()
    previous_sigterm = signal.signal(signal.SIGTERM, _stop_on_sigterm) if main_thread else None
    try:
        yield log
    except Exception as exc:
        log.exception("%s: %s", type(exc).__name__, exc)
        failure = exc
    except BaseException as exc:
        log.exception("%s: %s", type(exc).__name__, exc)
        raise
    finally:
        # cleanup never raises: an error here would hide the job's own outcome behind a second traceback
        try:
            if main_thread:
                signal.signal(signal.SIGTERM, previous_sigterm)
            if profiler is not None:
                problem = _dump_profile(profiler, path)
                if problem:
                    log.warning("%s", problem)
            logging.captureWarnings(False)
            root.removeHandler(handler)
            root.setLevel(previous_level)
            text = buffer.getvalue()
            if failure is None and not sys.exc_info()[0]:  # a failed job's log ends with its error
                text += timing_line() + "\n"
        except Exception as exc:  # noqa: BLE001 - keep what was collected, say what went wrong
            text = buffer.getvalue() + f"could not finish the log: {one_line(exc)}\n"
        unwritten = write_log(path, text)
        if unwritten is not None:
            _to_stderr(text)
            if sys.exc_info()[0] is not None and failure is None:  # an interruption: it propagates unchanged
                _to_stderr(unwritten)
    if unwritten is not None:
        if failure is not None:
            raise SystemExit(f"{one_line(failure)} (traceback above; {unwritten})") from failure
        raise SystemExit(f"{unwritten} (the log's text is above)")
    if failure is not None:
        raise SystemExit(f"{one_line(failure)} (traceback in {path})") from failure
