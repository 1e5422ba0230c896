"""Figures of the swing-phase impedance study, drawn from the pipeline's TSV tables.

* :func:`plot_responses` - mean perturbed and unperturbed joint angles and
  their difference (mean ± SD) after each perturbation onset;
* :func:`plot_fit` - measured response against the model's fit over the fit
  window, per onset and joint;
* :func:`plot_impedance` - the study's figure: stiffness K and damping D per
  joint against perturbation onset, one grey line per subject, the
  across-subject mean in black, the truth of synthetic subjects as open
  circles.

The tables hold angles in rad and time in s; the figures show degrees and ms.
Every PNG is written atomically (temporary file beside the target, then
``os.replace``). Missing or unusable columns raise
:class:`~loper_analysis.errors.LoperInputError` naming file, column and value.
"""

from __future__ import annotations

from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from .constants import JOINTS, PARAMETER_UNITS, PARAMETERS
from .errors import LoperInputError
from .transparency import _pyplot, _save_png_atomic

__all__ = [
    "ANALYSIS_WINDOW_MS",
    "IMPEDANCE_STATUSES_SHOWN",
    "plot_responses",
    "plot_fit",
    "plot_impedance",
]

#: Default analysis window relative to the perturbation onset, ms (used when a
#: response table has no ``analysis_window`` column or no sample flagged).
ANALYSIS_WINDOW_MS: tuple[float, float] = (-25.0, 250.0)
#: Fit statuses whose K/D are drawn in :func:`plot_impedance`.
IMPEDANCE_STATUSES_SHOWN: tuple[str, ...] = ("ok", "not_identifiable")

_RAD_TO_DEG = 180.0 / np.pi


# --------------------------------------------------------------------------- reading


def _read_tsv(path, columns: Sequence[str], numeric: Sequence[str] = ()) -> pd.DataFrame | None:
    """Read a pipeline TSV; ``None`` when it has no data rows (zero bytes or header only).

    Checks that ``columns`` are present (only when there are rows) and that
    ``numeric`` columns hold numbers or blanks.
    """
    path = Path(path)
    if not path.is_file():
        raise LoperInputError(f"{path}: file does not exist")
    if path.stat().st_size == 0:
        return None
    try:
        table = pd.read_csv(path, sep="\t")
    except pd.errors.EmptyDataError:
        return None
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise LoperInputError(f"{path}: not a readable TSV ({exc})") from None
    if table.empty:
        return None
    for column in columns:
        if column not in table.columns:
            raise LoperInputError(f"{path}: missing column {column!r} (has {list(table.columns)})")
    for column in numeric:
        values = pd.to_numeric(table[column], errors="coerce")
        bad = values.isna() & table[column].notna()
        if bad.any():
            raise LoperInputError(
                f"{path}: column {column!r} must be numeric, got {table[column][bad].iloc[0]!r}"
            )
        table[column] = values.astype(float)
    return table


def _check_inputs(name: str, paths: Mapping, out_png) -> tuple[list[tuple[int, Path]], Path]:
    if not isinstance(paths, Mapping) or not paths:
        raise LoperInputError(f"{name} must be a non-empty mapping onset_ms -> path, got {paths!r}")
    items = []
    for onset, path in paths.items():
        try:
            onset_ms = int(onset)
        except (TypeError, ValueError):
            raise LoperInputError(f"{name}: onset key must be an integer (ms), got {onset!r}") from None
        items.append((onset_ms, Path(path)))
    items.sort()
    return items, _check_out(out_png)


def _check_out(out_png) -> Path:
    out_png = Path(out_png)
    if not out_png.parent.is_dir():
        raise LoperInputError(f"out_png: directory {out_png.parent} does not exist")
    return out_png


def _window_ms(table: pd.DataFrame, time_ms: np.ndarray) -> tuple[float, float]:
    """Span of the samples flagged ``analysis_window``, else :data:`ANALYSIS_WINDOW_MS`."""
    if "analysis_window" in table.columns:
        flag = table["analysis_window"].astype(str).str.strip().str.lower().isin(("true", "1", "1.0"))
        if flag.any():
            return float(time_ms[flag.to_numpy()].min()), float(time_ms[flag.to_numpy()].max())
    return ANALYSIS_WINDOW_MS


def _say(ax, text: str) -> None:
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", color="0.4", fontsize=11)
    ax.set_xticks([])
    ax.set_yticks([])


