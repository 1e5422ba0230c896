"""File-level steps of the processing chain (DESIGN.md sections 1 and 4), one function per workflow rule.

Each step reads its inputs from disk, calls the library and writes exactly its
declared outputs, each atomically (a temporary file beside the target, then
:func:`os.replace`), so a failed step leaves nothing half-written. Messages of
:class:`~loper_analysis.errors.LoperInputError` name the file and the cause.

Chain: raw C3D -> :func:`process_markers` (gap fill, lab -> model frame,
zero-phase low-pass, TRC) -> :func:`model_generic` / :func:`model_scaled` /
:func:`model_segments` -> :func:`ik_chunk` / :func:`ik_join` (OpenSim IK,
.mot + angle table) -> :func:`detect_events` (GRF) -> :func:`loadcell_forces`
(robot log on the mocap clock) -> :func:`cut_strides` (strides, IQR outliers)
-> :func:`transparency_tables`.
"""

from __future__ import annotations

import logging
import os
import secrets
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import LoperInputError

__all__ = [
    "write_tsv",
    "process_markers",
    "model_generic",
    "model_scaled",
    "model_segments",
    "ik_weights",
    "ik_chunk",
    "ik_join",
    "detect_events",
    "loadcell_forces",
    "cut_strides",
    "read_cycles",
    "stride_summary",
    "transparency_tables",
]

log = logging.getLogger(__name__)


def _partial(path: Path) -> Path:
    return path.with_name(f".{path.name}.{secrets.token_hex(4)}.partial{path.suffix}")


