"""Transparency of LOPER in minimal-impedance mode (DESIGN.md section 4 "Transparency").

Walking with the device is compared with walking without it:

* :func:`force_phase_metrics` - RMS and peak interaction force per stride and
  phase (stance, swing);
* :func:`mean_sd`, :func:`rmsd`, :func:`within_subject_sd`, :func:`isv_ave` -
  the statistics of time-normalised joint angles;
* :func:`transparency_table` - RMSD between the mean trajectories with and
  without the device per subject, phase and joint, against the averaged
  inter-stride variability ISV_ave = (2 / n_subjects) · Σ σ_subject; the
  device counts as transparent where RMSD < ISV_ave;
* :func:`plot_transparency` - the study's figure (force and joint angles over
  the gait cycle, mean ± SD, with and without the device).

Angles are in rad, forces in N, time in s. Normalised arrays have shape
(n_strides, n_points[, n_joints]) as produced by :func:`loper_analysis.gait.cut`.
"""

from __future__ import annotations

import io
import os
import secrets
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from .constants import JOINTS
from .errors import LoperInputError

__all__ = [
    "CONDITIONS",
    "TRANSPARENCY_PHASES",
    "TRANSPARENCY_COLUMNS",
    "STUDY_TRANSPARENCY_RAD",
    "force_phase_metrics",
    "mean_sd",
    "rmsd",
    "within_subject_sd",
    "isv_ave",
    "mean_toe_off_pct",
    "transparency_table",
    "plot_transparency",
]

#: Walking conditions of the transparency experiment.
CONDITIONS: tuple[str, ...] = ("no_device", "device")
#: Phases compared (normalised separately: stance HS -> TO, swing TO -> next HS).
TRANSPARENCY_PHASES: tuple[str, ...] = ("stance", "swing")
#: Columns of :func:`transparency_table`.
TRANSPARENCY_COLUMNS: tuple[str, ...] = (
    "subject", "phase", "joint", "n_strides_no_device", "n_strides_device",
    "rmsd_rad", "sd_rad", "isv_ave_rad", "transparent",
)
#: The study's values (DESIGN.md section 4): (phase, joint) -> (RMSD, ISV_ave), in rad.
STUDY_TRANSPARENCY_RAD: dict[tuple[str, str], tuple[float, float]] = {
    ("stance", "hip"): (0.024, 0.040),
    ("stance", "knee"): (0.032, 0.062),
    ("stance", "ankle"): (0.017, 0.040),
    ("swing", "hip"): (0.035, 0.059),
    ("swing", "knee"): (0.071, 0.129),
    ("swing", "ankle"): (0.035, 0.064),
}

_PHASE_BOUNDS = {"stance": ("heel_strike_s", "toe_off_s"), "swing": ("toe_off_s", "end_s")}


def _where(source: str) -> str:
    return f"{source}: " if source else ""


def _strides_array(name: str, normalised, min_strides: int = 2) -> np.ndarray:
    x = np.asarray(normalised, dtype=float)
    if x.ndim not in (2, 3):
        raise LoperInputError(f"{name} must have shape (n_strides, n_points[, k]), got {x.shape}")
    if x.shape[0] < min_strides:
        raise LoperInputError(f"{name} needs >= {min_strides} strides, got {x.shape[0]}")
    bad = np.argwhere(~np.isfinite(x))
    if bad.size:
        raise LoperInputError(f"{name} is not finite at stride {bad[0][0]}, point {bad[0][1]}")
    return x


# --------------------------------------------------------------------------- interaction force


