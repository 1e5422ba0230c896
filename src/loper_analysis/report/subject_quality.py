"""The front page's section on recorded subjects: is each subject's model and each trial's kinematics right?

Per subject (:class:`SubjectQuality`): the mass and height used and where they came from, the scale factors,
the marker errors before and after marker placement, the static pose the markers were placed in (beside the
lab's own static angles), the scaling's warnings, and per trial the joint angles over the gait cycle and the
force plates with the events found. Then one table with a row per trial (:class:`TrialQuality`): frames solved
and left out of inverse kinematics, the marker RMS error and the three worst markers, strides found and kept, speed,
the agreement with the lab's own angles and the trial's warnings. Angles are shown in degrees, marker errors
in mm; each number's ``data-v`` holds the table's value in SI units.
"""

from __future__ import annotations

import base64
import html
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, SIDES

__all__ = ["SubjectQuality", "TrialQuality", "recorded_subjects_html"]


@dataclass(frozen=True)
class TrialQuality:
    """One recorded trial: its IK summary row, its agreement with the lab's own angles (rows per angle), its row of
    the strides summary (None when the trial has none) and its figures (PNG bytes or None)."""

    trial: str
    ik: pd.Series
    agreement: pd.DataFrame
    strides: pd.Series | None = None
    angles_png: bytes | None = None
    grf_png: bytes | None = None


@dataclass(frozen=True)
class SubjectQuality:
    """One recorded subject: its scale report (None: a scaled model was given) and its trials."""

    subject: str
    scale: pd.DataFrame | None
    trials: list[TrialQuality] = field(default_factory=list)


def _v(value, shown: str, key: str) -> str:
    """A number as the page shows it, with its table value (SI) and where it comes from."""
    return f'<span data-q="{html.escape(key)}" data-v="{value!r}">{shown}</span>'


def _deg(value_rad, key: str, decimals: int = 1) -> str:
    if value_rad is None or not np.isfinite(value_rad):
        return "–"
    return _v(float(value_rad), f"{math.degrees(value_rad):+.{decimals}f}", key)


def _mm(value_m, key: str) -> str:
    if value_m is None or not np.isfinite(value_m):
        return "–"
    return _v(float(value_m), f"{1000 * value_m:.1f}", key)


def _text(value) -> str:
    """A text cell of a table ('' for an empty cell, which a TSV reader may give as NaN)."""
    return "" if value is None or (isinstance(value, float) and math.isnan(value)) else str(value)


def _img(png: bytes | None, alt: str) -> str:
    if not png:
        return ""
    data = base64.b64encode(png).decode("ascii")
    return f'<img class="lf-wide" alt="{html.escape(alt)}" src="data:image/png;base64,{data}">'


def _scale_block(subject: str, scale: pd.DataFrame) -> str:
    """Mass and height, scale factors, marker errors before and after placement, static pose, warnings."""
    key = f"scale|{subject}"
    parts = []
    who = scale[scale["kind"] == "subject"]
    if len(who):
        row = who.iloc[0]
        parts.append(
            f"<p>mass {_v(float(row.mass_kg), f'{row.mass_kg:.1f}', key + '|subject|mass_kg')} kg, height "
            f"{_v(float(row.height_m), f'{row.height_m:.2f}', key + '|subject|height_m')} m "
            f"({html.escape(str(row.source))})</p>"
        )
    bodies = scale[scale["kind"] == "body"]
    if len(bodies):
        rows: dict[str, dict[str, str]] = {}
        for b in bodies.itertuples():
            name = str(b.name)
            stem, side = (name[:-2], name[-1]) if name[-2:] in ("_r", "_l") else (name, "")
            cell = _v(float(b.scale_factor_x), f"{b.scale_factor_x:.3f}", f"{key}|{name}|scale_factor_x")
            rows.setdefault(stem, {})[side] = cell
        body = "".join(
            f'<tr><td class="lf-l">{html.escape(stem)}</td><td>{cells.get("r", cells.get("", ""))}</td>'
            f"<td>{cells.get('l', '')}</td></tr>"
            for stem, cells in rows.items()
        )
        parts.append(
            '<table class="lf-scale"><caption>Scale factors</caption><thead><tr><th></th><th>right</th>'
            f"<th>left</th></tr></thead><tbody>{body}</tbody></table>"
        )
    fits = scale[scale["kind"] == "markers"]
    if len(fits):
        rows = "".join(
            f'<tr><td class="lf-l">{html.escape(str(r.name))}</td>'
            f"<td>{_mm(r.marker_error_rms_m, key + '|' + str(r.name) + '|marker_error_rms_m')}</td>"
            f"<td>{_mm(r.marker_error_max_m, key + '|' + str(r.name) + '|marker_error_max_m')}</td>"
            f'<td class="lf-l">{html.escape(str(r.worst_marker))}</td></tr>'
            for r in fits.itertuples()
        )
        parts.append(
            '<table class="lf-markers"><caption>Static trial: marker errors (mm)</caption><thead><tr><th></th>'
            "<th>RMS</th><th>largest</th><th>worst marker</th></tr></thead>"
            f"<tbody>{rows}</tbody></table>"
        )
    pose = scale[scale["kind"] == "pose"].set_index("name")
    if len(pose):
        head = "".join(f"<th>{j}</th>" for j in JOINTS)
        body = ""
        for side in SIDES:
            ours = "".join(
                f"<td>{_deg(pose.angle_rad.get(f'{j}_{side}'), key + f'|{j}_{side}|angle_rad')}</td>" for j in JOINTS
            )
            lab = "".join(
                f"<td>{_deg(pose.lab_angle_rad.get(f'{j}_{side}'), key + f'|{j}_{side}|lab_angle_rad')}</td>"
                for j in JOINTS
            )
            body += f'<tr><td class="lf-l">{side}</td>{ours}</tr>'
            if pose.lab_angle_rad.reindex([f"{j}_{side}" for j in JOINTS]).notna().any():
                body += f'<tr><td class="lf-l">{side}, the lab\'s own</td>{lab}</tr>'
        parts.append(
            '<table class="lf-pose"><caption>Static pose the markers were placed in (deg)</caption>'
            f"<thead><tr><th></th>{head}</tr></thead><tbody>{body}</tbody></table>"
        )
    warnings = scale.loc[scale["kind"] == "warning", "source"].astype(str).tolist()
    if warnings:
        items = "".join(f"<li>{html.escape(w)}</li>" for w in warnings)
        parts.append(f'<ul class="lf-warnings">{items}</ul>')
    return "".join(parts)