def write_tsv(frame: pd.DataFrame, path: str | os.PathLike, float_format: str = "%.9g") -> None:
    """Write a tidy TSV atomically (same frame -> same bytes)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _partial(path)
    try:
        frame.to_csv(tmp, sep="\t", index=False, float_format=float_format, lineterminator="\n")
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def _atomic(path: Path, writer) -> None:
    """Call ``writer(tmp_path)`` and move the result to ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _partial(path)
    try:
        writer(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


# ---------------------------------------------------------------------------
# markers


def process_markers(
    c3d_path,
    trc_out,
    gaps_out=None,
    rotation_deg: Sequence[float] = (-90.0, 0.0, 0.0),
    max_gap_frames: int = 10,
    cutoff_hz: float = 40.0,
    order: int = 4,
    duration_s: float | None = None,
) -> pd.DataFrame:
    """C3D markers -> gap fill -> lab-to-model rotation -> zero-phase low-pass -> TRC (mm).

    ``duration_s`` keeps only the first part of the trial (static trials).
    Returns the table of filled gaps (written to ``gaps_out`` when given).
    """
    from .filtering import lowpass
    from .io.c3d import read_c3d
    from .io.tables import write_trc
    from .markers import fill_gaps, rotate_markers

    rec = read_c3d(c3d_path)
    time_s, X = rec.time_s, rec.markers_m
    if duration_s is not None:
        keep = time_s < time_s[0] + duration_s - 1e-9
        time_s, X = time_s[keep], X[keep]
    filled, gaps = fill_gaps(X, max_gap_frames, rec.marker_labels, source=str(c3d_path))
    X = rotate_markers(filled, rotation_deg)
    try:
        X = lowpass(X, rec.point_rate_hz, cutoff_hz, order, axis=0)
    except LoperInputError as exc:
        raise LoperInputError(f"{c3d_path}: markers: {exc}") from None
    log.info("%s: %d frames at %g Hz, %d markers, %d gap(s) filled", c3d_path, len(time_s), rec.point_rate_hz,
             len(rec.marker_labels), len(gaps))
    write_trc(trc_out, time_s, X, rec.marker_labels)  # atomic, header names the file itself
    if gaps_out is not None:
        write_tsv(gaps, gaps_out)
    return gaps


# ---------------------------------------------------------------------------
# model


def model_generic(out_osim, height_m: float, mass_kg: float) -> None:
    """The generic lower-body model (:func:`loper_analysis.model.build_lower_body_model`) for this subject."""
    from .model import build_lower_body_model

    _atomic(Path(out_osim), lambda tmp: build_lower_body_model(height_m, mass_kg, tmp))


def model_scaled(generic_osim, static_trc, out_osim, mass_kg: float) -> None:
    """Scale the generic model to the static trial (OpenSim ScaleTool)."""
    from .model import scale_model

    scale_model(generic_osim, static_trc, mass_kg, out_osim)


def model_segments(model_osim, out_tsv, side: str = "left", height_m: float | None = None,
                   mass_kg: float | None = None, user_model: bool = False) -> None:
    """Segment table of the swing leg (TSV) for the dynamics model.

    From the scaled model; for a user-supplied model (whose bodies need not be
    ours) from Winter's table with the subject's height and mass.
    """
    from .dynamics import segment_parameters_from_anthropometry
    from .model import segment_parameters_from_model

    if user_model:
        if height_m is None or mass_kg is None:
            raise LoperInputError(f"{model_osim}: a user model needs the subject's height_m and mass_kg for its segment table")
        params = segment_parameters_from_anthropometry(height_m, mass_kg)
    else:
        params = segment_parameters_from_model(model_osim, side=side[0])
    _atomic(Path(out_tsv), params.to_tsv)


# ---------------------------------------------------------------------------
# inverse kinematics


def ik_weights(model_osim, labels: Sequence[str], tasks_file=None, default_weight: float = 1.0,
               marker_weights: Mapping[str, float] | None = None,
               coordinate_tasks: Mapping[str, Mapping] | None = None, source: str = ""):
    """Marker weights and coordinate tasks for a trial.

    From ``tasks_file`` (OpenSim XML or TSV) when given; otherwise every model
    marker gets ``marker_weights.get(marker, default_weight)``. A weighted model
    marker absent from the trial is an error naming it and the file.
    """
    from .kinematics import read_ik_tasks
    from .model import quiet_opensim

    if tasks_file:
        weights, coords = read_ik_tasks(tasks_file)
    else:
        osim = quiet_opensim()
        model = osim.Model(str(model_osim))
        ms = model.getMarkerSet()
        names = [ms.get(i).getName() for i in range(ms.getSize())]
        extra = sorted(set(marker_weights or {}) - set(names))
        if extra:
            raise LoperInputError(f"opensim.marker_weights: marker(s) {extra} are not in model {model_osim}")
        weights = {m: float((marker_weights or {}).get(m, default_weight)) for m in names}
        coords = {c: (float(v["weight"]), v.get("value")) for c, v in (coordinate_tasks or {}).items()}
    missing = [m for m, w in weights.items() if w > 0 and m not in labels]
    if missing:
        raise LoperInputError(f"{source}: marker(s) {missing} of the model's marker set are missing from the file")
    return weights, coords


def ik_chunk(model_osim, trc_path, out_mot, chunk: int, n_chunks: int, tasks_file=None,
             default_weight: float = 1.0, marker_weights=None, coordinate_tasks=None, accuracy: float = 1e-6
             ) -> pd.DataFrame:
    """IK of time chunk ``chunk`` of ``n_chunks`` of a TRC; writes a .mot (degrees), returns the coordinates."""
    from .io.tables import read_markers, write_mot
    from .kinematics import chunk_frames, inverse_kinematics

    time_s, X, labels = read_markers(trc_path)
    weights, coords = ik_weights(model_osim, labels, tasks_file, default_weight, marker_weights, coordinate_tasks,
                                 source=str(trc_path))
    sel = chunk_frames(len(time_s), n_chunks, chunk)
    res = inverse_kinematics(model_osim, time_s[sel], X[sel], labels, weights, coords, accuracy=accuracy)
    log.info("%s chunk %d/%d: %d frames, marker RMS error mean %.2f mm, max %.2f mm", trc_path, chunk, n_chunks,
             len(res.time_s), 1e3 * np.nanmean(res.marker_rms_m), 1e3 * np.nanmax(res.marker_max_m))
    frame = res.frame()
    write_mot(out_mot, frame, in_degrees=True)
    return frame


def ik_trial(model_osim, trc_path, out_mot, angles_tsv, coordinate_map=None, tasks_file=None,
             default_weight: float = 1.0, marker_weights=None, coordinate_tasks=None, accuracy: float = 1e-6
             ) -> pd.DataFrame:
    """IK of a whole TRC in one go: the .mot (degrees) and the tidy angle table that :func:`ik_join` gives."""
    from .kinematics import joint_angle_table

    coords = ik_chunk(model_osim, trc_path, out_mot, 0, 1, tasks_file, default_weight, marker_weights,
                      coordinate_tasks, accuracy)
    angles = joint_angle_table(coords, coordinate_map, source=str(out_mot))
    write_tsv(angles, angles_tsv)
    return angles


def ik_join(chunk_mots: Sequence, out_mot, angles_tsv, coordinate_map=None) -> pd.DataFrame:
    """Join IK chunks into one .mot and the tidy angle table (rad, m; :data:`kinematics.ANGLE_COLUMNS`)."""
    from .io.tables import read_mot, write_mot
    from .kinematics import join_chunks, joint_angle_table

    frames = [read_mot(p) for p in chunk_mots]
    coords = join_chunks(frames, [str(p) for p in chunk_mots])
    angles = joint_angle_table(coords, coordinate_map, source=str(chunk_mots[0]))
    write_mot(out_mot, coords, in_degrees=True)
    write_tsv(angles, angles_tsv)
    return angles


# ---------------------------------------------------------------------------
# events and forces


def detect_events(c3d_path, out_tsv, grf_channels: Mapping[str, str], threshold_on_n: float = 50.0,
                  threshold_off_n: float = 20.0, min_stance_s: float = 0.2, min_swing_s: float = 0.2,
                  cutoff_hz: float | None = None, order: int = 4) -> pd.DataFrame:
    """Heel strikes and toe-offs of both legs from the belts' vertical GRF, on the mocap clock.

    ``cutoff_hz`` low-passes the GRF first (zero-phase Butterworth); None
    thresholds the raw force (the hysteresis rejects noise, and a filter would
    smear the unloading at toe-off: 40 Hz moves a 20 N toe-off threshold by
    about 4.5 ms).
    """
    from .filtering import lowpass
    from .gait import gait_events
    from .io.c3d import read_c3d

    rec = read_c3d(c3d_path)
    tables = []
    for side in ("left", "right"):
        fz = rec.analog(grf_channels[side])
        if cutoff_hz is not None:
            fz = lowpass(fz, rec.analog_rate_hz, cutoff_hz, order)
        tables.append(gait_events(rec.analog_time_s, fz, side, threshold_on_n, threshold_off_n, min_stance_s,
                                  min_swing_s, source=f"{c3d_path} ({grf_channels[side]})"))
    events = pd.concat(tables, ignore_index=True).sort_values(["time_s", "side"], kind="stable", ignore_index=True)
    write_tsv(events, out_tsv)
    return events


def loadcell_forces(c3d_path, log_path, out_tsv, sync_channel: str = "sync", cutoff_hz: float = 40.0,
                    order: int = 4) -> pd.DataFrame:
    """The robot log's forces on the mocap frames (sync-pulse clock map, 40 Hz low-pass, 128 Hz)."""
    from .io.c3d import read_c3d
    from .io.robot_log import read_robot_log
    from .loadcell import robot_log_on_mocap_frames

    rec = read_c3d(c3d_path)
    frame, meta = read_robot_log(log_path)
    rate = float(meta["sample_rate_hz"])
    out = robot_log_on_mocap_frames(frame, rate, rec.analog(sync_channel), rec.analog_rate_hz, rec.time_s,
                                    cutoff_hz=cutoff_hz, order=order, source=f"{log_path} / {c3d_path}")
    cm = out.attrs.get("clock_map")
    if cm is not None:
        log.info("%s: clock map %s", log_path, cm)
    write_tsv(out, out_tsv)
    return out


# ---------------------------------------------------------------------------
# strides and outliers


def _joint_columns(side: str) -> list[str]:
    from .constants import JOINTS

    return [f"{j}_{side}_rad" for j in JOINTS]


def cut_strides(angles_tsv, events_tsv, strides_out, cycles_out, force_tsv=None, side: str = "left",
                n_points: int = 101, whisker: float = 1.5, max_fraction: float = 0.2, min_valid: int = 5) -> pd.DataFrame:
    """Strides of one leg, their outlier verdicts and the time-normalised cycles.

    Strides run heel strike to heel strike of ``side`` (events from the GRF),
    kept only where the joint angles cover them. Outliers: DESIGN.md section 4
    on the stride-normalised hip, knee and ankle angles
    (:func:`loper_analysis.gait.iqr_outliers`). Writes

    * ``strides_out``: one row per stride, absolute times (s) for perturbation
      windows, ``perturbed`` and its ``onset_s`` (from the robot log's
      perturbation flag), ``fraction_outlying_*``, ``removed``, ``reason`` and,
      with a force file, RMS and max |F| per phase (N). The outlier rule runs
      on the unperturbed strides; perturbed strides are kept for the response
      analysis (``reason`` = ``perturbed``), which judges them in their window;
    * ``cycles_out``: one row per stride x phase (stride, stance, swing) x
      normalised sample: ``stride``, ``phase``, ``point``, ``percent``, the
      joint angles (rad) and ``force_n`` (with a force file).

    Fewer than ``min_valid`` kept strides: a :class:`gait.TooFewStridesWarning`
    and ``attrs["too_few_strides"]`` (the caller flags the trial).
    """
    from .gait import PHASES, check_enough_strides, iqr_outliers, normalise, strides
    from .transparency import force_phase_metrics

    angles = pd.read_csv(angles_tsv, sep="\t")
    events = pd.read_csv(events_tsv, sep="\t")
    cols = _joint_columns(side)
    missing = [c for c in cols if c not in angles.columns]
    if missing:
        raise LoperInputError(f"{angles_tsv}: column(s) {missing} missing")
    table = strides(events, side)
    t = angles["time_s"].to_numpy(float)
    inside = (table["heel_strike_s"] >= t[0]) & (table["end_s"] <= t[-1])
    table = table[inside].reset_index(drop=True)
    table["stride"] = np.arange(len(table))
    if len(table) < 4:
        raise LoperInputError(
            f"{events_tsv}: {len(table)} complete {side} stride(s) inside the kinematics of {angles_tsv}; "
            "need at least 4 for the outlier rule"
        )
    values = angles[cols].to_numpy(float)
    force = None
    if force_tsv is not None:
        f = pd.read_csv(force_tsv, sep="\t")
        if len(f) != len(angles) or not np.allclose(f["time_s"].to_numpy(float), t, atol=1e-6):
            raise LoperInputError(f"{force_tsv}: frames differ from the kinematics in {angles_tsv}")
        force = f["force_measured_n"].to_numpy(float)
        covered = np.isfinite(force)
        ok = [bool(covered[(t >= a) & (t <= b)].all()) for a, b in zip(table.heel_strike_s, table.end_s)]
        if not all(ok):
            log.info("%s: %d stride(s) outside the robot log's span dropped", force_tsv, len(ok) - sum(ok))
            table = table[ok].reset_index(drop=True)
            table["stride"] = np.arange(len(table))
    table["perturbed"] = False
    table["onset_s"] = np.nan
    if force is not None and "perturbation" in f.columns:
        from .loadcell import perturbation_onsets

        onsets = perturbation_onsets(t, f["perturbation"].to_numpy(float))
        for i, (a, b) in enumerate(zip(table.heel_strike_s, table.end_s)):
            inside = onsets[(onsets >= a) & (onsets < b)]
            if inside.size:
                table.loc[i, ["perturbed", "onset_s"]] = (True, inside[0])
    by_stride = normalise(t, values, table, "stride", n_points, source=str(angles_tsv))
    names = [c.split("_")[0] for c in cols]
    plain = ~table["perturbed"].to_numpy()  # perturbed strides are the responses, judged in their window later
    if plain.sum() < 4:
        raise LoperInputError(f"{angles_tsv}: {int(plain.sum())} unperturbed stride(s); need at least 4 for the outlier rule")
    verdict = iqr_outliers(by_stride[plain], whisker, max_fraction, names=names, source=str(angles_tsv))
    verdict["stride"] = table.loc[plain, "stride"].to_numpy()
    out = table.merge(verdict, on="stride", how="left")
    out["removed"] = out["removed"].fillna(False).astype(bool)
    out.loc[out["perturbed"], "reason"] = "perturbed"
    out["reason"] = out["reason"].fillna("")
    if force is not None:
        metrics = force_phase_metrics(t, force, table, source=str(force_tsv))
        wide = metrics.pivot(index="stride", columns="phase", values=["rms_force_n", "max_abs_force_n"])
        wide.columns = [f"{m.removesuffix('_n')}_{ph}_n" for m, ph in wide.columns]
        out = out.merge(wide.reset_index(), on="stride")
    n_kept = int((~out["removed"] & ~out["perturbed"]).sum())
    log.info("%s: %d strides, %d perturbed, %d removed as outliers, %d unperturbed kept", angles_tsv, len(out),
             int(out["perturbed"].sum()), int(out["removed"].sum()), n_kept)
    for r in out[out["removed"]].itertuples():  # noqa: B007 - one log line per removed stride
        log.info("stride %d removed: %s", r.stride, r.reason)
    out.attrs["too_few_strides"] = not check_enough_strides(n_kept, str(angles_tsv), min_valid)
    cycles = []
    for phase in PHASES:
        arr = normalise(t, values, table, phase, n_points, source=str(angles_tsv))
        block = {
            "stride": np.repeat(table["stride"].to_numpy(), n_points),
            "phase": phase,
            "point": np.tile(np.arange(n_points), len(table)),
            "percent": np.tile(np.linspace(0.0, 100.0, n_points), len(table)),
        }
        for i, c in enumerate(cols):
            block[c] = arr[:, :, i].ravel()
        if force is not None:
            block["force_n"] = normalise(t, force, table, phase, n_points, source=str(force_tsv)).ravel()
        cycles.append(pd.DataFrame(block))
    write_tsv(pd.concat(cycles, ignore_index=True), cycles_out)
    write_tsv(out, strides_out)
    return out


def stride_summary(strides_tsvs: Mapping[tuple[str, str], str], out_tsv, min_valid: int = 5) -> pd.DataFrame:
    """One row per subject x trial: strides found, removed as outliers (and why), kept, and a status.

    ``status`` is ``ok`` or ``too_few_strides`` (fewer than ``min_valid``
    kept: the trial is flagged, not dropped silently).
    """
    rows = []
    for (subject, trial), path in strides_tsvs.items():
        table = pd.read_csv(path, sep="\t", keep_default_na=False, na_values=[""])
        removed = table[table["removed"]]
        signals = [c.removeprefix("fraction_outlying_") for c in table.columns if c.startswith("fraction_outlying_")]
        why = {s: int(removed["reason"].fillna("").str.contains(f"{s}:").sum()) for s in signals}
        perturbed = table["perturbed"].astype(bool) if "perturbed" in table.columns else pd.Series(False, index=table.index)
        n_kept = int((~table["removed"] & ~perturbed).sum())
        rows.append({
            "subject": subject, "trial": trial, "n_strides": len(table), "n_perturbed": int(perturbed.sum()),
            "n_removed": len(removed), "n_kept": n_kept,
            **{f"n_removed_{s}": n for s, n in why.items()},
            "mean_stride_s": table["duration_s"].mean(),
            "status": "ok" if n_kept >= min_valid else "too_few_strides",
        })
    out = pd.DataFrame(rows)
    write_tsv(out, out_tsv)
    return out


def read_cycles(cycles_tsv, strides_tsv, phase: str, columns: Sequence[str], keep_removed: bool = False) -> np.ndarray:
    """Normalised cycles of one phase as (n_strides, n_points, len(columns)); perturbed strides and (unless
    ``keep_removed``) outliers left out."""
    cycles = pd.read_csv(cycles_tsv, sep="\t")
    table = pd.read_csv(strides_tsv, sep="\t")
    plain = ~table["perturbed"].astype(bool) if "perturbed" in table.columns else True
    keep = table.loc[plain, "stride"] if keep_removed else table.loc[~table["removed"] & plain, "stride"]
    sel = cycles[(cycles["phase"] == phase) & cycles["stride"].isin(keep)]
    n_points = int(sel["point"].max()) + 1 if len(sel) else 0
    missing = [c for c in columns if c not in sel.columns]
    if missing:
        raise LoperInputError(f"{cycles_tsv}: column(s) {missing} missing")
    return sel[list(columns)].to_numpy(float).reshape(-1, n_points, len(columns))


def transparency_tables(trials: Mapping[str, Mapping[str, tuple]], rmsd_out, force_out, figure_out,
                        side: str = "left") -> pd.DataFrame:
    """Transparency of the device (DESIGN.md section 4): RMSD vs ISV_ave and the interaction force.

    ``trials``: ``{subject: {"no_device": (strides_tsv, cycles_tsv), "device": (strides_tsv, cycles_tsv)}}``.
    Writes ``rmsd_out`` (:func:`transparency.transparency_table` plus the
    study's values), ``force_out`` (per subject and phase: mean and SD over
    kept strides of the RMS and max |F|, N; summary rows ``all`` = mean and SD
    over subjects, with the study's values) and the figure (first subject
    pooled with the others: all subjects' kept strides).
    """
    from .constants import JOINTS
    from .transparency import STUDY_TRANSPARENCY_RAD, mean_toe_off_pct, plot_transparency, transparency_table

    cols = _joint_columns(side)
    per_subject, force_rows, pooled, pooled_force, toe_off = {}, [], {"no_device": [], "device": []}, [], {}
    for subject, conds in trials.items():
        per_subject[subject] = {}
        for cond, (strides_tsv, cycles_tsv) in conds.items():
            per_subject[subject][cond] = {ph: read_cycles(cycles_tsv, strides_tsv, ph, cols) for ph in ("stance", "swing")}
            pooled[cond].append(read_cycles(cycles_tsv, strides_tsv, "stride", cols))
            table = pd.read_csv(strides_tsv, sep="\t")
            kept = table[~table["removed"]]
            toe_off.setdefault(cond, []).append(mean_toe_off_pct(kept))
            if cond == "device":
                pooled_force.append(read_cycles(cycles_tsv, strides_tsv, "stride", ["force_n"])[:, :, 0])
                for ph in ("stance", "swing"):
                    force_rows.append({
                        "subject": subject, "phase": ph, "n_strides": len(kept),
                        "rms_force_mean_n": kept[f"rms_force_{ph}_n"].mean(),
                        "rms_force_sd_n": kept[f"rms_force_{ph}_n"].std(ddof=1),
                        "max_abs_force_mean_n": kept[f"max_abs_force_{ph}_n"].mean(),
                        "max_abs_force_sd_n": kept[f"max_abs_force_{ph}_n"].std(ddof=1),
                    })
    rmsd = transparency_table(per_subject, JOINTS)
    study = pd.DataFrame([{"phase": ph, "joint": j, "study_rmsd_rad": r, "study_isv_ave_rad": isv}
                          for (ph, j), (r, isv) in STUDY_TRANSPARENCY_RAD.items()])
    rmsd = rmsd.merge(study, on=["phase", "joint"], how="left")
    force = pd.DataFrame(force_rows)
    if len(force):
        summary = force.groupby("phase", sort=False).agg(
            n_strides=("n_strides", "sum"), rms_force_mean_n=("rms_force_mean_n", "mean"),
            rms_force_sd_n=("rms_force_mean_n", "std"), max_abs_force_mean_n=("max_abs_force_mean_n", "mean"),
            max_abs_force_sd_n=("max_abs_force_mean_n", "std")).reset_index().assign(subject="all")
        force = pd.concat([force, summary[force.columns]], ignore_index=True)
        study_force = {"stance": (1.97, 0.21, 4.46, 0.82), "swing": (2.13, 0.30, 4.63, 0.79)}
        for i, name in enumerate(("study_rms_force_mean_n", "study_rms_force_sd_n", "study_max_abs_force_mean_n",
                                  "study_max_abs_force_sd_n")):
            force[name] = [study_force[ph][i] for ph in force["phase"]]
    write_tsv(rmsd, rmsd_out)
    write_tsv(force, force_out)
    Path(figure_out).parent.mkdir(parents=True, exist_ok=True)
    plot_transparency(
        figure_out, {c: np.concatenate(v) for c, v in pooled.items() if v},
        np.concatenate(pooled_force) if pooled_force else None,
        {c: float(np.mean(v)) for c, v in toe_off.items()}, JOINTS,
        title=f"Transparency: {len(trials)} subject(s), kept strides pooled",
    )
    return rmsd