def force_phase_metrics(time_s, force_n, stride_table: pd.DataFrame, source: str = "") -> pd.DataFrame:
    """RMS and largest absolute interaction force per stride and phase.

    The phases are half-open sample sets: stance = samples with
    ``heel_strike_s <= t < toe_off_s``, swing = ``toe_off_s <= t < end_s``,
    so every sample belongs to at most one phase. RMS is the root of the mean
    square over those samples (equal weights: uniform sampling assumed).
    ``time_s`` and the stride table must share one clock (synchronised
    robot log and treadmill).

    Parameters
    ----------
    time_s : array_like, shape (n_samples,)
        Times of the force samples in s, finite and strictly increasing.
    force_n : array_like, shape (n_samples,)
        Interaction force in N, finite.
    stride_table : pandas.DataFrame
        Columns ``stride``, ``heel_strike_s``, ``toe_off_s``, ``end_s``
        (:func:`loper_analysis.gait.strides`); every phase must lie inside
        ``time_s[0] .. time_s[-1]`` and hold at least one sample.
    source : str
        Name of the trial, quoted in error messages.

    Returns
    -------
    pandas.DataFrame
        One row per stride and phase (stride order, stance before swing):
        ``stride``, ``phase`` (``stance`` | ``swing``), ``rms_force_n``,
        ``max_abs_force_n`` (N).

    Raises
    ------
    LoperInputError
        Bad shapes, non-finite or non-increasing input, missing columns, a
        phase outside the data or without samples.
    """
    t = np.asarray(time_s, dtype=float)
    f = np.asarray(force_n, dtype=float)
    if t.ndim != 1 or f.shape != t.shape or t.size < 2:
        raise LoperInputError(
            f"{_where(source)}time_s {t.shape} and force_n {f.shape} must be 1-D of equal length >= 2"
        )
    for name, a in (("time_s", t), ("force_n", f)):
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise LoperInputError(f"{_where(source)}{name} is not finite at sample {bad[0]}: {a[bad[0]]}")
    if np.any(np.diff(t) <= 0):
        i = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
        raise LoperInputError(f"{_where(source)}time_s must increase strictly; sample {i} does not")
    needed = {"stride", "heel_strike_s", "toe_off_s", "end_s"}
    if not needed <= set(stride_table.columns):
        raise LoperInputError(
            f"{_where(source)}stride_table lacks column(s) {sorted(needed - set(stride_table.columns))}"
        )
    square = np.concatenate([[0.0], np.cumsum(f * f)])
    absf = np.abs(f)
    rms, peak = [], []
    for phase in TRANSPARENCY_PHASES:
        a = stride_table[_PHASE_BOUNDS[phase][0]].to_numpy(float)
        b = stride_table[_PHASE_BOUNDS[phase][1]].to_numpy(float)
        out = np.flatnonzero(~((a >= t[0]) & (b <= t[-1]) & (a < b)))
        if out.size:
            r = out[0]
            raise LoperInputError(
                f"{_where(source)}stride {stride_table['stride'].iloc[r]} {phase} "
                f"({float(a[r])!r} .. {float(b[r])!r} s) "
                f"is empty or outside the force data ({float(t[0])!r} .. {float(t[-1])!r} s)"
            )
        lo = np.searchsorted(t, a, side="left")
        hi = np.searchsorted(t, b, side="left")
        empty = np.flatnonzero(hi <= lo)
        if empty.size:
            r = empty[0]
            raise LoperInputError(
                f"{_where(source)}stride {stride_table['stride'].iloc[r]} {phase} holds no force sample"
            )
        rms.append(np.sqrt((square[hi] - square[lo]) / (hi - lo)))
        peak.append(np.array([absf[i:j].max() for i, j in zip(lo, hi)]))  # a loop per stride, not per sample
    n_phases = len(TRANSPARENCY_PHASES)
    return pd.DataFrame({
        "stride": np.repeat(stride_table["stride"].to_numpy(), n_phases),
        "phase": np.tile(TRANSPARENCY_PHASES, len(stride_table)),
        "rms_force_n": np.column_stack(rms).ravel(),
        "max_abs_force_n": np.column_stack(peak).ravel(),
    })


# --------------------------------------------------------------------------- statistics


def mean_sd(normalised) -> tuple[np.ndarray, np.ndarray]:
    """Mean and SD (``ddof=1``) across strides.

    ``normalised`` has shape (n_strides, n_points[, k]) with >= 2 finite
    strides; returns two arrays of shape (n_points[, k]) in the input's unit.
    """
    x = _strides_array("normalised", normalised)
    return x.mean(axis=0), x.std(axis=0, ddof=1)


def rmsd(mean_a, mean_b):
    """Root-mean-square difference over normalised time.

    ``sqrt(mean_t (a - b)^2)`` over axis 0 of two arrays of shape
    (n_points,) or (n_points, k) (e.g. mean trajectories with and without the
    device); returns a float, or shape (k,) per signal, in the input's unit.
    """
    a = np.asarray(mean_a, dtype=float)
    b = np.asarray(mean_b, dtype=float)
    if a.shape != b.shape or a.ndim not in (1, 2) or a.shape[0] < 1:
        raise LoperInputError(f"mean_a {a.shape} and mean_b {b.shape} must share a shape (n_points[, k])")
    if not (np.isfinite(a).all() and np.isfinite(b).all()):
        raise LoperInputError("mean_a and mean_b must be finite")
    r = np.sqrt(np.mean((a - b) ** 2, axis=0))
    return float(r) if r.ndim == 0 else r


