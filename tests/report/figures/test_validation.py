"""The validation study's figure (loper_analysis.report.figures.validation): one box per condition and
parameter, drawn from that cell's errors alone."""

from __future__ import annotations

import numpy as np
import pandas as pd

from loper_analysis.constants import PARAMETER_UNITS, PARAMETERS
from loper_analysis.impedance.identification.validation import CONDITIONS
from loper_analysis.report.figures import pyplot
from loper_analysis.report.figures.validation import validation_errors_figure


def _errors() -> pd.DataFrame:
    """Errors 0..4 above an offset of its own for each condition and parameter, over 5 combinations; the noisy
    ankle damping left out."""
    rows = [
        (condition, k, name, 10.0 * (r + 1) + c + k)
        for r, condition in enumerate(CONDITIONS)
        for c, name in enumerate(PARAMETERS)
        for k in range(5)
        if (condition, name) != ("noise", "D_ankle")
    ]
    return pd.DataFrame(rows, columns=["condition", "combination", "parameter", "error"])


def _levels(ax) -> set[float]:
    """The heights of the horizontal lines of an axes (the box's quartiles, median and caps; the zero line)."""
    return {float(y) for line in ax.lines for y in np.unique(line.get_ydata())}


def test_each_box_holds_its_own_cells_quartiles_median_and_extremes():
    fig = validation_errors_figure(_errors())
    try:
        axes = np.array(fig.axes).reshape(2, 6)
        for r, condition in enumerate(CONDITIONS):
            for c, name in enumerate(PARAMETERS):
                ax = axes[r, c]
                if (condition, name) == ("noise", "D_ankle"):
                    assert _levels(ax) == {0.0}  # no box, only the zero line
                    continue
                offset = 10.0 * (r + 1) + c
                assert _levels(ax) == {0.0, *(offset + np.arange(5.0))}, (condition, name)
                assert ax.get_xlabel() == PARAMETER_UNITS[name]
        assert [ax.get_title() for ax in axes[0]] == ["K hip", "D hip", "K knee", "D knee", "K ankle", "D ankle"]
        assert [ax.get_ylabel() for ax in axes[:, 0]] == ["no noise\nerror", "noise\nerror"]
        assert fig._suptitle.get_text() == "Validation study: estimate − true over 5 K/D combinations"
    finally:
        pyplot().close(fig)