# --------------------------------------------------------------------------- responses


def plot_responses(
    response_tsvs: Mapping[int, str | Path],
    out_png: str | Path,
    title: str | None = None,
) -> pd.DataFrame:
    """Perturbation responses: joint angles with and without perturbation, and their difference.

    One column per onset; per joint two rows: the mean perturbed and mean
    unperturbed joint angle (deg), then their difference perturbed −
    unperturbed (mean ± 1 SD shaded, deg), against time after onset (ms).
    The analysis window (samples flagged ``analysis_window``, default
    −25..250 ms) is shaded lightly. An empty table (no rows: the onset is
    missing) gives a column that says "missing".

    Parameters
    ----------
    response_tsvs : mapping
        ``{onset_ms: path}`` of response TSVs with columns ``time_s`` (s,
        relative to onset), ``{joint}_rad_mean`` and ``{joint}_rad_sd``
        (difference, rad), ``{joint}_perturbed_rad_mean`` and
        ``{joint}_unperturbed_rad_mean`` (rad) for hip, knee, ankle; optional
        ``n_pairs`` and ``analysis_window`` (bool).
    out_png : path
        Output PNG; its directory must exist.
    title : str, optional
        Figure title.

    Returns
    -------
    pandas.DataFrame
        Peak |mean difference| in rad over all samples of each table, index
        ``onset_ms`` (sorted), columns hip, knee, ankle; NaN for missing onsets.

    Raises
    ------
    LoperInputError
        A file is missing, or a non-empty table lacks a column or holds
        non-numeric values.
    """
    items, out_png = _check_inputs("response_tsvs", response_tsvs, out_png)
    columns = ["time_s"]
    for joint in JOINTS:
        columns += [f"{joint}_rad_mean", f"{joint}_rad_sd",
                    f"{joint}_perturbed_rad_mean", f"{joint}_unperturbed_rad_mean"]
    tables = {onset: _read_tsv(path, columns, columns) for onset, path in items}

    peaks = pd.DataFrame(np.nan, index=pd.Index([o for o, _ in items], name="onset_ms"), columns=list(JOINTS))
    plt = _pyplot()
    n_cols, n_rows = len(items), 2 * len(JOINTS)
    fig, axes = plt.subplots(n_rows, n_cols, figsize=(3.2 * n_cols + 0.8, 1.5 * n_rows + 0.8),
                             sharex="col", constrained_layout=True, squeeze=False)
    try:
        for c, (onset, _path) in enumerate(items):
            table = tables[onset]
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
                if np.isfinite(diff).any():
                    peaks.loc[onset, joint] = float(np.nanmax(np.abs(diff)))
                ax_a, ax_d = axes[2 * j, c], axes[2 * j + 1, c]
                for ax in (ax_a, ax_d):
                    ax.axvspan(lo, hi, color="0.92", lw=0, zorder=0)
                    ax.axvline(0.0, color="0.6", lw=0.6, ls=":")
                ax_a.plot(t_ms, table[f"{joint}_unperturbed_rad_mean"].to_numpy() * _RAD_TO_DEG,
                          color="0.35", lw=1.3, label="unperturbed")
                ax_a.plot(t_ms, table[f"{joint}_perturbed_rad_mean"].to_numpy() * _RAD_TO_DEG,
                          color="tab:red", lw=1.3, label="perturbed")
                ax_d.fill_between(t_ms, (diff - sd) * _RAD_TO_DEG, (diff + sd) * _RAD_TO_DEG,
                                  color="tab:red", alpha=0.2, lw=0)
                ax_d.plot(t_ms, diff * _RAD_TO_DEG, color="tab:red", lw=1.3)
                ax_d.axhline(0.0, color="0.6", lw=0.6)
                if c == 0:
                    ax_a.set_ylabel(f"{joint} (deg)")
                    ax_d.set_ylabel(f"Δ{joint} (deg)")
        _finish(fig, axes, "time after onset (ms)", title, out_png)
    finally:
        plt.close(fig)
    return peaks


# --------------------------------------------------------------------------- fit


