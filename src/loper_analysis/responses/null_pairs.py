"""Null pairs: unperturbed strides paired like perturbed ones, samples of a response's stride-to-stride noise."""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence

import numpy as np

from ..constants import JOINTS
from ..dynamics import segment_coordinates
from .inputs import trial_angles, trial_name, trial_table
from .matching import match_unperturbed
from .windows import ResponseSettings, analysis_grid, paired_windows, window_outliers

__all__ = ["null_pair_windows"]

log = logging.getLogger(__name__)


def null_pair_windows(
    trials: Sequence[Mapping],
    onset_ms: float,
    settings: ResponseSettings = ResponseSettings(),
    *,
    side: str = "left",
    source: str = "",
) -> dict:
    """Unperturbed strides paired like perturbed ones: samples of a response's stride-to-stride noise.

    Every unperturbed stride of every trial is treated as if perturbed at
    ``onset_ms`` after its toe-off, matched by the study's rule among the
    other unperturbed strides of its trial (:func:`match_unperturbed` with
    ``null_pairs``), windowed like :func:`subject_onset_response` does and
    judged by the same IQR rule (:func:`window_outliers`). What its
    difference shows is what a perturbed-minus-matched difference holds
    besides the response: the residual of the matching. Trials need
    ``name``, ``angles`` and ``strides`` (frames, :mod:`loper_analysis.responses.inputs`);
    they may include trials of other onsets and unperturbed walking.
    ``settings`` as for :func:`subject_onset_response` (``min_strides`` unused).

    Returns
    -------
    dict
        ``time_s`` (n_grid,) relative to the onset (s); per kept pair
        ``q_perturbed``, ``q_unperturbed`` (n_pairs, n_grid, 4): [pelvis_x (m),
        thigh, shank, foot (rad)]; ``pelvis_angle_perturbed_rad``,
        ``pelvis_angle_unperturbed_rad`` (n_pairs, n_grid); ``n_pairs`` and
        ``n_outliers``.
    """
    onset_s, before, after, initial, start, grid = analysis_grid(trials, onset_ms, settings, side, source)
    rate_hz, whisker, max_fraction = settings.rate_hz, settings.whisker, settings.max_fraction
    parts = []
    for k, trial in enumerate(trials):
        name = trial_name(trial, k, ("angles", "strides"), source)
        t, columns, _ = trial_angles(trial, name, side)
        strides, where_s = trial_table(trial, "strides", name)
        matches = match_unperturbed(t, columns["joints"], strides, before, source=where_s, span_s=(start, after),
                                    onset_after_toe_off_s=onset_s, window_after_s=after, missing="drop",
                                    null_pairs=True)
        parts.append(paired_windows(t, columns, matches, start, after, rate_hz, source=where_s))
    win = {key: tuple(np.concatenate([w[key][i] for w in parts]) for i in range(2)) for key in parts[0]}
    jp, ju = win["joints"]
    label = f"{source} null pairs, onset {onset_ms:g} ms" if source else f"null pairs, onset {onset_ms:g} ms"
    keep = ~window_outliers(jp - ju, grid, before, after, whisker, max_fraction, JOINTS, label)["removed"].to_numpy()
    out: dict = {"time_s": grid}
    for what, i in (("perturbed", 0), ("unperturbed", 1)):
        j, pel, x = (win[key][i][keep] for key in ("joints", "pelvis_angle", "pelvis_x"))
        out[f"q_{what}"] = segment_coordinates(j.reshape(-1, 3), pel.reshape(-1), x.reshape(-1)).reshape(
            j.shape[:2] + (4,))
        out[f"pelvis_angle_{what}_rad"] = pel
    out["n_pairs"], out["n_outliers"] = int(keep.sum()), int((~keep).sum())
    log.info("%s: %d null pairs kept, %d outliers", label, out["n_pairs"], out["n_outliers"])
    return out
