"""The planner's inputs: the planned pulse as the rods deliver it, and the pilot's perturbed pairs at an onset.

* :func:`pulse_force_n` - the force the rods apply for a rectangular desired
  pulse: the device's closed loop (about 10 ms rise, 30 % overshoot), low-passed
  like the load cell;
* :func:`pilot_onset_series` - the pilot's response series at an onset: its
  perturbed pairs one by one and, with the conditional counterfactual, its
  unperturbed strides each predicted from the others;
* :func:`pilot_perturbed_pairs` - the pilot's kept perturbed pairs at an onset,
  one by one, whose scatter the prediction takes;
* :func:`trial_stretches` - a pilot trial cut into consecutive stretches that
  each hold a planned number of perturbed strides: shorter experiments of
  the planned size.

Used by :mod:`loper_analysis.planning.precision` (method: ``docs/planning.md``).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np
import pandas as pd

from loper_analysis.checks import number
from loper_analysis.errors import LoperInputError
from loper_analysis.filtering import CUTOFF_HZ, ORDER
from loper_analysis.study_design import PERTURBED_SIDE

__all__ = ["PLANNED_COUNTERFACTUAL", "pulse_force_n", "pilot_onset_series", "pilot_perturbed_pairs", "trial_stretches"]

#: The counterfactual the planner predicts for when none is given: the study's matched stride, whose pairs' scatter
#: the prediction scales (``docs/planning.md``); the workflow plans for ``impedance.counterfactual``.
PLANNED_COUNTERFACTUAL: str = "matched_stride"


def pulse_force_n(
    time_s, force_n: float, duration_s: float, device=None, cutoff_hz: float = CUTOFF_HZ, order: int = ORDER
) -> np.ndarray:
    """The rod force (N, along the rods) of a rectangular desired pulse, at ``time_s`` (s, onset at 0).

    The desired force ``force_n`` for ``0 <= t < duration_s`` drives the
    device's closed loop (:func:`loper_analysis.device.controller.simulate_device`
    with a still brace, no load-cell noise; ``device`` a
    :class:`~loper_analysis.device.controller.DeviceParameters`, default the
    study's tuning: about 10 ms rise and 30 % overshoot), minus the loop's
    output without the pulse; the result is low-passed like the load cell
    (zero-phase Butterworth, ``cutoff_hz``, ``order``) and sampled at
    ``time_s``. Zero before the onset.
    """
    from loper_analysis.device.controller import DeviceParameters, simulate_device
    from loper_analysis.filtering import lowpass

    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or t.size < 2 or not np.all(np.isfinite(t)):
        raise LoperInputError(f"time_s must be a finite 1-D array with >= 2 samples, got shape {t.shape}")
    f = number("pulse force_n", force_n)
    d = number("pulse duration_s", duration_s)
    if d <= 0:
        raise LoperInputError(f"pulse duration_s must be > 0 s, got {d:g} s")
    dev = replace(device or DeviceParameters(), loadcell_noise_sd_n=0.0)
    rate = dev.sample_rate_hz
    lead = 0.2
    n = int(math.ceil((max(t[-1], d) + lead + 0.2) * rate)) + 1
    t_dev = -lead + np.arange(n) / rate
    desired = np.where((t_dev >= -1e-9) & (t_dev < d - 1e-9), f, 0.0)
    still = np.zeros(n)
    on = simulate_device(desired, dev, None, brace_position_m=still)["force_measured_n"].to_numpy()
    off = simulate_device(0.0 * desired, dev, None, brace_position_m=still)["force_measured_n"].to_numpy()
    force = lowpass(on - off, rate, cutoff_hz, order)
    return np.interp(t, t_dev, force, left=0.0, right=float(force[-1]))


def pilot_onset_series(
    trials: Sequence[Mapping],
    onset_ms: float,
    response=None,
    *,
    side: str = PERTURBED_SIDE,
    onset_tolerance_ms: float = 12.5,
    source: str = "pilot",
) -> dict | None:
    """The pilot's response series at ``onset_ms`` (of
    :func:`~loper_analysis.impedance.responses.subject_onset_response`).

    ``trials``: ``name``, ``angles`` and ``strides`` tables of the pilot's
    trials with the device (:mod:`loper_analysis.impedance.responses.inputs`). Those
    whose perturbed strides' median onset (``onset_s - toe_off_s``) lies
    within ``onset_tolerance_ms`` of ``onset_ms`` are the onset's; their
    pairs are matched (or predicted), windowed and judged for outliers as the
    fit's with ``response`` settings (``pairs``: the kept perturbed pairs one
    by one; with the conditional counterfactual also ``null_pairs``, the
    onset's unperturbed strides each predicted from the others). The pairs'
    angles do not depend on the force, so none is needed (the response gets a
    zero force). None when no trial is the onset's.
    """
    from loper_analysis.errors import TooFewStridesWarning
    from loper_analysis.impedance.responses import ResponseSettings, subject_onset_response

    own = []
    for tr in trials:
        table = tr["strides"]
        if not {"perturbed", "onset_s", "toe_off_s"} <= set(table.columns):
            continue
        pert = table[table["perturbed"].astype(bool)]
        delay_ms = 1e3 * (pert["onset_s"].to_numpy(float) - pert["toe_off_s"].to_numpy(float))
        delay_ms = delay_ms[np.isfinite(delay_ms)]
        if delay_ms.size and abs(float(np.median(delay_ms)) - float(onset_ms)) <= onset_tolerance_ms:
            n = len(tr["angles"])
            own.append(
                {
                    "name": tr["name"],
                    "angles": tr["angles"],
                    "strides": table,
                    "force": pd.DataFrame(
                        {"time_s": tr["angles"]["time_s"].to_numpy(float), "force_measured_n": np.zeros(n)}
                    ),
                    "force_direction": np.tile([1.0, 0.0], (n, 1)),
                }
            )
    if not own:
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TooFewStridesWarning)
        _, _, series = subject_onset_response(
            own,
            onset_ms,
            response or ResponseSettings(counterfactual=PLANNED_COUNTERFACTUAL),
            side=side,
            source=f"{source}, perturbed pairs",
        )
    return series


def pilot_perturbed_pairs(trials: Sequence[Mapping], onset_ms: float, response=None, **options: Any) -> dict | None:
    """The pilot's kept perturbed pairs at ``onset_ms`` one by one (format of ``null_pairs``), or None.

    ``series["pairs"]`` of :func:`pilot_onset_series`, which takes ``trials``, ``onset_ms``, ``response``
    and the keyword ``options`` (``side``, ``onset_tolerance_ms``, ``source``); None when no trial is the
    onset's or no pair is kept.
    """
    series = pilot_onset_series(trials, onset_ms, response, **options)
    if series is None:
        return None
    pairs = series["pairs"]
    return pairs if int(pairs["n_pairs"]) > 0 else None


def trial_stretches(trial: Mapping, n_perturbed: int, *, side: str = PERTURBED_SIDE) -> list[dict]:
    """``trial`` cut into consecutive stretches that each hold ``n_perturbed`` perturbed strides.

    ``trial``: ``name``, ``angles`` (with ``time_s``) and ``strides`` (the
    stride table of ``side``: ``heel_strike_s``, ``end_s``, ``perturbed``).
    Stretch ``j`` starts at the heel strike of perturbed stride ``j * n``
    (the first at the trial's first stride) and ends before that of stride
    ``(j + 1) * n`` (the last at the trial's end when no stride follows); it
    keeps the strides that lie wholly inside it, their stride-table rows
    unchanged (outlier flags included), and the angle frames from its first
    heel strike to its last stride's end. Perturbed strides
    after the last whole stretch are left out. Each stretch is a trial with
    ``name`` (``"{name} [j/k]"``), ``angles`` and ``strides`` (what
    :func:`pilot_onset_series` reads); an empty list when the trial holds
    fewer than ``n_perturbed`` perturbed strides.
    """
    n = int(n_perturbed)
    if n < 1:
        raise LoperInputError(f"{trial.get('name', 'trial')}: n_perturbed must be >= 1, got {n_perturbed!r}")
    table = trial["strides"]
    if "side" in table.columns:
        table = table[table["side"] == side]
    table = table.sort_values("heel_strike_s").reset_index(drop=True)
    starts = table["heel_strike_s"].to_numpy(float)
    pert = np.flatnonzero(table["perturbed"].to_numpy(bool))
    k = pert.size // n
    if k == 0:
        return []
    bounds = [-np.inf] + [starts[pert[j * n]] if j * n < pert.size else np.inf for j in range(1, k + 1)]
    time_s = trial["angles"]["time_s"].to_numpy(float)
    out = []
    for j in range(k):
        keep = (starts >= bounds[j]) & (table["end_s"].to_numpy(float) <= bounds[j + 1])
        rows = table[keep].reset_index(drop=True)
        first, last = float(rows["heel_strike_s"].min()), float(rows["end_s"].max())
        frames = (time_s >= first - 1e-9) & (time_s <= last + 1e-9)
        out.append(
            {
                "name": f"{trial['name']} [{j + 1}/{k}]",
                "angles": trial["angles"][frames].reset_index(drop=True),
                "strides": rows,
            }
        )
    return out