def plot_fit(
    curves_tsvs: Mapping[int, str | Path],
    out_png: str | Path,
    title: str | None = None,
) -> None:
    """Measured perturbation response against the model's fit, per onset and joint.

    One column per onset, one row per joint (hip, knee, ankle): the measured
    response (grey) and the fitted model response (red), in deg, against
    time (ms, ``time_s`` × 1000 as given). An empty table (only a header:
    the onset was not fitted) gives a column that says "not fitted".

    Parameters
    ----------
    curves_tsvs : mapping
        ``{onset_ms: path}`` of fit-curve TSVs with columns ``time_s`` (s),
        ``{joint}_measured_rad`` and ``{joint}_model_rad`` (rad).
    out_png : path
        Output PNG; its directory must exist.
    title : str, optional
        Figure title.

    Raises
    ------
    LoperInputError
        A file is missing, or a non-empty table lacks a column or holds
        non-numeric values.
    """
    items, out_png = _check_inputs("curves_tsvs", curves_tsvs, out_png)
    columns = ["time_s"] + [f"{j}_{kind}_rad" for j in JOINTS for kind in ("measured", "model")]
    tables = {onset: _read_tsv(path, columns, columns) for onset, path in items}

    plt = _pyplot()
    n_cols, n_rows = len(items), len(JOINTS)
    fig, axes = plt.subplots(n_rows, n_cols, figsize=(3.2 * n_cols + 0.8, 1.9 * n_rows + 0.8),
                             sharex="col", constrained_layout=True, squeeze=False)
    try:
        for c, (onset, _path) in enumerate(items):
            axes[0, c].set_title(f"onset {onset} ms")
            table = tables[onset]
            if table is None:
                for r in range(n_rows):
                    _say(axes[r, c], "not fitted")
                continue
            table = table.sort_values("time_s", kind="stable")
            t_ms = table["time_s"].to_numpy() * 1000.0
            for r, joint in enumerate(JOINTS):
                ax = axes[r, c]
                ax.plot(t_ms, table[f"{joint}_measured_rad"].to_numpy() * _RAD_TO_DEG,
                        color="0.35", lw=1.3, label="measured")
                ax.plot(t_ms, table[f"{joint}_model_rad"].to_numpy() * _RAD_TO_DEG,
                        color="tab:red", lw=1.3, ls="--", label="model")
                ax.axhline(0.0, color="0.7", lw=0.6)
                if c == 0:
                    ax.set_ylabel(f"{joint} (deg)")
        _finish(fig, axes, "time (ms)", title, out_png)
    finally:
        plt.close(fig)


# --------------------------------------------------------------------------- impedance

_IMPEDANCE_COLUMNS = ("subject", "onset_ms", "joint", "K", "D", "K_true", "D_true", "status")