def _trial_row(subject: str, t: TrialQuality) -> str:
    key = f"trial|{subject}|{t.trial}"
    ik = t.ik
    strides = t.strides
    found = kept = speed = "–"
    if strides is not None:
        found = _v(int(strides.n_strides), str(int(strides.n_strides)), key + "|n_strides")
        kept = _v(int(strides.n_kept), str(int(strides.n_kept)), key + "|n_kept")
        if "speed_m_per_s" in strides and np.isfinite(strides.speed_m_per_s):
            speed = _v(float(strides.speed_m_per_s), f"{strides.speed_m_per_s:.2f}", key + "|speed_m_per_s")
    agree = "–"
    if len(t.agreement):
        joints = t.agreement[t.agreement["angle"] != "pelvis_angle"]
        if len(joints):
            r_min, rms_max = joints["r"].min(), joints["rms_diff_rad"].max()
            agree = (
                f"r ≥ {_v(float(r_min), f'{r_min:.2f}', key + '|lab_r_min')}, RMS ≤ "
                f"{_v(float(rms_max), f'{math.degrees(rms_max):.1f}', key + '|lab_rms_max_rad')}°"
            )
    warnings = _text(ik.get("warnings"))
    if strides is not None and str(strides.get("status", "ok")) != "ok":
        warnings = "; ".join(w for w in [str(strides.status), warnings] if w)
    worst = _text(ik.get("worst_markers_mm"))
    return (
        f'<tr><td class="lf-l">{html.escape(subject)}</td><td class="lf-l">{html.escape(t.trial)}</td>'
        f"<td>{_v(int(ik.n_frames_solved), str(int(ik.n_frames_solved)), key + '|n_frames_solved')}</td>"
        f"<td>{_v(int(ik.n_frames_left_out), str(int(ik.n_frames_left_out)), key + '|n_frames_left_out')}</td>"
        f"<td>{_mm(ik.marker_rms_mean_m, key + '|marker_rms_mean_m')}</td>"
        f'<td class="lf-l">{html.escape(worst)}</td>'
        f"<td>{found}</td><td>{kept}</td><td>{speed}</td><td>{agree}</td>"
        f'<td class="lf-l lf-wrap">{html.escape(warnings)}</td></tr>'
    )


def recorded_subjects_html(subjects: Sequence[SubjectQuality]) -> str:
    """The section's HTML (empty without recorded subjects): per subject its scaling and figures, then one table
    with a row per trial (id ``lf-trials``)."""
    if not subjects:
        return ""
    parts = ['<h2 id="lf-recorded">Recorded subjects: model and kinematics</h2>']
    for s in subjects:
        parts.append(f'<h3 id="lf-subject-{html.escape(s.subject)}">{html.escape(s.subject)}</h3>')
        if s.scale is not None:
            parts.append(_scale_block(s.subject, s.scale))
        else:
            parts.append("<p>Scaled model given in the subject sheet (no scaling here).</p>")
        for t in s.trials:
            parts.append(_img(t.angles_png, f"{s.subject} {t.trial}: joint angles over the gait cycle"))
            parts.append(_img(t.grf_png, f"{s.subject} {t.trial}: force plates and events"))
    rows = "".join(_trial_row(s.subject, t) for s in subjects for t in s.trials)
    parts.append(
        '<table id="lf-trials"><caption>Per trial: inverse kinematics, strides and agreement with the lab\'s own '
        "angles (hip, knee, ankle)</caption><thead><tr><th>subject</th><th>trial</th><th>frames solved</th>"
        "<th>left out</th><th>marker RMS (mm)</th><th>worst markers (RMS, mm)</th><th>strides</th><th>kept</th>"
        "<th>speed (m/s)</th><th>lab's own angles</th><th>warnings</th></tr></thead>"
        f"<tbody>{rows}</tbody></table>"
    )
    return "\n".join(parts)
