"""Figures of the pipeline, drawn with matplotlib from arrays and tables; every function returns the figure.

* :mod:`.impedance` - responses, fit vs data, K and D per onset;
* :mod:`.transparency` - the gait cycle with and without the device;
* :mod:`.device` - Bode plot and step responses of the force controller;
* :mod:`.validation` - estimation errors of the validation study.

The caller writes a figure with :func:`loper_analysis.io.atomic.write_figure`
and closes it (``matplotlib.pyplot.close``).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

__all__ = ["pyplot", "closed_on_error"]


def pyplot():
    """``matplotlib.pyplot`` on the non-interactive Agg backend (no screen needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


@contextlib.contextmanager
def closed_on_error(figure) -> Iterator[None]:
    """Close ``figure`` and re-raise when drawing it fails (a half-drawn figure is never returned)."""
    try:
        yield
    except BaseException:
        pyplot().close(figure)
        raise
