"""The log of a workflow job: messages, warnings and the full error, written atomically when the job ends."""

from __future__ import annotations

import contextlib
import io
import logging
import os
from collections.abc import Iterator

from ..errors import one_line
from ..io.atomic import write_text

__all__ = ["LOG_FORMAT", "rule_log"]

#: One line per message: time, level, logger name, message.
LOG_FORMAT = "%(asctime)s %(levelname)s %(name)s: %(message)s"


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
    propagates unchanged.

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
    try:
        yield log
    except Exception as exc:
        log.exception("%s: %s", type(exc).__name__, exc)
        failure = exc
    except BaseException as exc:
        log.exception("%s: %s", type(exc).__name__, exc)
        raise
    finally:
        logging.captureWarnings(False)
        root.removeHandler(handler)
        root.setLevel(previous_level)
        write_text(path, buffer.getvalue(), "log")
    if failure is not None:
        raise SystemExit(f"{one_line(failure)} (traceback in {path})") from failure
