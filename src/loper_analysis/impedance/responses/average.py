"""The mean perturbation response of one subject at one onset, over the subject's trials.

The averaged pair is what the identification
(:func:`loper_analysis.impedance.identification.prepare_window`) fits.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from loper_analysis.checks import bool_column, number, where
from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.outliers import check_enough_strides
from loper_analysis.gait.resampling import window_times_s
from loper_analysis.impedance.responses.conditional import (
    CandidatePool,
    conditional_null_pair_windows,
    conditional_null_pairs,
    conditional_windows,
    covariance_scale,
    unit_scatter_variance,
)
from loper_analysis.impedance.responses.inputs import trial_angles, trial_name, trial_table
from loper_analysis.impedance.responses.matching import match_in_window, stride_table, too_short
from loper_analysis.impedance.responses.native_force import (
    native_force_rate_hz,
    native_force_windows,
    rod_magnitudes,
)
from loper_analysis.impedance.responses.sampling import TIME_TOLERANCE_S
from loper_analysis.impedance.responses.windows import (
    AnalysisGrid,
    ResponseSettings,
    analysis_grid,
    paired_windows,
    pooled_windows,
    window_coordinates,
    window_outliers,
)
from loper_analysis.study_design import PERTURBED_SIDE

__all__ = ["COUNT_COLUMNS", "mean_and_sd", "subject_onset_response"]

log = logging.getLogger(__name__)

#: Columns of the counts table returned by :func:`subject_onset_response`.
COUNT_COLUMNS: tuple[str, ...] = (
    "trial",
    "n_perturbed",
    "n_too_short",
    "n_no_match",
    "n_outliers",
    "n_kept",
    "status",
    "reason",
)


def mean_and_sd(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and SD (ddof 1) over axis 0; NaN where too few rows (no warnings)."""
    shape = a.shape[1:]
    mean = a.mean(axis=0) if a.shape[0] else np.full(shape, np.nan)
    sd = a.std(axis=0, ddof=1) if a.shape[0] >= 2 else np.full(shape, np.nan)
    return mean, sd


