"""Shared test data: small result tables in the shapes the headline tables read (loper_analysis.report.headline)."""

from __future__ import annotations

import math

import pandas as pd

from loper_analysis.impedance.identification import t_quantile
from loper_analysis.impedance.identification.impedance import IMPEDANCE_COLUMNS
from loper_analysis.reference import STUDY_DEVICE

#: Degrees of freedom of the intervals of these rows (those of a fit with 31 null pairs).
CI_DOF = 30


def impedance_row(subject, onset, joint, k, d, k_ci, d_ci, k_true=None, d_true=None, status="ok") -> dict:
    """One row of the impedance table (K in N·m/rad, D in N·m·s/rad); with a truth, its errors."""
    row = dict.fromkeys(IMPEDANCE_COLUMNS)
    row.update(
        subject=subject,
        onset_ms=onset,
        joint=joint,
        K_nm_per_rad=k,
        D_nms_per_rad=d,
        K_ci95_low_nm_per_rad=k_ci[0],
        K_ci95_high_nm_per_rad=k_ci[1],
        D_ci95_low_nms_per_rad=d_ci[0],
        D_ci95_high_nms_per_rad=d_ci[1],
        K_se_nm_per_rad=(k_ci[1] - k_ci[0]) / (2 * t_quantile(CI_DOF)),
        D_se_nms_per_rad=(d_ci[1] - d_ci[0]) / (2 * t_quantile(CI_DOF)),
        ci_dof=CI_DOF,
        vaf_pct=90.0,
        n_strides=10,
        status=status,
        reason="",
    )
    if k_true is not None:
        row.update(
            K_true_nm_per_rad=k_true,
            D_true_nms_per_rad=d_true,
            K_error_nm_per_rad=k - k_true,
            D_error_nms_per_rad=d - d_true,
        )
    return row


def impedance_table() -> pd.DataFrame:
    """Two synthetic subjects (one failed fit) and a recorded one, with known errors."""
    nan = math.nan
    return pd.DataFrame(
        [
            # hip K: error -2 (within 10 % of 52, truth in CI); 15 (outside both).
            # D: -0.6 (outside both); -0.2 (in both)
            impedance_row("S1", 50, "hip", 50.0, 3.0, (40.0, 60.0), (2.5, 3.5), 52.0, 3.6),
            impedance_row("S2", 50, "hip", 70.0, 4.0, (60.0, 80.0), (3.0, 5.0), 55.0, 4.2),
            impedance_row("S1", 175, "hip", nan, nan, (nan, nan), (nan, nan), 40.0, 2.0, status="failed"),
            # knee K: error -2 = the 2 N·m/rad floor of the tolerance (within); D: -0.02 (within)
            impedance_row("S1", 50, "knee", 1.0, 0.10, (0.0, 4.0), (0.0, 0.3), 3.0, 0.12, status="not_identifiable"),
            impedance_row("R1", 50, "hip", 45.0, 3.3, (30.0, 60.0), (2.0, 4.6)),  # recorded: no truth
        ]
    )


def validation_summary() -> pd.DataFrame:
    """A validation summary: no-noise errors within the study's, one noisy row (N·m/rad, N·m·s/rad)."""
    return pd.DataFrame(
        {
            "condition": ["no_noise", "no_noise", "noise"],
            "parameter": ["K_hip", "D_hip", "K_hip"],
            "min_error": [-0.01, -0.001, -70.0],
            "max_error": [0.02, 0.002, 40.0],
            "n": 729,
            "study_min_error": [-0.87, -0.092, -6.2],
            "study_max_error": [0.59, 0.047, 6.5],
        }
    )


def device_summary() -> pd.DataFrame:
    """A device summary: every metric of the study, close to the study's values."""
    return pd.DataFrame({"metric": list(STUDY_DEVICE), "value": [38.79, 9.9, 31.5, 35.3]})
