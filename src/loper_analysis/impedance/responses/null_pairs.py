"""Null pairs: unperturbed strides paired like perturbed ones, samples of a response's stride-to-stride noise.

* :func:`null_pair_windows` - the null pairs of a subject at one onset, pooled over trials;
* :func:`trial_deviation_rad` and :func:`deviant_trials` - the screen that leaves out a trial whose
  null pairs deviate far more than the other trials' (``docs/null_pairs.md``).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence

import numpy as np

from loper_analysis.checks import number, where
from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.responses.inputs import trial_angles, trial_name, trial_table
from loper_analysis.impedance.responses.matching import match_in_window
from loper_analysis.impedance.responses.sampling import TIME_TOLERANCE_S
from loper_analysis.impedance.responses.windows import (
    ResponseSettings,
    analysis_grid,
    paired_windows,
    pooled_windows,
    window_coordinates,
    window_outliers,
)
from loper_analysis.study_design import PERTURBED_SIDE

__all__ = ["MAX_TRIAL_DEVIATION_RATIO", "null_pair_windows", "trial_deviation_rad", "deviant_trials"]

log = logging.getLogger(__name__)

#: A trial whose typical null-pair deviation exceeds this multiple of the other trials' median is left out.
MAX_TRIAL_DEVIATION_RATIO: float = 3.0


def trial_deviation_rad(differences, rel_time_s, before_s: float, after_s: float) -> float:
    """Typical size (rad) of a trial's null pairs: the median over its pairs of the RMS difference.

    ``differences`` (n_pairs, n_grid, 3): perturbed-minus-matched joint angles (rad) of the trial's
    null pairs on the grid ``rel_time_s`` (s); the RMS runs over the analysis window
    ``-before_s .. after_s`` and hip, knee and ankle. NaN without a pair.
    """
    d = np.asarray(differences, dtype=float)
    rel = np.asarray(rel_time_s, dtype=float)
    if d.ndim != 3 or d.shape[1] != rel.size:
        raise LoperInputError(f"differences must have shape (n_pairs, {rel.size}, k), got {d.shape}")
    if d.shape[0] == 0:
        return float("nan")
    sel = (rel >= -before_s - TIME_TOLERANCE_S) & (rel <= after_s + TIME_TOLERANCE_S)
    return float(np.median(np.sqrt(np.mean(d[:, sel] ** 2, axis=(1, 2)))))


def deviant_trials(deviation_rad: dict, max_ratio: float = MAX_TRIAL_DEVIATION_RATIO, source: str = "") -> dict:
    """Trials whose null pairs deviate far more than the other trials': ``{name: reason}``.

    ``deviation_rad``: trial name -> :func:`trial_deviation_rad` (NaN: no null pair, not judged).
    A trial is deviant when its value exceeds ``max_ratio`` times the median of the other trials'
    values; at least one other trial with null pairs is needed (the trial of least deviation is never
    left out). ``max_ratio`` (>= 1) None: no screen.
    """
    if max_ratio is None:
        return {}
    ratio = number("max_ratio", max_ratio, source, minimum=1.0)
    out = {}
    judged = {k: float(v) for k, v in deviation_rad.items() if np.isfinite(v)}
    for name, value in judged.items():
        others = [v for k, v in judged.items() if k != name]
        if not others:
            continue
        typical = float(np.median(others))
        if value > ratio * typical:
            times = f"{value / typical:.3g} times" if typical > 0 else "more than"
            out[name] = (
                f"trial {name} left out of the null pairs: its null pairs deviate by {value:.3g} rad "
                f"(median RMS), {times} the other trials' {typical:.3g} rad (limit {ratio:g} times)"
            )
    return out


def null_pair_windows(
    trials: Sequence[Mapping],
    onset_ms: float,
    settings: ResponseSettings = ResponseSettings(),
    *,
    side: str = PERTURBED_SIDE,
    source: str = "",
    max_trial_ratio: float | None = MAX_TRIAL_DEVIATION_RATIO,
) -> dict:
    """Unperturbed strides paired like perturbed ones: samples of a response's stride-to-stride noise.

    Every unperturbed stride of every trial is treated as if perturbed at
    ``onset_ms`` after its toe-off, matched by the study's rule among the
    other unperturbed strides of its trial (:func:`match_unperturbed` with
    ``null_pairs``), windowed like :func:`subject_onset_response` does and
    judged by the same IQR rule (:func:`window_outliers`). What its
    difference shows is what a perturbed-minus-matched difference holds
    besides the response: the residual of the matching. Trials need
    ``name``, ``angles`` and ``strides`` (frames, :mod:`loper_analysis.impedance.responses.inputs`);
    they may include trials of other onsets and unperturbed walking.
    ``settings`` as for :func:`subject_onset_response` (``min_strides`` unused).

    Before the pairs are pooled, a trial whose null pairs deviate more than
    ``max_trial_ratio`` times as much as the other trials' (:func:`deviant_trials`
    on :func:`trial_deviation_rad`) is left out with a logged warning naming it:
    one bad trial must not shift the null pairs of every onset. None: every
    trial is pooled.

    Returns
    -------
    dict
        ``time_s`` (n_grid,) relative to the onset (s); per kept pair
        ``q_perturbed``, ``q_unperturbed`` (n_pairs, n_grid, 4): [pelvis_x (m),
        thigh, shank, foot (rad)]; ``pelvis_angle_perturbed_rad``,
        ``pelvis_angle_unperturbed_rad`` (n_pairs, n_grid); ``n_pairs`` and
        ``n_outliers``; ``trial_deviation_rad`` (trial name -> :func:`trial_deviation_rad`)
        and ``trials_left_out`` (trial name -> reason).
    """
    analysis = analysis_grid(trials, onset_ms, settings, side, source)
    _, before, after, _, start, grid = analysis
    rate_hz, whisker, max_fraction = settings.rate_hz, settings.whisker, settings.max_fraction
    parts, deviation = [], {}
    for k, trial in enumerate(trials):
        name = trial_name(trial, k, ("angles", "strides"), source)
        if name in deviation:
            raise LoperInputError(f"{where(source)}trial name {name!r} appears twice; names must be unique")
        t, columns, _ = trial_angles(trial, name, side)
        strides, where_s = trial_table(trial, "strides", name)
        matches = match_in_window(t, columns["joints"], strides, analysis, where_s, null_pairs=True)
        part = paired_windows(t, columns, matches, start, after, rate_hz, source=where_s)
        deviation[name] = trial_deviation_rad(part["joints"][0] - part["joints"][1], grid, before, after)
        parts.append(part)
    label = f"{source} null pairs, onset {onset_ms:g} ms" if source else f"null pairs, onset {onset_ms:g} ms"
    left_out = deviant_trials(deviation, max_trial_ratio, source)
    for why in left_out.values():
        log.warning("%s: %s", label, why)
    parts = [w for w, name in zip(parts, deviation) if name not in left_out]
    win = pooled_windows(parts)
    jp, ju = win["joints"]
    keep = ~window_outliers(jp - ju, grid, before, after, whisker, max_fraction, JOINTS, label)["removed"].to_numpy()
    out: dict = {"time_s": grid}
    for what, i in (("perturbed", 0), ("unperturbed", 1)):
        j, pel, x = (win[key][i][keep] for key in ("joints", "pelvis_angle", "pelvis_x"))
        out[f"q_{what}"] = window_coordinates(j, pel, x)
        out[f"pelvis_angle_{what}_rad"] = pel
    out["n_pairs"], out["n_outliers"] = int(keep.sum()), int((~keep).sum())
    out["trial_deviation_rad"], out["trials_left_out"] = deviation, left_out
    log.info("%s: %d null pairs kept, %d outliers", label, out["n_pairs"], out["n_outliers"])
    return out
