"""Parts of one onset's fit (:func:`loper_analysis.impedance.identification.impedance.fit_onset`).

* :func:`mean_response_window` - the identification window of the onset's mean response;
* :func:`force_keywords` - the rods' forces as the window takes them;
* :func:`fit_null_pairs` - the null pairs whose deviation weights the fit's prediction errors;
* :func:`fit_curves` - the measured and model responses of the fit;
* :func:`force_table` - the mean rod forces the fit received.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS
from loper_analysis.impedance.identification.fit import ImpedanceFit
from loper_analysis.impedance.identification.window import PreparedWindow, prepare_window
from loper_analysis.impedance.responses import ResponseSettings, null_pair_windows
from loper_analysis.swing_leg.dynamics import SegmentParameters

__all__ = [
    "FORCE_COLUMNS",
    "SHANK_FORCE_COLUMNS",
    "mean_response_window",
    "force_keywords",
    "fit_null_pairs",
    "fit_curves",
    "force_table",
]


def force_keywords(perturbed_n, unperturbed_n) -> dict:
    """:func:`~loper_analysis.impedance.identification.prepare_window`'s force keywords of the rods' forces
    (N, (k, 2): the thigh rod's; (k, 4): the thigh rod's, then a second rod's at the shank, as the responses
    carry them)."""
    fp, fu = np.asarray(perturbed_n, dtype=float), np.asarray(unperturbed_n, dtype=float)
    if fp.shape[-1] == 2:
        return {"force_unperturbed_n": unperturbed_n, "force_perturbed_n": perturbed_n}
    return {
        "force_unperturbed_n": fu[..., :2],
        "force_perturbed_n": fp[..., :2],
        "shank_force_unperturbed_n": fu[..., 2:],
        "shank_force_perturbed_n": fp[..., 2:],
    }


def mean_response_window(series: Mapping, params: SegmentParameters, options: Mapping) -> PreparedWindow:
    """The identification window of the mean response ``series`` (onset at 0 s; ``options``: the window keywords
    of :func:`loper_analysis.impedance.identification.prepare_window`)."""
    return prepare_window(
        series["time_s"],
        series["q_unperturbed"],
        series["q_perturbed"],
        params,
        0.0,
        **force_keywords(series["force_perturbed_n"], series["force_unperturbed_n"]),
        force_time_s=series.get("force_time_s"),
        pelvis_angle_unperturbed_rad=series["pelvis_angle_unperturbed_rad"],
        pelvis_angle_perturbed_rad=series["pelvis_angle_perturbed_rad"],
        **options,
    )


def fit_null_pairs(
    inputs: Sequence[Mapping],
    null_trials: Sequence[Mapping],
    series: Mapping,
    onset_ms: int,
    response: ResponseSettings,
    max_trial_ratio: float | None,
    subject: str,
) -> dict:
    """The null pairs of the fit: the conditional counterfactual's leave-one-out predictions (``series``), or the
    unperturbed strides of ``null_trials`` (the onset's ``inputs`` when empty) matched as if perturbed
    (:func:`loper_analysis.impedance.responses.null_pair_windows`; a trial whose null pairs deviate more than
    ``max_trial_ratio`` times the other trials' left out, None: never)."""
    loaded = {i["name"]: i for i in inputs}
    pool = [loaded.get(str(t.get("name")), t) for t in null_trials] or inputs
    if response.counterfactual == "conditional":  # the candidates' leave-one-out predictions
        return series["null_pairs"]
    return null_pair_windows(pool, onset_ms, response, source=subject, max_trial_ratio=max_trial_ratio)


def fit_curves(fit: ImpedanceFit, averaging: np.ndarray) -> pd.DataFrame:
    """The measured and model joint-angle responses of a fit (rad, ``averaging`` (n, 3) added back to both):
    ``time_s``, ``{joint}_measured_rad``, ``{joint}_model_rad``."""
    return pd.DataFrame(
        {
            "time_s": fit.time_s,
            **{f"{j}_measured_rad": fit.measured[:, i] + averaging[:, i] for i, j in enumerate(JOINTS)},
            **{f"{j}_model_rad": fit.model[:, i] + averaging[:, i] for i, j in enumerate(JOINTS)},
        }
    )


#: Columns of :func:`force_table`.
FORCE_COLUMNS: tuple[str, ...] = (
    "time_s",
    "force_perturbed_x_n",
    "force_perturbed_y_n",
    "force_unperturbed_x_n",
    "force_unperturbed_y_n",
)
#: Columns :func:`force_table` adds for a second rod at the shank.
SHANK_FORCE_COLUMNS: tuple[str, ...] = tuple(f"shank_{c}" for c in FORCE_COLUMNS[1:])


def force_table(series: Mapping) -> pd.DataFrame:
    """The mean rod forces of a response as the fit receives them (columns :data:`FORCE_COLUMNS`).

    ``time_s`` relative to the onset (s): ``series["force_time_s"]`` (the robot rate) when the response
    carries it, else the response's grid; the perturbed and matched unperturbed mean force vectors (N, world x/y);
    with a second rod at the shank its vectors after them (:data:`SHANK_FORCE_COLUMNS`).
    """
    t = series.get("force_time_s", series["time_s"])
    fp, fu = series["force_perturbed_n"], series["force_unperturbed_n"]
    if np.shape(fp)[-1] == 4:
        shank = dict(zip(SHANK_FORCE_COLUMNS, (fp[:, 2], fp[:, 3], fu[:, 2], fu[:, 3])))
        return force_table({**series, "force_perturbed_n": fp[:, :2], "force_unperturbed_n": fu[:, :2]}).assign(**shank)
    return pd.DataFrame(
        {
            "time_s": t,
            "force_perturbed_x_n": fp[:, 0],
            "force_perturbed_y_n": fp[:, 1],
            "force_unperturbed_x_n": fu[:, 0],
            "force_unperturbed_y_n": fu[:, 1],
        },
        columns=list(FORCE_COLUMNS),
    )
