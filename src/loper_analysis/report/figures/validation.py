"""The figure of the validation study: estimation errors per parameter, without and with noise."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pandas as pd

from loper_analysis.constants import PARAMETER_UNITS, PARAMETERS
from loper_analysis.impedance.identification.validation import CONDITIONS
from loper_analysis.report.figures import pyplot

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["validation_errors_figure"]


def validation_errors_figure(errors: pd.DataFrame) -> Figure:
    """Box plots of the estimation error (estimate − true) per parameter, one row per condition.

    ``errors``: ``condition``, ``combination``, ``parameter``, ``error``
    (``results/validation/errors.tsv``). Returns the figure.
    """
    plt = pyplot()
    fig, axes = plt.subplots(2, 6, figsize=(13, 5.5), constrained_layout=True)
    for r, condition in enumerate(CONDITIONS):
        sub = errors[errors.condition == condition]
        for c, name in enumerate(PARAMETERS):
            ax = axes[r, c]
            e = sub.loc[sub.parameter == name, "error"].to_numpy()
            if e.size:
                ax.boxplot(e, widths=0.6, showfliers=True, flierprops={"markersize": 2})
            ax.axhline(0, color="0.6", lw=0.8)
            ax.set_xticks([])
            if r == 0:
                ax.set_title(name.replace("_", " "))
            if c == 0:
                ax.set_ylabel(f"{condition.replace('_', ' ')}\nerror")
            ax.set_xlabel(PARAMETER_UNITS[name], fontsize=8)
    fig.suptitle(f"Validation study: estimate − true over {errors.combination.nunique()} K/D combinations")
    return fig
