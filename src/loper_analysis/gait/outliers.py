"""Stride outliers: the per-sample IQR rule and the warning when too few strides remain."""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np
import pandas as pd

from loper_analysis.checks import number, where
from loper_analysis.errors import LoperInputError, TooFewStridesWarning

__all__ = [
    "IQR_WHISKER",
    "MAX_OUTLIER_FRACTION",
    "MIN_STRIDES_FOR_OUTLIERS",
    "MIN_VALID_STRIDES",
    "iqr_outliers",
    "check_enough_strides",
]

#: Fewest strides the IQR rule judges (:func:`iqr_outliers` refuses fewer; callers keep them all unjudged).
MIN_STRIDES_FOR_OUTLIERS: int = 4
#: Fewest strides per subject and condition that an average is built from (warning below); the default of the
#: config's ``strides.min_valid_strides`` wherever a function takes that setting.
MIN_VALID_STRIDES: int = 5
#: The IQR rule's whisker (outlier beyond Q1 - w IQR or Q3 + w IQR; config ``strides.iqr_whisker``).
IQR_WHISKER: float = 1.5
#: A stride with more outlying samples than this fraction is an outlier (config ``strides.max_outlier_fraction``).
MAX_OUTLIER_FRACTION: float = 0.2


def iqr_outliers(
    values,
    whisker: float = IQR_WHISKER,
    max_fraction: float = MAX_OUTLIER_FRACTION,
    names: Sequence[str] | None = None,
    source: str = "",
) -> pd.DataFrame:
    """Stride outliers by the per-sample IQR rule (``docs/processing.md``).

    For every normalised time sample (and signal), Q1 and Q3 are taken across
    strides with :func:`numpy.percentile` (default ``method="linear"``: the
    quantile interpolates linearly between order statistics, position
    ``p/100 * (n - 1)``). A value is outlying if it is below
    ``Q1 - whisker * IQR`` or above ``Q3 + whisker * IQR`` (values on a bound
    are not outlying). Per stride and signal the fraction of outlying samples
    is computed; a stride is removed if that fraction exceeds
    ``max_fraction`` for any signal. For perturbation analysis pass only the
    samples of the analysis window (25 ms before to 250 ms after onset).

    Parameters
    ----------
    values : array_like, shape (n_strides, n_samples) or (n_strides, n_samples, k)
        Normalised strides (any unit), finite; at least :data:`MIN_STRIDES_FOR_OUTLIERS` (4) strides.
    whisker : float
        IQR multiple (>= 0).
    max_fraction : float
        Largest accepted fraction of outlying samples, 0 .. 1.
    names : sequence of str, optional
        Signal names (length k; one name for 2-D input). Default ``"signal"``
        for 2-D input, ``"signal_0" ..`` for 3-D input.
    source : str
        Name of the trial or subject, quoted in error messages.

    Returns
    -------
    pandas.DataFrame
        One row per stride (input order): ``stride`` (row index into
        ``values``), ``fraction_outlying_<name>`` per signal (0 .. 1),
        ``removed`` (bool), ``reason`` (e.g. ``"knee: 27.7 % of samples
        outside 1.5·IQR"``, signals joined by ``"; "``; empty if kept).

    Raises
    ------
    LoperInputError
        Fewer than :data:`MIN_STRIDES_FOR_OUTLIERS` strides, bad shapes or names, non-finite values, bad settings.
    """
    v = np.asarray(values, dtype=float)
    if v.ndim not in (2, 3):
        raise LoperInputError(f"{where(source)}values must have shape (n_strides, n_samples[, k]), got {v.shape}")
    if v.shape[0] < MIN_STRIDES_FOR_OUTLIERS:
        raise LoperInputError(
            f"{where(source)}the IQR rule needs >= {MIN_STRIDES_FOR_OUTLIERS} strides, got {v.shape[0]}"
        )
    if v.shape[1] < 1 or (v.ndim == 3 and v.shape[2] < 1):
        raise LoperInputError(f"{where(source)}values has no samples: shape {v.shape}")
    bad = np.argwhere(~np.isfinite(v))
    if bad.size:
        raise LoperInputError(f"{where(source)}values are not finite at stride {bad[0][0]}, sample {bad[0][1]}")
    w = number("whisker", whisker, source, minimum=0.0)
    mf = number("max_fraction", max_fraction, source, minimum=0.0)
    if mf > 1:
        raise LoperInputError(f"{where(source)}max_fraction must lie in 0 .. 1, got {mf!r}")
    x = v if v.ndim == 3 else v[:, :, None]
    k = x.shape[2]
    if names is None:
        names = ["signal"] if v.ndim == 2 else [f"signal_{j}" for j in range(k)]
    names = [str(n) for n in names]
    if len(names) != k or len(set(names)) != k:
        raise LoperInputError(f"{where(source)}names must be {k} distinct names, got {names!r}")

    q1, q3 = np.percentile(x, [25.0, 75.0], axis=0)  # (n_samples, k) each
    iqr = q3 - q1
    outlying = (x < q1 - w * iqr) | (x > q3 + w * iqr)
    fraction = outlying.mean(axis=1)  # (n_strides, k)
    over = fraction > mf
    table = pd.DataFrame({"stride": np.arange(x.shape[0], dtype=np.int64)})
    for j, name in enumerate(names):
        table[f"fraction_outlying_{name}"] = fraction[:, j]
    table["removed"] = over.any(axis=1)
    table["reason"] = [
        "; ".join(
            f"{names[j]}: {100 * fraction[i, j]:.1f} % of samples outside {w:g}·IQR" for j in np.flatnonzero(over[i])
        )
        for i in range(x.shape[0])
    ]
    table.attrs.update({"source": source, "whisker": w, "max_fraction": mf})
    return table


def check_enough_strides(n_kept: int, source: str, minimum: int = MIN_VALID_STRIDES) -> bool:
    """True if ``n_kept >= minimum``; otherwise warn (:class:`TooFewStridesWarning`,
    naming ``source`` and both counts) and return False."""
    if int(n_kept) >= int(minimum):
        return True
    warnings.warn(
        f"{source}: only {int(n_kept)} valid stride(s), fewer than the {int(minimum)} required",
        TooFewStridesWarning,
        stacklevel=2,
    )
    return False