def within_subject_sd(normalised):
    """σ of one subject: the across-stride SD (``ddof=1``) averaged over normalised time.

    ``normalised`` has shape (n_strides, n_points[, k]); returns a float, or
    shape (k,) per signal. Which strides go in (device or no-device
    condition) is the caller's choice; :func:`transparency_table` uses the
    no-device strides unless told otherwise.
    """
    _, sd = mean_sd(normalised)
    s = sd.mean(axis=0)
    return float(s) if s.ndim == 0 else s


def isv_ave(sigmas):
    """Averaged inter-stride variability ISV_ave = (2 / n_subjects) · Σ σ_subject.

    Parameters
    ----------
    sigmas : array_like, shape (n_subjects,) or (n_subjects, k)
        σ per subject (:func:`within_subject_sd`), in the angle unit. By the
        study's convention σ comes from the strides **without** the device
        (natural variability); the choice is made where σ is computed.

    Returns
    -------
    float or numpy.ndarray of shape (k,)
        Twice the mean σ (the width of a ±1 SD band), per signal.
    """
    s = np.asarray(sigmas, dtype=float)
    if s.ndim not in (1, 2) or s.shape[0] < 1:
        raise LoperInputError(f"sigmas must have shape (n_subjects[, k]) with >= 1 subject, got {s.shape}")
    if not np.isfinite(s).all() or (s < 0).any():
        raise LoperInputError(f"sigmas must be finite and >= 0, got {s.tolist()}")
    v = 2.0 / s.shape[0] * s.sum(axis=0)
    return float(v) if v.ndim == 0 else v


def mean_toe_off_pct(stride_table: pd.DataFrame) -> float:
    """Mean toe-off in % of the stride: ``100 · mean(stance_s / duration_s)``."""
    if not {"stance_s", "duration_s"} <= set(stride_table.columns) or not len(stride_table):
        raise LoperInputError("stride_table needs columns stance_s, duration_s and >= 1 stride")
    return float(100.0 * np.mean(stride_table["stance_s"].to_numpy(float) / stride_table["duration_s"].to_numpy(float)))


# --------------------------------------------------------------------------- table


def _subject_arrays(per_subject: Mapping, phases: Sequence[str], k: int):
    for subject, conditions in per_subject.items():
        if str(subject) == "all":
            raise LoperInputError("subject ID 'all' is reserved for the summary rows")
        for condition in CONDITIONS:
            if condition not in conditions:
                raise LoperInputError(f"subject {subject}: condition {condition!r} missing")
            for phase in phases:
                if phase not in conditions[condition]:
                    raise LoperInputError(f"subject {subject}: {condition} lacks phase {phase!r}")
        for phase in phases:
            arrays = {}
            for condition in CONDITIONS:
                name = f"subject {subject}, {condition}, {phase}"
                x = _strides_array(name, conditions[condition][phase])
                if x.ndim != 3 or x.shape[2] != k:
                    raise LoperInputError(f"{name}: shape must be (n_strides, n_points, {k}), got {x.shape}")
                arrays[condition] = x
            if arrays["device"].shape[1] != arrays["no_device"].shape[1]:
                raise LoperInputError(
                    f"subject {subject}, {phase}: device and no_device differ in n_points "
                    f"({arrays['device'].shape[1]} vs {arrays['no_device'].shape[1]})"
                )
            yield subject, phase, arrays