def plot_impedance(impedance_tsv: str | Path, out_png: str | Path) -> pd.DataFrame:
    """The study's figure: joint stiffness and damping against perturbation onset.

    Panels: K (top row, N·m/rad) and D (bottom row, N·m·s/rad) for hip and
    knee, plus ankle when the table has ankle values. Each subject is a grey
    line with markers against onset (ms); a subject without a value at an
    onset shows a broken line. The across-subject mean (of the subjects with
    a value at that onset) is drawn in black. Synthetic subjects (``K_true``
    / ``D_true`` not empty) have their truth drawn as small open circles.
    Only rows with ``status`` in :data:`IMPEDANCE_STATUSES_SHOWN` and a finite
    value count.

    Parameters
    ----------
    impedance_tsv : path
        Impedance table with (at least) columns ``subject``, ``onset_ms``
        (ms), ``joint``, ``K`` (N·m/rad), ``D`` (N·m·s/rad), ``K_true``,
        ``D_true`` and ``status``.
    out_png : path
        Output PNG; its directory must exist.

    Returns
    -------
    pandas.DataFrame
        Across-subject mean, index ``onset_ms`` (all onsets of the table,
        sorted), columns the parameters of :data:`~loper_analysis.constants.PARAMETERS`
        (``K_hip``, ``D_hip``, ...), in their units; NaN where no subject
        has a value.

    Raises
    ------
    LoperInputError
        Missing file or column, an empty table, non-numeric values, an
        unknown joint or duplicate (subject, onset_ms, joint) rows.
    """
    path = Path(impedance_tsv)
    table = _read_tsv(path, _IMPEDANCE_COLUMNS, ("onset_ms", "K", "D", "K_true", "D_true"))
    if table is None:
        raise LoperInputError(f"{path}: impedance table has no rows")
    out_png = _check_out(out_png)
    table["joint"] = table["joint"].astype(str).str.strip()
    unknown = sorted(set(table["joint"]) - set(JOINTS))
    if unknown:
        raise LoperInputError(f"{path}: column 'joint' has unknown value {unknown[0]!r} (expected {JOINTS})")
    if table["onset_ms"].isna().any():
        raise LoperInputError(f"{path}: column 'onset_ms' has an empty value")
    if (table["onset_ms"] == table["onset_ms"].round()).all():
        table["onset_ms"] = table["onset_ms"].astype(int)
    table["subject"] = table["subject"].astype(str)
    keys = ["subject", "onset_ms", "joint"]
    dup = table.duplicated(keys)
    if dup.any():
        row = table.loc[dup, keys].iloc[0]
        raise LoperInputError(f"{path}: duplicate row for subject/onset_ms/joint {tuple(row)!r}")

    onsets = np.sort(table["onset_ms"].unique())
    shown = table["status"].astype(str).str.strip().isin(IMPEDANCE_STATUSES_SHOWN)
    long = []
    for kind in ("K", "D"):
        part = table[keys + [f"{kind}_true"]].copy()
        part["parameter"] = kind + "_" + part["joint"]
        part["value"] = table[kind].where(shown)
        part["truth"] = part.pop(f"{kind}_true")
        long.append(part)
    long = pd.concat(long, ignore_index=True)
    values = long.pivot(index="onset_ms", columns=["parameter", "subject"], values="value")
    mean = pd.DataFrame(
        {p: (values[p].mean(axis=1, skipna=True) if p in values.columns.get_level_values(0)
             else pd.Series(np.nan, index=values.index)) for p in PARAMETERS}
    ).reindex(onsets)
    mean.index.name = "onset_ms"
    mean.columns.name = None

    joints = [j for j in JOINTS if j != "ankle" or mean[[f"K_{j}", f"D_{j}"]].notna().any().any()]
    plt = _pyplot()
    fig, axes = plt.subplots(2, len(joints), figsize=(3.3 * len(joints) + 0.6, 5.8),
                             sharex=True, constrained_layout=True, squeeze=False)
    try:
        subjects = sorted(long["subject"].unique())
        for c, joint in enumerate(joints):
            for r, kind in enumerate(("K", "D")):
                ax, parameter = axes[r, c], f"{kind}_{joint}"
                part = long[long["parameter"] == parameter]
                for s in subjects:
                    one = part[part["subject"] == s].set_index("onset_ms").reindex(onsets)
                    ax.plot(onsets, one["value"].to_numpy(), color="0.65", lw=0.9, marker="o", ms=3,
                            zorder=2)
                    truth = one["truth"].to_numpy()
                    if np.isfinite(truth).any():
                        ax.plot(onsets, truth, ls="none", marker="o", ms=4.5, mfc="none",
                                mec="tab:blue", mew=0.9, zorder=3)
                ax.plot(onsets, mean[parameter].to_numpy(), color="black", lw=2.0, marker="o", ms=5,
                        zorder=4)
                ax.set_title(parameter)
                ax.set_ylabel(f"{kind} ({PARAMETER_UNITS[parameter]})")
                ax.set_xticks(onsets)
                if r == 1:
                    ax.set_xlabel("perturbation onset (ms)")
        from matplotlib.lines import Line2D

        handles = [Line2D([], [], color="0.65", marker="o", ms=3, lw=0.9, label="subject"),
                   Line2D([], [], color="black", marker="o", ms=5, lw=2.0, label="mean")]
        if long["truth"].notna().any():
            handles.append(Line2D([], [], ls="none", marker="o", mfc="none", mec="tab:blue", label="truth"))
        axes[0, 0].legend(handles=handles, fontsize=7, loc="best")
        _save_png_atomic(fig, out_png)
    finally:
        plt.close(fig)
    return mean


def _finish(fig, axes, xlabel: str, title: str | None, out_png) -> None:
    """Legend in the first panel (if it has labelled curves), x labels on the bottom row, title, atomic PNG."""
    if axes[0, 0].get_legend_handles_labels()[1]:
        axes[0, 0].legend(fontsize=7, loc="best")
    for ax in axes[-1]:
        ax.set_xlabel(xlabel)
    if title:
        fig.suptitle(title)
    _save_png_atomic(fig, out_png)
