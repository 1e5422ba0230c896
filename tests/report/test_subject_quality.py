"""The front page's section on recorded subjects: every number it shows is its table's."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

from loper_analysis.report.front_page import RunSettings, front_page_html
from loper_analysis.report.subject_quality import SubjectQuality, TrialQuality, recorded_subjects_html

SCALE = pd.DataFrame(
    [
        {"kind": "subject", "name": "subject", "mass_kg": 72.233726, "height_m": 1.86, "source": "mass: plates"},
        {"kind": "body", "name": "pelvis", "scale_factor_x": 1.05814},
        {"kind": "body", "name": "femur_r", "scale_factor_x": 1.07066},
        {"kind": "body", "name": "femur_l", "scale_factor_x": 1.07066},
        {"kind": "markers", "name": "before placement", "marker_error_rms_m": 0.037004, "marker_error_max_m": 0.0978,
         "worst_marker": "LTHI"},
        {"kind": "pose", "name": "knee_left", "angle_rad": -0.069547, "lab_angle_rad": -0.140802},
        {"kind": "warning", "name": "w", "source": "static pose: knee <beyond>"},
    ]
)  # fmt: skip
IK = pd.Series(
    {"n_frames_solved": 216, "n_frames_left_out": 0, "marker_rms_mean_m": 0.0158, "worst_marker": "LTHI",
     "worst_marker_rms_m": 0.028, "worst_markers_mm": "LTHI 28.0, RTHI 25.1, C7 20.2", "warnings": ""}
)  # fmt: skip
AGREEMENT = pd.DataFrame(
    {
        "angle": ["pelvis_angle", "hip_left", "knee_left"],
        "r": [0.33, 0.991, 0.998],
        "rms_diff_rad": [0.06, 0.044, 0.071],
    }
)
STRIDES = pd.Series({"n_strides": 1, "n_kept": 1, "speed_m_per_s": 1.2724, "status": "too_few_strides"})


def _shown(page: str) -> dict[str, tuple[float, str]]:
    return {k: (float(v), text) for k, v, text in re.findall(r'data-q="([^"]+)" data-v="([^"]+)">([^<]+)<', page)}


def test_the_numbers_are_the_tables_in_the_page_s_units():
    page = recorded_subjects_html([SubjectQuality("QCMAS", SCALE, [TrialQuality("walk", IK, AGREEMENT, STRIDES)])])
    shown = _shown(page)
    assert shown["scale|QCMAS|subject|mass_kg"] == (72.233726, "72.2")
    assert shown["scale|QCMAS|femur_l|scale_factor_x"] == (1.07066, "1.071")
    assert shown["scale|QCMAS|before placement|marker_error_rms_m"] == (0.037004, "37.0")
    assert shown["scale|QCMAS|knee_left|angle_rad"] == (-0.069547, f"{np.degrees(-0.069547):+.1f}")
    assert shown["scale|QCMAS|knee_left|lab_angle_rad"][1] == "-8.1"
    # the trial's agreement over the joints: the pelvis (r 0.33) is not a joint
    assert shown["trial|QCMAS|walk|lab_r_min"] == (0.991, "0.99")
    assert shown["trial|QCMAS|walk|lab_rms_max_rad"] == (0.071, f"{np.degrees(0.071):.1f}")
    assert shown["trial|QCMAS|walk|speed_m_per_s"] == (1.2724, "1.27")
    assert shown["trial|QCMAS|walk|marker_rms_mean_m"] == (0.0158, "15.8")
    assert "static pose: knee &lt;beyond&gt;" in page and "too_few_strides" in page
    assert '<td class="lf-l">LTHI 28.0, RTHI 25.1, C7 20.2</td>' in page
    assert page.index('id="lf-subject-QCMAS"') < page.index('id="lf-trials"')


def test_a_study_without_perturbations_says_so_and_shows_the_section_without_a_validation_study():
    settings = RunSettings(
        2024, [50, 175, 300], 2, "left", 40.0, 4, 0.025, 0.25, [0.0, 200.0], [0.0, 10.0], 10, "null_pairs", 6,
        "study", 45.0, 40.0, 0.1,
    )  # fmt: skip
    section = recorded_subjects_html([SubjectQuality("QCMAS", None, [TrialQuality("walk", IK, AGREEMENT)])])
    page = front_page_html({"QCMAS": "recorded"}, {"QCMAS": ["walk"]}, settings, {"Python": "3.11"},
                           pd.DataFrame(), None, recorded_html=section)  # fmt: skip
    assert "No perturbation trials in this run" in page and "onsets" not in page.split("</p>")[0]
    assert "Scaled model given in the subject sheet" in page and 'id="lf-trials"' in page
    assert "validation" not in page.lower().split('id="lf-run"')[0]
    run = page.split('id="lf-run"')[1]
    assert (
        "filter" in run
        and "seed" in run
        and not {"fit window", "bounds", "synthetic lab"} & set(re.findall(r'<td class="lf-l">([a-z ]+)</td>', run))
    )
