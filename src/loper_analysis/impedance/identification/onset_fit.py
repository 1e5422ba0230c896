"""Parts of one onset's fit (:func:`loper_analysis.impedance.identification.impedance.fit_onset`).

* :func:`mean_response_window` - the identification window of the onset's mean response;
* :func:`force_keywords` - the rods' forces as the window takes them;
* :func:`fit_null_pairs` - the null pairs whose deviation weights the fit's prediction errors;
* :func:`fit_curves` - the measured and model responses of the fit.
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

__all__ = ["mean_response_window", "force_keywords", "fit_null_pairs", "fit_curves"]


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
