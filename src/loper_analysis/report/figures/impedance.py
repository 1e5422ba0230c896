"""Figures of the swing-phase impedance study, drawn from the pipeline's tables.

* :func:`responses_figure` - mean perturbed and unperturbed joint angles and
  their difference (mean ± SD) after each perturbation onset
  (:func:`response_peaks` gives the peak differences);
* :func:`fit_figure` - measured response against the model's fit over the
  fit window, per onset and joint;
* :func:`impedance_figure` - the study's figure: stiffness K and damping D
  per joint against perturbation onset, one grey line per subject, the
  across-subject mean in black, the truth of synthetic subjects as open
  circles (:func:`impedance_means` gives the means).

The tables hold angles in rad and time in s; the figures show degrees and
ms. Each function returns the matplotlib figure (the caller writes it with
:func:`loper_analysis.io.atomic.write_figure` and closes it). Missing or
unusable columns raise :class:`~loper_analysis.errors.LoperInputError`
naming the table (``source``), column and value.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, PARAMETER_UNITS, PARAMETERS, parameter_column
from loper_analysis.errors import LoperInputError
from loper_analysis.report.figures import closed_on_error, pyplot

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "ANALYSIS_WINDOW_MS",
    "IMPEDANCE_STATUSES_SHOWN",
    "RESPONSE_COLUMNS",
    "CURVE_COLUMNS",
    "response_peaks",
    "responses_figure",
    "fit_figure",
    "impedance_means",
    "impedance_figure",
]

#: Default analysis window relative to the perturbation onset, ms (used when a
#: response table has no ``analysis_window`` column or no sample flagged).
ANALYSIS_WINDOW_MS: tuple[float, float] = (-25.0, 250.0)
#: Fit statuses whose K/D are drawn in :func:`impedance_figure`.
IMPEDANCE_STATUSES_SHOWN: tuple[str, ...] = ("ok", "not_identifiable")

_RAD_TO_DEG = 180.0 / np.pi
#: Columns of a response table (:func:`loper_analysis.impedance.responses.subject_onset_response`) that the figure
#: draws.
RESPONSE_COLUMNS: tuple[str, ...] = (
    "time_s",
    *(f"{j}_{kind}" for j in JOINTS for kind in ("rad_mean", "rad_sd", "perturbed_rad_mean", "unperturbed_rad_mean")),
)
#: Columns of a fit-curve table (measured and model response per joint).
CURVE_COLUMNS: tuple[str, ...] = ("time_s", *(f"{j}_{kind}_rad" for j in JOINTS for kind in ("measured", "model")))
_K, _D = parameter_column("K"), parameter_column("D")
_K_TRUE, _D_TRUE = parameter_column("K", "true"), parameter_column("D", "true")
_IMPEDANCE_COLUMNS = ("subject", "onset_ms", "joint", _K, _D, _K_TRUE, _D_TRUE, "status")


# --------------------------------------------------------------------------- reading


def _usable(
    table: pd.DataFrame | None, columns: Sequence[str], numeric: Sequence[str], source: str
) -> pd.DataFrame | None:
    """The table with ``numeric`` columns as float; None when it has no rows.

    Checks that ``columns`` are present (only when there are rows) and that
    ``numeric`` columns hold numbers or blanks.
    """
    if table is None or table.empty:
        return None
    table = table.copy()
    for column in columns:
        if column not in table.columns:
            raise LoperInputError(f"{source}: missing column {column!r} (has {list(table.columns)})")
    for column in numeric:
        values = pd.to_numeric(table[column], errors="coerce")
        bad = values.isna() & table[column].notna()
        if bad.any():
            raise LoperInputError(f"{source}: column {column!r} must be numeric, got {table[column][bad].iloc[0]!r}")
        table[column] = values.astype(float)
    return table


def _onset_panels(
    name: str, tables: Mapping, columns: Sequence[str], sources: Mapping | None, n_rows: int, row_height_in: float
):
    """Checked tables by onset (``(onset_ms, table or None)``) and a figure with one column of panels per onset."""
    items = [(o, _usable(t, columns, columns, s)) for o, t, s in _onset_tables(name, tables, sources)]
    n_cols = len(items)
    fig, axes = pyplot().subplots(
        n_rows,
        n_cols,
        figsize=(3.2 * n_cols + 0.8, row_height_in * n_rows + 0.8),
        sharex="col",
        constrained_layout=True,
        squeeze=False,
    )
    return items, fig, axes


def _onset_tables(name: str, tables: Mapping, sources: Mapping | None) -> list[tuple[int, pd.DataFrame | None, str]]:
    """``(onset_ms, table, source)`` sorted by onset from ``{onset_ms: table}``."""
    if not isinstance(tables, Mapping) or not tables:
        raise LoperInputError(f"{name} must be a non-empty mapping onset_ms -> table, got {tables!r}")
    items = []
    for onset, table in tables.items():
        try:
            onset_ms = int(onset)
        except (TypeError, ValueError):
            raise LoperInputError(f"{name}: onset key must be an integer (ms), got {onset!r}") from None
        items.append((onset_ms, table, str((sources or {}).get(onset, f"{name}[{onset_ms}]"))))
    items.sort(key=lambda item: item[0])
    return items


def _window_ms(table: pd.DataFrame, time_ms: np.ndarray) -> tuple[float, float]:
    """Span of the samples flagged ``analysis_window``, else :data:`ANALYSIS_WINDOW_MS`."""
    if "analysis_window" in table.columns:
        flag = table["analysis_window"].astype(str).str.strip().str.lower().isin(("true", "1", "1.0"))
        if flag.any():
            return float(time_ms[flag.to_numpy()].min()), float(time_ms[flag.to_numpy()].max())
    return ANALYSIS_WINDOW_MS


def _grey_and_red(ax, time_ms: np.ndarray, grey: pd.Series, red: pd.Series, labels: tuple[str, str], **red_style):
    """Two angle columns (rad) drawn in deg against ``time_ms``: the reference in grey, the other in red.

    ``labels`` names the two curves in the legend; ``red_style`` adds to the red curve's style (e.g. ``ls``).
    """
    ax.plot(time_ms, grey.to_numpy() * _RAD_TO_DEG, color="0.35", lw=1.3, label=labels[0])
    ax.plot(time_ms, red.to_numpy() * _RAD_TO_DEG, color="tab:red", lw=1.3, label=labels[1], **red_style)


def _say(ax, text: str) -> None:
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", color="0.4", fontsize=11)
    ax.set_xticks([])
    ax.set_yticks([])


# --------------------------------------------------------------------------- responses


def response_peaks(tables: Mapping[int, pd.DataFrame], sources: Mapping | None = None) -> pd.DataFrame:
    """Peak |mean difference| (rad) over all samples of each response table.

    Index ``onset_ms`` (sorted), columns hip, knee, ankle; NaN for an onset
    whose table has no rows (missing) or no finite difference.
    """
    items = _onset_tables("response tables", tables, sources)
    peaks = pd.DataFrame(np.nan, index=pd.Index([o for o, _, _ in items], name="onset_ms"), columns=list(JOINTS))
    for onset, table, source in items:
        table = _usable(table, RESPONSE_COLUMNS, RESPONSE_COLUMNS, source)
        if table is None:
            continue
        for joint in JOINTS:
            diff = table[f"{joint}_rad_mean"].to_numpy()
            if np.isfinite(diff).any():
                peaks.loc[onset, joint] = float(np.nanmax(np.abs(diff)))
    return peaks


def responses_figure(
    tables: Mapping[int, pd.DataFrame], title: str | None = None, sources: Mapping | None = None
) -> Figure:
    """Perturbation responses: joint angles with and without perturbation, and their difference.

    One column per onset; per joint two rows: the mean perturbed and mean
    unperturbed joint angle (deg), then their difference perturbed −
    unperturbed (mean ± 1 SD shaded, deg), against time after onset (ms).
    The analysis window (samples flagged ``analysis_window``, default
    −25..250 ms) is shaded lightly. An empty table (no rows: the onset is
    missing) gives a column that says "missing".

    Parameters
    ----------
    tables : mapping
        ``{onset_ms: response table}`` with :data:`RESPONSE_COLUMNS` (time
        relative to onset in s, angles and differences in rad); optional
        ``n_pairs`` and ``analysis_window`` (bool).
    title : str, optional
        Figure title.
    sources : mapping, optional
        ``{onset_ms: name}`` of each table (its file), quoted in errors.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    LoperInputError
        A non-empty table lacks a column or holds non-numeric values.
    """
    items, fig, axes = _onset_panels("response tables", tables, RESPONSE_COLUMNS, sources, 2 * len(JOINTS), 1.5)
    n_rows = axes.shape[0]
    with closed_on_error(fig):
        for c, (onset, table) in enumerate(items):
            head = f"onset {onset} ms"
            if table is None:
                axes[0, c].set_title(head)
                for r in range(n_rows):
                    _say(axes[r, c], "missing")
                continue
            table = table.sort_values("time_s", kind="stable")
            if "n_pairs" in table.columns:
                n = pd.to_numeric(table["n_pairs"], errors="coerce").max()
                if np.isfinite(n):
                    head += f" (n = {int(n)})"
            axes[0, c].set_title(head)
            t_ms = table["time_s"].to_numpy() * 1000.0
            lo, hi = _window_ms(table, t_ms)
            for j, joint in enumerate(JOINTS):
                diff = table[f"{joint}_rad_mean"].to_numpy()
                sd = table[f"{joint}_rad_sd"].to_numpy()
                ax_a, ax_d = axes[2 * j, c], axes[2 * j + 1, c]
                for ax in (ax_a, ax_d):
                    ax.axvspan(lo, hi, color="0.92", lw=0, zorder=0)
                    ax.axvline(0.0, color="0.6", lw=0.6, ls=":")
                means = table[f"{joint}_unperturbed_rad_mean"], table[f"{joint}_perturbed_rad_mean"]
                _grey_and_red(ax_a, t_ms, *means, ("unperturbed", "perturbed"))
                ax_d.fill_between(
                    t_ms, (diff - sd) * _RAD_TO_DEG, (diff + sd) * _RAD_TO_DEG, color="tab:red", alpha=0.2, lw=0
                )
                ax_d.plot(t_ms, diff * _RAD_TO_DEG, color="tab:red", lw=1.3)
                ax_d.axhline(0.0, color="0.6", lw=0.6)
                if c == 0:
                    ax_a.set_ylabel(f"{joint} (deg)")
                    ax_d.set_ylabel(f"Δ{joint} (deg)")
        _finish(fig, axes, "time after onset (ms)", title)
    return fig


# --------------------------------------------------------------------------- fit


def fit_figure(tables: Mapping[int, pd.DataFrame], title: str | None = None, sources: Mapping | None = None) -> Figure:
    """Measured perturbation response against the model's fit, per onset and joint.

    One column per onset, one row per joint (hip, knee, ankle): the measured
    response (grey) and the fitted model response (red), in deg, against
    time (ms, ``time_s`` × 1000 as given). ``tables``: ``{onset_ms: fit-curve
    table}`` with :data:`CURVE_COLUMNS` (s, rad); an empty table (only a
    header: the onset was not fitted) gives a column that says "not fitted".
    ``title``, ``sources``, the returned figure and the errors as for
    :func:`responses_figure`.
    """
    items, fig, axes = _onset_panels("fit-curve tables", tables, CURVE_COLUMNS, sources, len(JOINTS), 1.9)
    n_rows = axes.shape[0]
    with closed_on_error(fig):
        for c, (onset, table) in enumerate(items):
            axes[0, c].set_title(f"onset {onset} ms")
            if table is None:
                for r in range(n_rows):
                    _say(axes[r, c], "not fitted")
                continue
            table = table.sort_values("time_s", kind="stable")
            t_ms = table["time_s"].to_numpy() * 1000.0
            for r, joint in enumerate(JOINTS):
                ax = axes[r, c]
                curves = table[f"{joint}_measured_rad"], table[f"{joint}_model_rad"]
                _grey_and_red(ax, t_ms, *curves, ("measured", "model"), ls="--")
                ax.axhline(0.0, color="0.7", lw=0.6)
                if c == 0:
                    ax.set_ylabel(f"{joint} (deg)")
        _finish(fig, axes, "time (ms)", title)
    return fig


# --------------------------------------------------------------------------- impedance


def _impedance_long(table: pd.DataFrame, source: str) -> tuple[pd.DataFrame, np.ndarray]:
    """Checked impedance rows in long form (parameter, subject, onset_ms, value, truth) and the onsets."""
    table = _usable(table, _IMPEDANCE_COLUMNS, ("onset_ms", _K, _D, _K_TRUE, _D_TRUE), source)
    if table is None:
        raise LoperInputError(f"{source}: impedance table has no rows")
    table["joint"] = table["joint"].astype(str).str.strip()
    unknown = sorted(set(table["joint"]) - set(JOINTS))
    if unknown:
        raise LoperInputError(f"{source}: column 'joint' has unknown value {unknown[0]!r} (expected {JOINTS})")
    if table["onset_ms"].isna().any():
        raise LoperInputError(f"{source}: column 'onset_ms' has an empty value")
    if (table["onset_ms"] == table["onset_ms"].round()).all():
        table["onset_ms"] = table["onset_ms"].astype(int)
    table["subject"] = table["subject"].astype(str)
    keys = ["subject", "onset_ms", "joint"]
    dup = table.duplicated(keys)
    if dup.any():
        row = table.loc[dup, keys].iloc[0]
        raise LoperInputError(f"{source}: duplicate row for subject/onset_ms/joint {tuple(row)!r}")
    onsets = np.sort(table["onset_ms"].unique())
    shown = table["status"].astype(str).str.strip().isin(IMPEDANCE_STATUSES_SHOWN)
    long = []
    for kind, value, truth in (("K", _K, _K_TRUE), ("D", _D, _D_TRUE)):
        part = table[keys + [truth]].copy()
        part["parameter"] = kind + "_" + part["joint"]
        part["value"] = table[value].where(shown)
        part["truth"] = part.pop(truth)
        long.append(part)
    return pd.concat(long, ignore_index=True), onsets


def _means(long: pd.DataFrame, onsets: np.ndarray) -> pd.DataFrame:
    """Across-subject mean per onset and parameter from the long form of :func:`_impedance_long`."""
    values = long.pivot(index="onset_ms", columns=["parameter", "subject"], values="value")
    mean = pd.DataFrame(
        {
            p: (
                values[p].mean(axis=1, skipna=True)
                if p in values.columns.get_level_values(0)
                else pd.Series(np.nan, index=values.index)
            )
            for p in PARAMETERS
        }
    ).reindex(onsets)
    mean.index.name = "onset_ms"
    mean.columns.name = None
    return mean


def impedance_means(table: pd.DataFrame, source: str = "impedance table") -> pd.DataFrame:
    """Across-subject mean of K and D per onset, as drawn by :func:`impedance_figure`.

    Index ``onset_ms`` (all onsets of the table, sorted), columns the
    parameters of :data:`~loper_analysis.constants.PARAMETERS` (``K_hip``,
    ``D_hip``, ...) in their units; NaN where no subject has a value. Only
    rows with ``status`` in :data:`IMPEDANCE_STATUSES_SHOWN` and a finite value count.
    """
    return _means(*_impedance_long(table, source))


def impedance_figure(table: pd.DataFrame, source: str = "impedance table") -> Figure:
    """The study's figure: joint stiffness and damping against perturbation onset.

    Panels: K (top row, N·m/rad) and D (bottom row, N·m·s/rad) for hip and
    knee, plus ankle when the table has ankle values. Each subject is a grey
    line with markers against onset (ms); a subject without a value at an
    onset shows a broken line. The across-subject mean (of the subjects with
    a value at that onset, :func:`impedance_means`) is drawn in black.
    Synthetic subjects (``K_true_nm_per_rad`` / ``D_true_nms_per_rad`` not
    empty) have their truth drawn as small open circles.

    Parameters
    ----------
    table : pandas.DataFrame
        Impedance table (``results/impedance/impedance.tsv``) with at least
        ``subject``, ``onset_ms`` (ms), ``joint``, ``K_nm_per_rad``,
        ``D_nms_per_rad``, ``K_true_nm_per_rad``, ``D_true_nms_per_rad`` and ``status``.
    source : str
        Name of the table (its file), quoted in errors: a missing column, an
        empty table, non-numeric values, an unknown joint or duplicate
        (subject, onset_ms, joint) rows raise
        :class:`~loper_analysis.errors.LoperInputError`.

    Returns the figure.
    """
    long, onsets = _impedance_long(table, source)
    mean = _means(long, onsets)
    joints = [j for j in JOINTS if j != "ankle" or mean[[f"K_{j}", f"D_{j}"]].notna().any().any()]
    plt = pyplot()
    fig, axes = plt.subplots(
        2, len(joints), figsize=(3.3 * len(joints) + 0.6, 5.8), sharex=True, constrained_layout=True, squeeze=False
    )
    with closed_on_error(fig):
        subjects = sorted(long["subject"].unique())
        for c, joint in enumerate(joints):
            for r, kind in enumerate(("K", "D")):
                ax, parameter = axes[r, c], f"{kind}_{joint}"
                part = long[long["parameter"] == parameter]
                for s in subjects:
                    one = part[part["subject"] == s].set_index("onset_ms").reindex(onsets)
                    ax.plot(onsets, one["value"].to_numpy(), color="0.65", lw=0.9, marker="o", ms=3, zorder=2)
                    truth = one["truth"].to_numpy()
                    if np.isfinite(truth).any():
                        ax.plot(
                            onsets, truth, ls="none", marker="o", ms=4.5, mfc="none", mec="tab:blue", mew=0.9, zorder=3
                        )
                ax.plot(onsets, mean[parameter].to_numpy(), color="black", lw=2.0, marker="o", ms=5, zorder=4)
                ax.set_title(parameter)
                ax.set_ylabel(f"{kind} ({PARAMETER_UNITS[parameter]})")
                ax.set_xticks(onsets)
                if r == 1:
                    ax.set_xlabel("perturbation onset (ms)")
        from matplotlib.lines import Line2D

        handles = [
            Line2D([], [], color="0.65", marker="o", ms=3, lw=0.9, label="subject"),
            Line2D([], [], color="black", marker="o", ms=5, lw=2.0, label="mean"),
        ]
        if long["truth"].notna().any():
            handles.append(Line2D([], [], ls="none", marker="o", mfc="none", mec="tab:blue", label="truth"))
        axes[0, 0].legend(handles=handles, fontsize=7, loc="best")
    return fig


def _finish(fig, axes, xlabel: str, title: str | None) -> None:
    """Legend in the first panel (if it has labelled curves), x labels on the bottom row, title."""
    if axes[0, 0].get_legend_handles_labels()[1]:
        axes[0, 0].legend(fontsize=7, loc="best")
    for ax in axes[-1]:
        ax.set_xlabel(xlabel)
    if title:
        fig.suptitle(title)