def transparency_table(
    per_subject: Mapping[str, Mapping[str, Mapping[str, np.ndarray]]],
    joints: Sequence[str] = JOINTS,
    isv_condition: str = "no_device",
    phases: Sequence[str] = TRANSPARENCY_PHASES,
) -> pd.DataFrame:
    """RMSD with versus without the device against ISV_ave, per subject, phase and joint.

    Per subject and phase, strides are averaged within each condition; the
    RMSD between the two mean trajectories is taken over the normalised
    samples (:func:`rmsd`). σ_subject (:func:`within_subject_sd`) is
    computed from the strides of ``isv_condition`` - by default
    ``"no_device"``, the natural variability of walking. Per phase and joint,
    ISV_ave = (2 / n_subjects) · Σ σ_subject (:func:`isv_ave`).

    Parameters
    ----------
    per_subject : mapping
        ``{subject: {"device" | "no_device": {"stance" | "swing": array}}}``;
        each array has shape (n_strides >= 2, n_points, n_joints) in rad,
        phase-normalised (:func:`loper_analysis.gait.normalise`); the two
        conditions of a subject and phase share ``n_points``.
    joints : sequence of str
        Names of the last axis, in order.
    isv_condition : {"no_device", "device"}
        Condition whose strides give σ_subject.
    phases : sequence of str
        Phases to compare.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`TRANSPARENCY_COLUMNS`, rows ordered subject (input
        order, then ``"all"``), phase, joint:

        ``subject``
            Subject ID; ``"all"`` for the group summary.
        ``phase``, ``joint``
        ``n_strides_no_device``, ``n_strides_device``
            Strides averaged (summary: totals over subjects).
        ``rmsd_rad``
            RMSD of the mean trajectories (summary: mean over subjects).
        ``sd_rad``
            σ_subject from ``isv_condition`` (summary: mean σ over subjects).
        ``isv_ave_rad``
            ISV_ave of the group, the same on every row of a phase and joint.
        ``transparent``
            ``rmsd_rad < isv_ave_rad``. On a summary row this is the study's
            criterion; on a subject row it compares that subject's RMSD with the group ISV_ave.

        ``attrs``: ``isv_condition``, ``n_subjects``.

    Raises
    ------
    LoperInputError
        No subject, a missing condition or phase, bad shapes, fewer than 2
        strides, non-finite angles, the reserved subject ID ``"all"``, an
        unknown ``isv_condition``.
    """
    if isv_condition not in CONDITIONS:
        raise LoperInputError(f"isv_condition must be one of {CONDITIONS}, got {isv_condition!r}")
    if not per_subject:
        raise LoperInputError("per_subject holds no subject")
    joints = [str(j) for j in joints]
    rows = []
    for subject, phase, arrays in _subject_arrays(per_subject, phases, len(joints)):
        mean_dev = arrays["device"].mean(axis=0)
        mean_nod = arrays["no_device"].mean(axis=0)
        r = rmsd(mean_dev, mean_nod)
        s = within_subject_sd(arrays[isv_condition])
        for j, joint in enumerate(joints):
            rows.append({
                "subject": str(subject), "phase": phase, "joint": joint,
                "n_strides_no_device": arrays["no_device"].shape[0],
                "n_strides_device": arrays["device"].shape[0],
                "rmsd_rad": float(r[j]), "sd_rad": float(s[j]),
            })
    table = pd.DataFrame(rows)
    group = table.groupby(["phase", "joint"], sort=False)
    summary = group.agg(
        n_strides_no_device=("n_strides_no_device", "sum"),
        n_strides_device=("n_strides_device", "sum"),
        rmsd_rad=("rmsd_rad", "mean"),
        sd_rad=("sd_rad", "mean"),
    ).reset_index()
    summary["isv_ave_rad"] = [isv_ave(g["sd_rad"].to_numpy()) for _, g in group]
    summary.insert(0, "subject", "all")
    isv = summary.set_index(["phase", "joint"])["isv_ave_rad"]
    table["isv_ave_rad"] = isv.reindex(pd.MultiIndex.from_frame(table[["phase", "joint"]])).to_numpy()
    out = pd.concat([table, summary], ignore_index=True)
    out["transparent"] = out["rmsd_rad"] < out["isv_ave_rad"]
    out = out[list(TRANSPARENCY_COLUMNS)]
    out.attrs.update({"isv_condition": isv_condition, "n_subjects": len(per_subject)})
    return out


