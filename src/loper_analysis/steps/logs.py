"""The log of a workflow job: messages, warnings and the full error, written atomically when the job ends."""

from __future__ import annotations

import contextlib
import io
import logging
import os
from collections.abc import Iterator

from ..io.atomic import write_text

__all__ = ["LOG_FORMAT", "rule_log"]

#: One line per message: time, level, logger name, message.
LOG_FORMAT = "%(asctime)s %(levelname)s %(name)s: %(message)s"


@contextlib.contextmanager
def rule_log(path: str | os.PathLike) -> Iterator[logging.Logger]:
    """Collect the job's log records (INFO and up) and warnings; write them to ``path`` when the job ends.

    Yields the logger ``loper_analysis.rule``. When the body raises, the
    error and its traceback are logged before the log is written and the
    error propagates (Snakemake then prints its one-line message and points
    to this file).
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
    try:
        yield log
    except BaseException as exc:
        log.error("%s: %s", type(exc).__name__, exc, exc_info=True)
        raise
    finally:
        logging.captureWarnings(False)
        root.removeHandler(handler)
        root.setLevel(previous_level)
        write_text(path, buffer.getvalue(), "log")