def _trial_inputs(trial: Mapping, k: int, side: str, source: str):
    """Checked frame data of one trial: name, stride-table label, time, columns to window, stride table."""
    name = trial_name(trial, k, ("angles", "strides", "force", "force_direction"), source)
    t, columns, where_a = trial_angles(trial, name, side)
    strides, where_s = trial_table(trial, "strides", name)
    force, where_f = trial_table(trial, "force", name, ("time_s", "force_measured_n"))
    tf = force["time_s"].to_numpy(float)
    if tf.shape != t.shape or not np.allclose(tf, t, rtol=0.0, atol=1e-6):
        raise LoperInputError(
            f"{where_f}: time_s ({tf.size} frames) differs from the angles' frames in {where_a} ({t.size} frames)"
        )
    direction = np.asarray(trial["force_direction"], dtype=float)
    if direction.ndim != 2 or direction.shape[0] != t.size or direction.shape[1] not in (2, 4):
        raise LoperInputError(
            f"{name}: force_direction must have shape ({t.size}, 2), or ({t.size}, 4) with a second rod, "
            f"got {direction.shape}"
        )
    for r in range(direction.shape[1] // 2):
        with np.errstate(invalid="ignore"):
            off = np.flatnonzero(np.abs(np.hypot(direction[:, 2 * r], direction[:, 2 * r + 1]) - 1.0) > 1e-6)
        if off.size:
            i = int(off[0])
            raise LoperInputError(
                f"{name}: force_direction at frame {i} (t = {t[i]:.4f} s) is not a unit vector: "
                f"{direction[i, 2 * r : 2 * r + 2].tolist()}"
            )
    magnitude = rod_magnitudes(force, direction, where_f)
    columns["force"] = magnitude if magnitude.ndim == 1 else magnitude[:, 0]
    if magnitude.ndim == 1:
        columns["force_vector"] = magnitude[:, None] * direction  # NaN frames stay NaN
    else:  # each rod's force along its own direction, side by side
        columns["force_vector"] = np.repeat(magnitude, 2, axis=1) * direction
    native = None
    if trial.get("force_native") is not None:
        native, where_n = trial_table(trial, "force_native", name, ("time_s", "force_measured_n"))
        native = (native, where_n, direction)
    return name, where_s, t, columns, strides, native


def _conditional(pool, win, force_pairs, pair_table, delays_s, analysis, settings, native_rate, label) -> dict:
    """The perturbed pairs with the conditional counterfactual as their unperturbed side.

    Pairs without a prediction (too few candidates) are dropped and counted per trial (``unpredicted``);
    the pair table's ``matched_stride`` is -1, ``matched_anchor_s`` NaN and ``rmsd_rad`` the RMS of the
    perturbed minus predicted joint angles over the matching span. Also the candidates' null pairs at the
    nominal onset (``null``, :func:`conditional_null_pairs`, whose penalty the predictions use) and each
    pair's weights over the candidates (``weights``).
    """
    onset_s, before, after, _, start, grid = analysis
    candidates = CandidatePool(pool, start, after, settings.rate_hz)
    native_grid = None if native_rate is None else window_times_s(-start, after, native_rate)
    labels = [f"{tr}: perturbed stride {s}" for tr, s in zip(pair_table["trial"], pair_table["stride"])]
    try:
        null = conditional_null_pairs(candidates, onset_s, source=label)
    except LoperInputError as err:  # too few unperturbed strides: no pair has a counterfactual
        log.warning("%s", err)
        null, missing = None, [str(err)] * len(pair_table)
        predicted = {k: np.full_like(p, np.nan) for k, (p, _) in win.items()}
        native = None if force_pairs is None else np.full_like(force_pairs[0], np.nan)
        weights = np.zeros((len(pair_table), candidates.size))
    else:
        predicted, native, weights, missing = conditional_windows(
            candidates,
            delays_s,
            {k: win[k][0] for k in ("joints", "pelvis_angle")},
            null["alpha"],
            native_grid,
            label,
            labels,
        )
    ok = np.array([not m for m in missing], dtype=bool)
    for why in filter(None, missing):
        log.info("%s", why)
    unpredicted = pair_table.loc[~ok, "trial"].value_counts().to_dict()
    win = {k: (p[ok], predicted[k][ok]) for k, (p, _) in win.items()}
    if force_pairs is not None:
        force_pairs = (force_pairs[0][ok], native[ok])
    span = (grid >= -before - TIME_TOLERANCE_S) & (grid <= TIME_TOLERANCE_S)
    diff = win["joints"][0][:, span] - win["joints"][1][:, span]
    pair_table = pair_table[ok].reset_index(drop=True)
    pair_table = pair_table.assign(
        matched_stride=-1, matched_anchor_s=np.nan, rmsd_rad=np.sqrt(np.mean(diff**2, axis=(1, 2)))
    )
    return {
        "win": win,
        "force_pairs": force_pairs,
        "pair_table": pair_table,
        "unpredicted": unpredicted,
        "null": null,
        "weights": weights[ok],
    }


def subject_onset_response(
    trials: Sequence[Mapping],
    onset_ms: float,
    settings: ResponseSettings = ResponseSettings(),
    *,
    side: str = PERTURBED_SIDE,
    method: str = "cubic",
    candidate_within_swing: bool = False,
    source: str = "",
) -> tuple[pd.DataFrame, pd.DataFrame, dict]:
    """Mean perturbation response of one subject at one onset, over the subject's trials.

    With ``settings`` (:class:`~loper_analysis.impedance.responses.windows.ResponseSettings`)
    ``before``, ``after`` and ``initial``: per trial, perturbed strides that
    are :func:`too_short` for ``onset_ms`` and ``after`` are dropped; the
    others are matched within the trial (:func:`match_unperturbed` on hip,
    knee and ankle of ``side`` over ``before``; candidates must cover the
    whole window); windows from ``-(initial + before)`` to ``after`` around
    the onset are taken (:func:`paired_windows`). The pairs of all trials are
    pooled, judged by :func:`window_outliers` on ``-before .. after``, and
    the kept pairs averaged. Status ``too_few_strides`` (and a
    :class:`loper_analysis.errors.TooFewStridesWarning` for the total) when
    fewer than ``settings.min_strides`` pairs are kept.

    Parameters
    ----------
    trials : sequence of mapping
        One per trial of this onset: ``name``, ``angles``, ``strides``,
        ``force`` and ``force_direction`` (:mod:`loper_analysis.impedance.responses.inputs`),
        optionally ``force_native`` (``time_s``, ``force_measured_n`` at the
        robot rate, mocap clock) in every trial or in none.
    onset_ms : float
        Nominal onset after toe-off, ms (e.g. 300).
    settings : ResponseSettings
        Windows, grid rate, IQR rule and fewest kept pairs.
    side : {"left", "right"}
        Swing leg of the joint-angle columns.
    method : {"cubic", "linear"}
        Interpolation of :func:`paired_windows`.
    candidate_within_swing : bool
        See :func:`match_unperturbed`.
    source : str
        Name of the subject, quoted in messages.

    Returns
    -------
    response : pandas.DataFrame
        One row per grid sample: ``time_s`` (relative to onset, s);
        ``{hip,knee,ankle}_rad_mean`` / ``_sd`` - perturbed minus matched
        unperturbed angle (rad, SD ddof 1); ``force_n_mean`` / ``force_n_sd``
        - perturbed minus unperturbed measured force (N);
        ``{joint}_perturbed_rad_mean``, ``{joint}_unperturbed_rad_mean``
        (rad); ``force_perturbed_n_mean``, ``force_unperturbed_n_mean`` (N);
        ``n_pairs`` (kept pairs); ``analysis_window`` (bool, inside
        ``-before_s .. after_s``). NaN where no (mean) or one (SD) pair is kept.
    counts : pandas.DataFrame
        Columns :data:`COUNT_COLUMNS`, one row per trial and a row ``total``:
        perturbed strides, too short, without match, outliers, kept pairs,
        ``status`` (``ok`` | ``too_few_strides``: ``n_kept < min_strides``) and
        ``reason``. ``attrs["pairs"]``: one row per pair (``trial``,
        ``stride``, ``matched_stride``, ``onset_s``, ``matched_anchor_s``,
        ``rmsd_rad``, ``removed``, ``reason``); ``attrs["outliers_judged"]``;
        ``attrs["longest_swing_after_onset_s"]``: the most swing time any
        perturbed stride leaves after its onset (s; the longest
        ``window_after_s`` that keeps a stride, NaN without perturbed strides).
    series : dict
        Means over kept pairs on the grid, named like the arguments of
        :func:`loper_analysis.impedance.identification.prepare_window`: ``time_s``
        (n_grid,), ``onset_s`` (0.0), ``q_unperturbed`` / ``q_perturbed``
        (n_grid, 4): [pelvis_x (m), thigh, shank, foot (rad)] from
        :func:`loper_analysis.swing_leg.dynamics.segment_coordinates`,
        ``pelvis_angle_unperturbed_rad`` / ``pelvis_angle_perturbed_rad``
        (n_grid,), ``force_unperturbed_n`` / ``force_perturbed_n`` (n_grid, 2):
        ``force_measured_n * force_direction`` (N, world x/y). When the trials
        hold ``force_native`` (the force table at the robot log's rate,
        :mod:`loper_analysis.impedance.responses.native_force`), the forces are the means
        at that rate instead, (k, 2) at ``force_time_s`` (k,) relative to the
        onset (the ``force_time_s`` of ``prepare_window``); plus
        ``window_before_s``, ``window_after_s``, ``initial_state_span_s`` and
        ``n_pairs``; ``pairs``: the kept pairs one by one, in the format of
        :func:`loper_analysis.impedance.responses.null_pair_windows` (``time_s``,
        ``q_perturbed``, ``q_unperturbed`` (n_pairs, n_grid, 4), the pelvis
        angles (n_pairs, n_grid), ``n_pairs``). Arrays are NaN when no pair is kept.

    Raises
    ------
    LoperInputError
        Bad inputs or settings (naming the trial/file, column and value),
        duplicate trial names.
    """
    analysis = analysis_grid(trials, onset_ms, settings, side, source)
    _, before, after, initial, _, grid = analysis
    min_n = int(number("min_strides", settings.min_strides, source, minimum=0.0))
    whisker, max_fraction = settings.whisker, settings.max_fraction

    found = _trial_windows(trials, analysis, settings, side, method, candidate_within_swing, source)
    per_trial, pairs, native_rate = found["per_trial"], found["pairs"], found["native_rate"]
    win = pooled_windows(found["windows"])
    label = f"{source} onset {onset_ms:g} ms" if source else f"onset {onset_ms:g} ms"
    pair_table = _pair_table(pairs)
    force_pairs = None
    if native_rate is not None:
        force_pairs = tuple(np.concatenate([w[i] for w in found["force_windows"]]) for i in range(2))
    conditional = None
    if settings.counterfactual == "conditional":
        delays = pair_table["onset_s"].to_numpy(float) - np.concatenate([m["toe_off_s"].to_numpy(float) for m in pairs])
        conditional = _conditional(
            found["pool"], win, force_pairs, pair_table, delays, analysis, settings, native_rate, label
        )
        win, force_pairs, pair_table = conditional["win"], conditional["force_pairs"], conditional["pair_table"]
        for rec in per_trial:
            rec["n_no_match"] += conditional["unpredicted"].get(rec["trial"], 0)
    joints_p, joints_u = win["joints"]
    verdict = window_outliers(joints_p - joints_u, grid, before, after, whisker, max_fraction, JOINTS, label)
    pair_table = pair_table.assign(removed=verdict["removed"].to_numpy(), reason=verdict["reason"].to_numpy())
    keep = ~pair_table["removed"].to_numpy(bool)
    n_pairs = int(keep.sum())

    rows = _count_rows(per_trial, pair_table, verdict, min_n, before, after)
    counts = _counts_table(rows, pair_table, verdict, found["rooms"], onset_ms, source)
    check_enough_strides(n_pairs, label or "perturbation response", min_n)
    total = rows[-1]
    log.info(
        "%s: %d perturbed, %d too short, %d without match, %d outliers, %d kept",
        label,
        total["n_perturbed"],
        total["n_too_short"],
        total["n_no_match"],
        total["n_outliers"],
        total["n_kept"],
    )

    kept = {key: (p[keep], u[keep]) for key, (p, u) in win.items()}
    response = _response_table(kept, n_pairs, analysis, onset_ms, source)
    series = _mean_series(kept, n_pairs, force_pairs, keep, analysis, native_rate)
    if conditional is not None and conditional["null"] is not None:
        series["null_pairs"], weights = _null_pair_series(conditional, keep, analysis, settings, label)
        series["pairs"].update(weights)
    series.update(
        {"window_before_s": before, "window_after_s": after, "initial_state_span_s": initial, "n_pairs": n_pairs}
    )
    return response, counts, series


def _trial_windows(
    trials: Sequence[Mapping],
    analysis: AnalysisGrid,
    settings: ResponseSettings,
    side: str,
    method: str,
    candidate_within_swing: bool,
    source: str,
) -> dict:
    """The perturbed strides of every trial matched and cut into windows (:func:`subject_onset_response`).

    Returns
    -------
    dict
        ``per_trial``: per trial its name and counts of perturbed, too short and unmatched strides;
        ``pairs``: per trial its match table (:func:`match_in_window`) with a ``trial`` column;
        ``windows``: per trial its :func:`paired_windows`; ``rooms``: per perturbed stride the swing time
        (s) left after its onset; ``force_windows``: per trial the forces at the robot rate
        (:func:`native_force_windows`, empty without ``force_native``); ``pool``: per trial ``(name, time,
        columns, stride table, (native force table, force direction (n, 2)) or None)``; ``native_rate``:
        the robot rate (Hz), None without ``force_native``.
    """
    onset_s, _, after, _, start, _ = analysis
    per_trial, pairs, windows, rooms, force_windows, pool = [], [], [], [], [], []
    native_rate = None
    for k, trial in enumerate(trials):
        name, where_s, t, columns, strides, native = _trial_inputs(trial, k, side, source)
        if (native is None) != (native_rate is None) and k:
            raise LoperInputError(
                f"{where(source)}{name}: the force at the robot rate (force_native) must be given "
                "for every trial of the onset or for none"
            )
        if any(rec["trial"] == name for rec in per_trial):
            raise LoperInputError(f"{where(source)}trial name {name!r} appears twice; names must be unique")
        table = stride_table(strides, where_s)
        perturbed = bool_column(table, "perturbed", where_s, what="strides")
        n_perturbed = int(perturbed.sum())
        n_short = int(too_short(table, onset_s, after, source=where_s).sum())
        delay = np.fmax(table["onset_s"].to_numpy(float) - table["toe_off_s"].to_numpy(float), onset_s)
        rooms.extend((table["swing_s"].to_numpy(float) - delay)[perturbed].tolist())
        matches = match_in_window(
            t, columns["joints"], table, analysis, where_s, candidate_within_swing=candidate_within_swing
        )
        for s, why in matches.attrs["unmatched"].items():
            log.info("%s: perturbed stride %s has no match: %s", where_s, s, why)
        windows.append(
            paired_windows(t, columns, matches, start, after, settings.rate_hz, method=method, source=where_s)
        )
        pool.append((name, t, columns, table, None if native is None else (native[0], native[2])))
        if native is not None:
            table, where_n, direction = native
            rate_n = native_force_rate_hz(table, where_n)
            if native_rate is not None and rate_n != native_rate:
                raise LoperInputError(
                    f"{where_n}: robot rate {rate_n:g} Hz differs from the other trials' {native_rate:g} Hz"
                )
            native_rate = rate_n
            force_windows.append(native_force_windows(t, direction, table, matches, start, after, rate_n, where_n))
        pairs.append(matches.assign(trial=name))
        per_trial.append(
            {
                "trial": name,
                "n_perturbed": n_perturbed,
                "n_too_short": n_short,
                "n_no_match": len(matches.attrs["unmatched"]),
            }
        )
    return {
        "per_trial": per_trial,
        "pairs": pairs,
        "windows": windows,
        "rooms": rooms,
        "force_windows": force_windows,
        "pool": pool,
        "native_rate": native_rate,
    }


def _pair_table(pairs: Sequence[pd.DataFrame]) -> pd.DataFrame:
    """One row per matched pair of all trials (``trial``, ``stride``, ``matched_stride``, ``onset_s``,
    ``matched_anchor_s`` in s, ``rmsd_rad``), without attrs; the first trial's empty columns when none matched."""
    pair_columns = ["trial", "stride", "matched_stride", "onset_s", "matched_anchor_s", "rmsd_rad"]
    filled = [m[pair_columns] for m in pairs if len(m)]
    pair_table = (pd.concat(filled, ignore_index=True) if filled else pairs[0][pair_columns]).reset_index(drop=True)
    pair_table.attrs = {}
    return pair_table


def _count_rows(
    per_trial: Sequence[dict], pair_table: pd.DataFrame, verdict: pd.DataFrame, min_n: int, before: float, after: float
) -> list[dict]:
    """The rows of the counts table (:data:`COUNT_COLUMNS`): one per trial, then ``total``.

    ``pair_table`` holds the pairs' ``trial`` and ``removed``; ``verdict`` is :func:`window_outliers`'
    (its ``attrs["judged"]``); ``before`` and ``after`` (s) are the analysis window, quoted in reasons.
    """
    keep = ~pair_table["removed"].to_numpy(bool)
    judged = bool(verdict.attrs["judged"])
    rows = []
    for rec in per_trial:
        mine = pair_table["trial"].to_numpy() == rec["trial"]
        rows.append({**rec, "n_outliers": int((mine & ~keep).sum()), "n_kept": int((mine & keep).sum())})
    total = {
        key: sum(r[key] for r in rows) for key in ("n_perturbed", "n_too_short", "n_no_match", "n_outliers", "n_kept")
    }
    rows.append({"trial": "total", **total})
    for r in rows:
        parts = []
        if r["n_kept"] < min_n:
            parts.append(
                f"{r['n_kept']} pair(s) kept, fewer than min_strides = {min_n}"
                + ("" if r["trial"] == "total" else " (the average pools the trials: see total)")
            )
        if r["n_too_short"]:
            parts.append(f"{r['n_too_short']} too short (swing < onset delay + {after * 1e3:g} ms)")
        if r["n_no_match"]:
            parts.append(f"{r['n_no_match']} without unperturbed match")
        if r["n_outliers"]:
            parts.append(f"{r['n_outliers']} outlier(s) in the window -{before * 1e3:g} .. {after * 1e3:g} ms")
        if not judged:
            parts.append(verdict["reason"].iloc[0] if len(verdict) else "outliers not judged: no pair")
        r["status"] = "ok" if r["n_kept"] >= min_n else "too_few_strides"
        r["reason"] = "; ".join(parts)
    return rows


def _counts_table(
    rows: Sequence[dict],
    pair_table: pd.DataFrame,
    verdict: pd.DataFrame,
    rooms: Sequence[float],
    onset_ms: float,
    source: str,
) -> pd.DataFrame:
    """The counts table of :func:`subject_onset_response` from its rows (:func:`_count_rows`), with its attrs;
    ``rooms``: per perturbed stride the swing time (s) left after its onset."""
    counts = pd.DataFrame(rows, columns=list(COUNT_COLUMNS))
    finite_rooms = [r for r in rooms if np.isfinite(r)]
    counts.attrs = {
        "pairs": pair_table,
        "outliers_judged": bool(verdict.attrs["judged"]),
        "onset_ms": float(onset_ms),
        "source": source,
        "longest_swing_after_onset_s": max(finite_rooms) if finite_rooms else float("nan"),
    }
    return counts


def _response_table(kept: Mapping, n_pairs: int, analysis: AnalysisGrid, onset_ms: float, source: str) -> pd.DataFrame:
    """The response table of :func:`subject_onset_response`: means and SDs over the kept pairs on the grid.

    ``kept``: per window key the kept pairs' perturbed and unperturbed windows (n_pairs, n_grid, ...);
    joint angles in rad, forces in N.
    """
    _, before, after, initial, _, grid = analysis
    jp, ju = kept["joints"]
    d_mean, d_sd = mean_and_sd(jp - ju)
    fp, fu = kept["force"]
    f_mean, f_sd = mean_and_sd(fp - fu)
    jp_mean, ju_mean = mean_and_sd(jp)[0], mean_and_sd(ju)[0]
    response = pd.DataFrame({"time_s": grid})
    for j, joint in enumerate(JOINTS):
        response[f"{joint}_rad_mean"] = d_mean[:, j]
        response[f"{joint}_rad_sd"] = d_sd[:, j]
    response["force_n_mean"], response["force_n_sd"] = f_mean, f_sd
    for j, joint in enumerate(JOINTS):
        response[f"{joint}_perturbed_rad_mean"] = jp_mean[:, j]
        response[f"{joint}_unperturbed_rad_mean"] = ju_mean[:, j]
    response["force_perturbed_n_mean"], response["force_unperturbed_n_mean"] = mean_and_sd(fp)[0], mean_and_sd(fu)[0]
    response["n_pairs"] = n_pairs
    response["analysis_window"] = (grid >= -before - TIME_TOLERANCE_S) & (grid <= after + TIME_TOLERANCE_S)
    response.attrs = {
        "onset_ms": float(onset_ms),
        "n_pairs": n_pairs,
        "source": source,
        "before_s": before,
        "after_s": after,
        "initial_span_s": initial,
    }
    return response


def _mean_series(
    kept: Mapping,
    n_pairs: int,
    force_pairs: tuple[np.ndarray, np.ndarray] | None,
    keep: np.ndarray,
    analysis: AnalysisGrid,
    native_rate: float | None,
) -> dict:
    """The series of :func:`subject_onset_response` (means over the kept pairs) with the kept pairs one by one
    under ``pairs``; the forces at the robot rate (``native_rate``, Hz) when ``force_pairs`` (all pairs'
    perturbed and unperturbed forces, (n, k, 2) in N) are given, ``keep`` (n,) selecting the kept pairs."""
    _, _, after, _, start, grid = analysis
    series: dict = {"time_s": grid.copy(), "onset_s": 0.0}
    pair_series: dict = {"time_s": grid.copy(), "n_pairs": n_pairs}
    for what, i in (("perturbed", 0), ("unperturbed", 1)):
        pel = kept["pelvis_angle"][i]
        q = window_coordinates(kept["joints"][i], pel, kept["pelvis_x"][i])
        series[f"q_{what}"] = mean_and_sd(q)[0]
        series[f"pelvis_angle_{what}_rad"] = mean_and_sd(pel)[0]
        series[f"force_{what}_n"] = mean_and_sd(kept["force_vector"][i])[0]
        pair_series[f"q_{what}"], pair_series[f"pelvis_angle_{what}_rad"] = q, pel
        pair_series[f"force_{what}_n"] = kept["force_vector"][i]
    series["pairs"] = pair_series
    if force_pairs is not None:
        # the force at the robot rate replaces the frames' for the identification
        series["force_time_s"] = pair_series["force_time_s"] = window_times_s(-start, after, native_rate)
        for i, what in enumerate(("perturbed", "unperturbed")):
            series[f"force_{what}_n"] = mean_and_sd(force_pairs[i][keep])[0]
            pair_series[f"force_{what}_n"] = force_pairs[i][keep]
    return series


def _null_pair_series(
    conditional: Mapping, keep: np.ndarray, analysis: AnalysisGrid, settings: ResponseSettings, label: str
) -> tuple[dict, dict]:
    """The conditional counterfactual's null pairs (:func:`conditional_null_pair_windows`, those kept by
    :func:`window_outliers`, with their unit scatter variance and, with kept pairs, covariance scale) and the
    kept pairs' prediction weights (n_pairs, N) and covariance scale (empty without kept pairs)."""
    _, before, after, _, _, grid = analysis
    null = conditional["null"]
    d = null["own"]["joints"] - null["predicted"]["joints"]
    null_keep = ~window_outliers(
        d, grid, before, after, settings.whisker, settings.max_fraction, JOINTS, f"{label} null pairs"
    )["removed"].to_numpy(bool)
    null_pairs = conditional_null_pair_windows(null, grid, before, after, null_keep)
    null_pairs["unit_scatter_variance"] = unit_scatter_variance(null["weights"], null_keep)
    weights: dict = {}
    if int(keep.sum()):
        kept_weights = weights["prediction_weights"] = conditional["weights"][keep]
        weights["covariance_scale"] = covariance_scale(kept_weights)
        null_pairs["covariance_scale"] = covariance_scale(kept_weights, null["weights"], null_keep)
    return null_pairs, weights
