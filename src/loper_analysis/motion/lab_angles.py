"""The lab's own joint angles stored in a C3D file, and how ours agree with them.

Vicon Nexus stores Plug-in Gait's joint angles as points (``LHipAngles``,
``LKneeAngles``, ``LAnkleAngles``, ``LPelvisAngles`` and the right side's,
often with a suffix: ``LHipAngles_M``, ``LHipAnglesV``), listed in ``POINT:ANGLES``, in the
unit of ``POINT:ANGLE_UNITS`` (degrees). Their x component is the sagittal
angle in our sense: hip and knee flexion, ankle dorsiflexion and anterior
pelvic tilt positive. They were computed by another model from the same
markers, so they are an independent check of ours: a sign, an offset built
into the scaled model or swapped sides show at once.

:func:`lab_joint_angles` picks them out of a recording's non-marker points;
:func:`lab_agreement` compares our angle table with them frame by frame:
Pearson's r, the RMS difference and the mean offset (ours minus the lab's),
with a warning beyond :data:`MIN_LAB_R` or :data:`MAX_LAB_RMS_RAD`. An angle that is not compared (the
file stores no such angle, it holds no number, too few frames in common) is logged with the reason.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

import numpy as np
import pandas as pd

from loper_analysis.errors import LoperInputError

__all__ = [
    "LAB_AGREEMENT_COLUMNS",
    "LAB_ANGLE_STEMS",
    "MAX_LAB_OFFSET_RAD",
    "MAX_LAB_RMS_RAD",
    "MIN_LAB_EXCURSION_RAD",
    "MIN_LAB_R",
    "lab_agreement",
    "lab_agreement_warnings",
    "lab_joint_angles",
    "window_means",
]

#: Our angle -> the stem of the lab's label holding it (x component), Plug-in Gait's names.
LAB_ANGLE_STEMS: dict[str, str] = {
    "pelvis_angle": "LPelvisAngles",
    "hip_left": "LHipAngles",
    "knee_left": "LKneeAngles",
    "ankle_left": "LAnkleAngles",
    "hip_right": "RHipAngles",
    "knee_right": "RKneeAngles",
    "ankle_right": "RAnkleAngles",
}
#: Below this correlation with the lab's angle a joint is warned about.
MIN_LAB_R: float = 0.9
#: Above this RMS difference from the lab's angle (rad; 10 degrees) a joint is warned about.
MAX_LAB_RMS_RAD: float = float(np.radians(10.0))
#: Beyond this mean offset from the lab's angle at the hip or knee (rad; 6 degrees) a joint is warned about: a
#: calibration that bends the static pose shows as a constant offset long before the RMS limit. Seven clinical labs'
#: walks through the joint-centre calibration stay within 4.9 degrees of their own Plug-in Gait (a calibration on the
#: template's marker places gave 6 to 15 degrees).
MAX_LAB_OFFSET_RAD: float = float(np.radians(6.0))
#: The correlation is judged only where the lab's angle moves at least this much (rad; 10 degrees, max - min):
#: the pelvis tilts by 2-4 degrees in walking, where r says more about noise than about agreement.
MIN_LAB_EXCURSION_RAD: float = float(np.radians(10.0))
#: Columns of :func:`lab_agreement`.
LAB_AGREEMENT_COLUMNS: tuple[str, ...] = (
    "angle",
    "n_frames",
    "lab_excursion_rad",
    "r",
    "rms_diff_rad",
    "mean_offset_rad",
    "warning",
)
log = logging.getLogger(__name__)
_ANGLE_UNITS = {"deg": np.pi / 180.0, "degree": np.pi / 180.0, "degrees": np.pi / 180.0, "rad": 1.0, "radian": 1.0}


def _bare(label: str) -> str:
    return str(label).rpartition(":")[2].strip()


def _pick(stem: str, labels: Sequence[str]) -> int | None:
    """Index of the label holding ``stem``: the stem itself, else the first label that is the stem and a suffix
    after ``_`` (``LHipAngles_M``), else the first that is the stem and any suffix (``LHipAnglesV``)."""
    bare = [_bare(lab) for lab in labels]
    if stem in bare:
        return bare.index(stem)
    for prefix in (stem + "_", stem):
        for i, lab in enumerate(bare):
            if lab.startswith(prefix) and lab != stem:
                return i
    return None


def lab_joint_angles(
    time_s: np.ndarray,
    labels: Sequence[str],
    kinds: Sequence[str],
    values: np.ndarray,
    angle_unit: str | None,
    source: str = "",
) -> tuple[pd.DataFrame, dict[str, str]]:
    """The lab's sagittal joint angles among a recording's non-marker points.

    Parameters
    ----------
    time_s : numpy.ndarray
        Frame times (n_frames,), s.
    labels, kinds : sequence of str
        The non-marker points' labels and kinds (:attr:`loper_analysis.io.c3d.C3DRecording.output_labels`,
        ``output_kinds``); only kind ``ANGLES`` is read.
    values : numpy.ndarray
        Their values (n_frames, n_points, 3), as stored; NaN where missing.
    angle_unit : str or None
        ``POINT:ANGLE_UNITS`` (``deg`` or ``rad``); None: degrees, Nexus's unit.
    source : str
        The file, for messages.

    Returns
    -------
    (pandas.DataFrame, dict)
        ``time_s`` and one ``{angle}_rad`` column per angle of :data:`LAB_ANGLE_STEMS` found (none found: only
        ``time_s``), and {angle: the label read}.

    Raises
    ------
    LoperInputError
        An angle unit that is neither degrees nor radians (naming the file and ``POINT:ANGLE_UNITS``).
    """
    unit = (angle_unit or "deg").strip().lower()
    if unit not in _ANGLE_UNITS:
        raise LoperInputError(f"{source}: POINT:ANGLE_UNITS '{angle_unit}' is neither degrees nor radians")
    angles = [(lab, i) for i, (lab, kind) in enumerate(zip(labels, kinds)) if kind == "ANGLES"]
    names = [lab for lab, _ in angles]
    out = {"time_s": np.asarray(time_s, float)}
    used, skipped = {}, {}
    for angle, stem in LAB_ANGLE_STEMS.items():
        k = _pick(stem, names)
        if k is None:
            skipped[angle] = f"no ANGLES point {stem} (with or without a suffix)"
            continue
        column = np.asarray(values, float)[:, angles[k][1], 0] * _ANGLE_UNITS[unit]
        if np.isfinite(column).any():
            out[f"{angle}_rad"] = column
            used[angle] = _bare(names[k])
        else:
            skipped[angle] = f"{_bare(names[k])} holds no number"
    if skipped:
        where = f"{source}: " if source else ""
        if not used:
            log.info("%sno lab joint angle to compare with: %s", where, "; ".join(skipped.values()))
        else:
            log.info("%slab angles not read: %s", where, "; ".join(f"{a} ({why})" for a, why in skipped.items()))
    return pd.DataFrame(out), used


def lab_agreement(ours: pd.DataFrame, lab: pd.DataFrame, min_frames: int = 10) -> pd.DataFrame:
    """How our joint angles agree with the lab's, per angle, over the frames both hold.

    Parameters
    ----------
    ours, lab : pandas.DataFrame
        ``time_s`` and ``{angle}_rad`` columns (our angle table; :func:`lab_joint_angles`); frames are matched
        by time (to 1 microsecond).
    min_frames : int
        Fewer common finite frames: the angle's row holds NaN.

    Returns
    -------
    pandas.DataFrame
        One row per angle both tables hold, columns :data:`LAB_AGREEMENT_COLUMNS`: ``r`` (Pearson),
        ``rms_diff_rad`` and ``mean_offset_rad`` (ours minus the lab's), ``warning`` ('' when within
        :data:`MIN_LAB_R`, :data:`MAX_LAB_RMS_RAD` and, at the hip and knee, :data:`MAX_LAB_OFFSET_RAD`).
    """
    missing = [c.removesuffix("_rad") for c in ours.columns if c.endswith("_rad") and c not in lab.columns]
    if missing and len(missing) == sum(c.endswith("_rad") for c in ours.columns):
        log.info("not compared with the lab's own angles: the lab's file stores none of them")
    elif missing:
        log.info("not compared with the lab's own angles (the lab's file lacks them): %s", ", ".join(missing))
    key_ours = np.round(ours["time_s"].to_numpy(float) * 1e6).astype(np.int64)
    key_lab = np.round(lab["time_s"].to_numpy(float) * 1e6).astype(np.int64)
    common, i_ours, i_lab = np.intersect1d(key_ours, key_lab, return_indices=True)
    rows = []
    for column in [c for c in lab.columns if c != "time_s" and c in ours.columns]:
        angle = column.removesuffix("_rad")
        a = ours[column].to_numpy(float)[i_ours]
        b = lab[column].to_numpy(float)[i_lab]
        ok = np.isfinite(a) & np.isfinite(b)
        n = int(ok.sum())
        row = {"angle": angle, "n_frames": n, "lab_excursion_rad": float(np.ptp(b[ok])) if n else np.nan}
        if n >= min_frames and np.std(a[ok]) > 0 and np.std(b[ok]) > 0:
            d = a[ok] - b[ok]
            row |= {
                "r": float(np.corrcoef(a[ok], b[ok])[0, 1]),
                "rms_diff_rad": float(np.sqrt(np.mean(d**2))),
                "mean_offset_rad": float(d.mean()),
            }
        else:
            row |= {"r": np.nan, "rms_diff_rad": np.nan, "mean_offset_rad": np.nan}
            log.info(
                "%s not compared with the lab's own angle: %s",
                angle,
                f"{n} frame(s) in common, fewer than {min_frames}" if n < min_frames else "one of them is constant",
            )
        rows.append(row)
    table = pd.DataFrame(rows, columns=list(LAB_AGREEMENT_COLUMNS))
    table["warning"] = lab_agreement_warnings(table)
    return table


def lab_agreement_warnings(
    table: pd.DataFrame, min_r: float = MIN_LAB_R, max_rms_rad: float = MAX_LAB_RMS_RAD
) -> list[str]:
    """One text per row of :func:`lab_agreement`: what is off ('' when nothing is, or nothing was compared)."""
    out = []
    for row in table.itertuples():
        problems = []
        moves = np.isfinite(row.lab_excursion_rad) and row.lab_excursion_rad >= MIN_LAB_EXCURSION_RAD
        if moves and np.isfinite(row.r) and row.r < min_r:
            problems.append(f"r {row.r:.2f} < {min_r:g}")
        if np.isfinite(row.rms_diff_rad) and row.rms_diff_rad > max_rms_rad:
            problems.append(
                f"RMS difference {np.degrees(row.rms_diff_rad):.1f} deg > {np.degrees(max_rms_rad):.0f} deg "
                f"(mean offset {np.degrees(row.mean_offset_rad):+.1f} deg)"
            )
        offset = row.mean_offset_rad
        joint = str(row.angle).split("_")[0]
        if joint in ("hip", "knee") and np.isfinite(offset) and abs(offset) > MAX_LAB_OFFSET_RAD:
            problems.append(
                f"mean offset {np.degrees(offset):+.1f} deg from the lab's own beyond "
                f"{np.degrees(MAX_LAB_OFFSET_RAD):.0f} deg: the static trial's calibration (the joint centres' "
                "landmarks in markers.label_map, the lab's widths) or another joint-centre method than the lab's"
            )
        if moves and row.r < 0:
            problems.append("anticorrelated: a sign (ik.coordinate_map) or swapped sides (markers.label_map)?")
        out.append("; ".join(problems))
    return out


def window_means(table: pd.DataFrame, window: tuple[float, float]) -> dict[str, float]:
    """Each angle of a lab-angle table (columns ``time_s`` and ``*_rad``) averaged over the frames within
    ``window`` (s): ``{angle: rad}``, the ``_rad`` suffix dropped; empty without rows or frames there."""
    if not len(table):
        return {}
    t = table["time_s"].to_numpy(float)
    inside = (t >= window[0] - 1e-9) & (t <= window[1] + 1e-9)
    if not inside.any():
        return {}
    return {
        c.removesuffix("_rad"): float(np.nanmean(table.loc[inside, c])) for c in table.columns if c.endswith("_rad")
    }
