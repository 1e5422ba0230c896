"""Transparency of LOPER in minimal-impedance mode (``docs/processing.md``, transparency).

Walking with the device is compared with walking without it:

* :func:`mean_sd`, :func:`rmsd`, :func:`within_subject_sd`, :func:`isv_ave` -
  the statistics of time-normalised joint angles;
* :func:`transparency_table` - RMSD between the mean trajectories with and
  without the device per subject, phase and joint, against the averaged
  inter-stride variability ISV_ave = (2 / n_subjects) · Σ σ_subject; the
  device counts as transparent where RMSD < ISV_ave;
* :func:`transparency_results` - all of it for the pipeline's stride and
  cycle tables, with the study's values beside ours; :class:`TransparencySettings`, the leg and the fewest
  kept strides it follows, from the config.

The study's figure is :func:`loper_analysis.report.figures.transparency.transparency_figure`.
Angles are in rad, forces in N, time in s. Normalised arrays have shape
(n_strides, n_points[, n_joints]) as produced by :func:`loper_analysis.gait.resampling.cut`.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, angle_column
from loper_analysis.errors import LoperInputError, TooFewStridesWarning
from loper_analysis.gait.outliers import MIN_VALID_STRIDES
from loper_analysis.gait.strides import phase_cycles
from loper_analysis.reference import STUDY_INTERACTION_FORCE_N, STUDY_TRANSPARENCY_RAD
from loper_analysis.study_design import PERTURBED_SIDE, TRANSPARENCY_CONDITIONS

__all__ = [
    "TransparencySettings",
    "TRANSPARENCY_PHASES",
    "strides_array",
    "TRANSPARENCY_COLUMNS",
    "mean_sd",
    "rmsd",
    "within_subject_sd",
    "isv_ave",
    "mean_toe_off_pct",
    "transparency_table",
    "TransparencyResults",
    "transparency_results",
]


@dataclass(frozen=True)
class TransparencySettings:
    """How the two walking trials are compared (config ``study.perturbed_side``, ``strides.min_valid_strides``).

    ``side``: the leg whose strides are compared; ``min_strides``: a subject with fewer kept strides in
    either trial is left out of the comparison (its rows keep the counts, with empty metrics).
    """

    side: str = PERTURBED_SIDE
    min_strides: int = MIN_VALID_STRIDES


#: Phases compared (normalised separately: stance HS -> TO, swing TO -> next HS).
TRANSPARENCY_PHASES: tuple[str, ...] = ("stance", "swing")
#: Columns of :func:`transparency_table`.
TRANSPARENCY_COLUMNS: tuple[str, ...] = (
    "subject",
    "phase",
    "joint",
    "n_strides_no_device",
    "n_strides_device",
    "rmsd_rad",
    "sd_rad",
    "isv_ave_rad",
    "transparent",
)


def strides_array(name: str, normalised, min_strides: int = 2) -> np.ndarray:
    """Normalised strides (n_strides >= ``min_strides``, n_points[, k]), finite; ``name`` is quoted in errors."""
    x = np.asarray(normalised, dtype=float)
    if x.ndim not in (2, 3):
        raise LoperInputError(f"{name} must have shape (n_strides, n_points[, k]), got {x.shape}")
    if x.shape[0] < min_strides:
        raise LoperInputError(f"{name} needs >= {min_strides} strides, got {x.shape[0]}")
    bad = np.argwhere(~np.isfinite(x))
    if bad.size:
        raise LoperInputError(f"{name} is not finite at stride {bad[0][0]}, point {bad[0][1]}")
    return x


# --------------------------------------------------------------------------- statistics


def mean_sd(normalised) -> tuple[np.ndarray, np.ndarray]:
    """Mean and SD (``ddof=1``) across strides.

    ``normalised`` has shape (n_strides, n_points[, k]) with >= 2 finite
    strides; returns two arrays of shape (n_points[, k]) in the input's unit.
    """
    x = strides_array("normalised", normalised)
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
        for condition in TRANSPARENCY_CONDITIONS:
            if condition not in conditions:
                raise LoperInputError(f"subject {subject}: condition {condition!r} missing")
            for phase in phases:
                if phase not in conditions[condition]:
                    raise LoperInputError(f"subject {subject}: {condition} lacks phase {phase!r}")
        for phase in phases:
            arrays = {}
            for condition in TRANSPARENCY_CONDITIONS:
                name = f"subject {subject}, {condition}, {phase}"
                x = strides_array(name, conditions[condition][phase])
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
        phase-normalised (:func:`loper_analysis.gait.resampling.normalise`); the two
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
    if isv_condition not in TRANSPARENCY_CONDITIONS:
        raise LoperInputError(f"isv_condition must be one of {TRANSPARENCY_CONDITIONS}, got {isv_condition!r}")
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
            rows.append(
                {
                    "subject": str(subject),
                    "phase": phase,
                    "joint": joint,
                    "n_strides_no_device": arrays["no_device"].shape[0],
                    "n_strides_device": arrays["device"].shape[0],
                    "rmsd_rad": float(r[j]),
                    "sd_rad": float(s[j]),
                }
            )
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


# --------------------------------------------------------------------------- the pipeline's tables


@dataclass
class TransparencyResults:
    """Transparency of a group of subjects (:func:`transparency_results`).

    ``rmsd``: :func:`transparency_table` with the study's ``study_rmsd_rad``
    and ``study_isv_ave_rad``; ``force``: per subject and phase the mean and
    SD over kept strides of the RMS and max |F| (N), summary rows ``all``
    (mean and SD over subjects) and the study's values; for the figure the
    kept stride-normalised angles pooled over subjects per condition
    (``angles_rad``), the interaction force with the device (``force_n``)
    and the mean toe-off per condition (``toe_off_pct``).
    """

    rmsd: pd.DataFrame
    force: pd.DataFrame
    angles_rad: dict[str, np.ndarray]
    force_n: np.ndarray | None
    toe_off_pct: dict[str, float]


def _kept(strides: pd.DataFrame) -> int:
    """Kept unperturbed strides of a stride table."""
    plain = ~strides["perturbed"].astype(bool) if "perturbed" in strides.columns else True
    return int((~strides["removed"].astype(bool) & plain).sum())


def _flagged_rows(subject: str, counts: Mapping[str, int], joints: Sequence[str]) -> list[dict]:
    """Rows with the stride counts and empty metrics: of a subject left out of the comparison, or of the
    group (``all``) when no subject is left to compare."""
    return [
        {
            "subject": str(subject),
            "phase": ph,
            "joint": j,
            "n_strides_no_device": counts["no_device"],
            "n_strides_device": counts["device"],
            "rmsd_rad": np.nan,
            "sd_rad": np.nan,
            "isv_ave_rad": np.nan,
            "transparent": None,
        }
        for ph in TRANSPARENCY_PHASES
        for j in joints
    ]


def transparency_results(
    trials: Mapping[str, Mapping[str, tuple[pd.DataFrame, pd.DataFrame]]],
    side: str = PERTURBED_SIDE,
    min_strides: int = MIN_VALID_STRIDES,
) -> TransparencyResults:
    """Transparency of the device from each subject's stride and cycle tables with and without it.

    ``trials``: ``{subject: {"no_device": (strides, cycles), "device": (strides, cycles)}}``,
    the tables of :func:`loper_analysis.gait.strides.stride_tables` (kept,
    unperturbed strides count). A subject with fewer than ``min_strides``
    (at least 2) kept strides in either condition is left out of the
    comparison, the group rows and the figure, with a
    :class:`~loper_analysis.errors.TooFewStridesWarning`: its rows keep the
    stride counts, their metrics and ``transparent`` are empty. Without any
    subject left, the group rows are empty too and ``angles_rad`` is ``{}``.
    """
    cols = [angle_column(j, side) for j in JOINTS]
    least = max(int(min_strides), 2)
    counts = {
        subject: {c: _kept(conds[c][0]) for c in TRANSPARENCY_CONDITIONS if c in conds}
        for subject, conds in trials.items()
    }
    left_out = {s: n for s, n in counts.items() if len(n) == len(TRANSPARENCY_CONDITIONS) and min(n.values()) < least}
    for subject, n in left_out.items():
        warnings.warn(
            f"subject {subject}: {n['no_device']} kept stride(s) without and {n['device']} with the "
            f"device, fewer than {least}: left out of the transparency analysis",
            TooFewStridesWarning,
            stacklevel=2,
        )
    if left_out:
        return _results_without(trials, left_out, side, least)
    per_subject, force_rows, pooled, pooled_force, toe_off = {}, [], {"no_device": [], "device": []}, [], {}
    for subject, conds in trials.items():
        per_subject[subject] = {}
        for cond, (strides, cycles) in conds.items():
            per_subject[subject][cond] = {ph: phase_cycles(cycles, strides, ph, cols) for ph in TRANSPARENCY_PHASES}
            pooled[cond].append(phase_cycles(cycles, strides, "stride", cols))
            kept = strides[~strides["removed"]]
            toe_off.setdefault(cond, []).append(mean_toe_off_pct(kept))
            if cond == "device":
                pooled_force.append(phase_cycles(cycles, strides, "stride", ["force_n"])[:, :, 0])
                for ph in TRANSPARENCY_PHASES:
                    force_rows.append(
                        {
                            "subject": subject,
                            "phase": ph,
                            "n_strides": len(kept),
                            "rms_force_mean_n": kept[f"rms_force_{ph}_n"].mean(),
                            "rms_force_sd_n": kept[f"rms_force_{ph}_n"].std(ddof=1),
                            "max_abs_force_mean_n": kept[f"max_abs_force_{ph}_n"].mean(),
                            "max_abs_force_sd_n": kept[f"max_abs_force_{ph}_n"].std(ddof=1),
                        }
                    )
    rmsd = transparency_table(per_subject, JOINTS)
    study = pd.DataFrame(
        [
            {"phase": ph, "joint": j, "study_rmsd_rad": r, "study_isv_ave_rad": isv}
            for (ph, j), (r, isv) in STUDY_TRANSPARENCY_RAD.items()
        ]
    )
    rmsd = rmsd.merge(study, on=["phase", "joint"], how="left")
    force = pd.DataFrame(force_rows)
    if len(force):
        summary = (
            force.groupby("phase", sort=False)
            .agg(
                n_strides=("n_strides", "sum"),
                rms_force_mean_n=("rms_force_mean_n", "mean"),
                rms_force_sd_n=("rms_force_mean_n", "std"),
                max_abs_force_mean_n=("max_abs_force_mean_n", "mean"),
                max_abs_force_sd_n=("max_abs_force_mean_n", "std"),
            )
            .reset_index()
            .assign(subject="all")
        )
        force = pd.concat([force, summary[force.columns]], ignore_index=True)
        for i, name in enumerate(
            ("study_rms_force_mean_n", "study_rms_force_sd_n", "study_max_abs_force_mean_n", "study_max_abs_force_sd_n")
        ):
            force[name] = [STUDY_INTERACTION_FORCE_N[ph][i] for ph in force["phase"]]
    return TransparencyResults(
        rmsd=rmsd,
        force=force,
        angles_rad={c: np.concatenate(v) for c, v in pooled.items() if v},
        force_n=np.concatenate(pooled_force) if pooled_force else None,
        toe_off_pct={c: float(np.mean(v)) for c, v in toe_off.items()},
    )


def _results_without(
    trials: Mapping, left_out: Mapping[str, Mapping[str, int]], side: str, least: int
) -> TransparencyResults:
    """:func:`transparency_results` of the other subjects, with the rows of those ``left_out`` in subject order."""
    kept = {s: v for s, v in trials.items() if s not in left_out}
    if kept:
        part = transparency_results(kept, side, least)
        rmsd, force = part.rmsd, part.force
    else:
        part = TransparencyResults(pd.DataFrame(columns=list(TRANSPARENCY_COLUMNS)), pd.DataFrame(), {}, None, {})
        rmsd = pd.DataFrame(_flagged_rows("all", {"no_device": 0, "device": 0}, JOINTS))
        study = pd.DataFrame(
            [
                {"phase": ph, "joint": j, "study_rmsd_rad": r, "study_isv_ave_rad": isv}
                for (ph, j), (r, isv) in STUDY_TRANSPARENCY_RAD.items()
            ]
        )
        rmsd = rmsd.merge(study, on=["phase", "joint"], how="left")
        force = pd.DataFrame()
    rows, force_rows = [], []
    for subject in trials:
        if subject in left_out:
            rows.append(pd.DataFrame(_flagged_rows(subject, left_out[subject], JOINTS)))
            force_rows.append(
                pd.DataFrame(
                    [
                        {"subject": subject, "phase": ph, "n_strides": left_out[subject]["device"]}
                        for ph in TRANSPARENCY_PHASES
                    ]
                )
            )
        else:
            rows.append(rmsd[rmsd["subject"] == str(subject)])
            if len(force):
                force_rows.append(force[force["subject"] == subject])
    rows.append(rmsd[rmsd["subject"] == "all"])
    out = pd.concat(rows, ignore_index=True)
    out["transparent"] = out["transparent"].astype(object).where(out["rmsd_rad"].notna(), None)
    study_cols = [c for c in rmsd.columns if c.startswith("study_")]
    out = out.drop(columns=study_cols).merge(
        rmsd[["phase", "joint", *study_cols]].drop_duplicates(), on=["phase", "joint"], how="left"
    )
    force_rows.append(
        force[force["subject"] == "all"]
        if len(force)
        else pd.DataFrame([{"subject": "all", "phase": ph, "n_strides": 0} for ph in TRANSPARENCY_PHASES])
    )
    force_out = pd.concat(force_rows, ignore_index=True)
    for i, name in enumerate(
        ("study_rms_force_mean_n", "study_rms_force_sd_n", "study_max_abs_force_mean_n", "study_max_abs_force_sd_n")
    ):
        force_out[name] = [STUDY_INTERACTION_FORCE_N[ph][i] for ph in force_out["phase"]]
    force_cols = [
        "subject",
        "phase",
        "n_strides",
        "rms_force_mean_n",
        "rms_force_sd_n",
        "max_abs_force_mean_n",
        "max_abs_force_sd_n",
    ]
    force_out = force_out.reindex(columns=force_cols + [c for c in force_out.columns if c not in force_cols])
    return TransparencyResults(out, force_out, part.angles_rad, part.force_n, part.toe_off_pct)