# --------------------------------------------------------------------------- figure


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save_png_atomic(fig, out_png: Path) -> None:
    """Render to memory, write a temporary file beside ``out_png`` (mode honours the umask), rename it over."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110, metadata={"Software": None})
    tmp = out_png.with_name(f".{out_png.name}.{secrets.token_hex(6)}.tmp")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(buffer.getvalue())
        os.replace(tmp, out_png)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def plot_transparency(
    out_png,
    angles_rad: Mapping[str, np.ndarray],
    force_n=None,
    toe_off_pct: float | Mapping[str, float] | None = None,
    joints: Sequence[str] = JOINTS,
    title: str | None = None,
) -> None:
    """The transparency figure: interaction force and joint angles over the gait cycle.

    Panels top to bottom: interaction force (device only), then one panel per
    joint; each curve is the mean across strides with ±1 SD shaded, against
    0-100 % of the stride. Angles are drawn in degrees (converted here).
    Dashed vertical lines mark the mean toe-off of each condition. Written
    atomically as PNG.

    Parameters
    ----------
    out_png : path
        Output file; its directory must exist.
    angles_rad : mapping
        ``{"no_device" | "device": array (n_strides >= 2, n_points, n_joints)}``,
        stride-normalised joint angles in rad (either condition may be absent,
        not both).
    force_n : array_like, shape (n_strides >= 2, n_points), optional
        Stride-normalised interaction force in N (device condition).
    toe_off_pct : float or mapping, optional
        Mean toe-off in % of the stride (:func:`mean_toe_off_pct`), one value
        or one per condition.
    joints : sequence of str
        Names of the joint axis.
    title : str, optional
        Figure title.
    """
    conditions = [c for c in CONDITIONS if c in angles_rad]
    if not conditions or set(angles_rad) - set(CONDITIONS):
        raise LoperInputError(f"angles_rad must map some of {CONDITIONS} to arrays, got {sorted(angles_rad)}")
    joints = [str(j) for j in joints]
    data = {}
    for c in conditions:
        x = _strides_array(f"angles_rad[{c!r}]", angles_rad[c])
        if x.ndim != 3 or x.shape[2] != len(joints):
            raise LoperInputError(
                f"angles_rad[{c!r}] must have shape (n_strides, n_points, {len(joints)}), got {x.shape}"
            )
        data[c] = x
    force = None if force_n is None else _strides_array("force_n", force_n)
    if force is not None and force.ndim != 2:
        raise LoperInputError(f"force_n must have shape (n_strides, n_points), got {force.shape}")
    if isinstance(toe_off_pct, Mapping):
        toe_off = {c: float(v) for c, v in toe_off_pct.items() if c in conditions}
    elif toe_off_pct is not None:
        toe_off = {c: float(toe_off_pct) for c in conditions}
    else:
        toe_off = {}
    out_png = Path(out_png)
    if not out_png.parent.is_dir():
        raise LoperInputError(f"out_png: directory {out_png.parent} does not exist")

    plt = _pyplot()
    colors = {"no_device": "0.35", "device": "tab:blue"}
    labels = {"no_device": "without device", "device": "with device"}
    n_panels = len(joints) + (force is not None)
    fig, axes = plt.subplots(n_panels, 1, figsize=(5.5, 2.0 * n_panels + 0.6), sharex=True,
                             constrained_layout=True, squeeze=False)
    axes = axes[:, 0]

    def band(ax, x, color, label):
        m, s = x.mean(axis=0), x.std(axis=0, ddof=1)
        pct = np.linspace(0.0, 100.0, m.size)
        ax.plot(pct, m, color=color, lw=1.5, label=label)
        ax.fill_between(pct, m - s, m + s, color=color, alpha=0.25, lw=0)

    panel = 0
    if force is not None:
        band(axes[0], force, colors["device"], f"{labels['device']} (n = {force.shape[0]})")
        axes[0].axhline(0, color="0.6", lw=0.8)
        axes[0].set_ylabel("interaction force (N)")
        panel = 1
    for j, joint in enumerate(joints):
        ax = axes[panel + j]
        for c in conditions:
            band(ax, np.degrees(data[c][:, :, j]), colors[c], f"{labels[c]} (n = {data[c].shape[0]})")
        ax.set_ylabel(f"{joint} angle (deg)")
    for ax in axes:
        for c, pct in toe_off.items():
            ax.axvline(pct, color=colors[c], ls="--", lw=1)
    axes[panel].legend(frameon=False, fontsize=8)
    if force is not None:
        axes[0].legend(frameon=False, fontsize=8)
    axes[-1].set_xlim(0, 100)
    axes[-1].set_xlabel("gait cycle (%)  -  dashed: mean toe-off")
    if title:
        fig.suptitle(title)
    try:
        _save_png_atomic(fig, out_png)
    finally:
        plt.close(fig)
