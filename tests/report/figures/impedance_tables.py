"""Small impedance-study tables with known contents, shared by the figure tests and the figure-step tests."""

from __future__ import annotations

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, parameter_column

#: Peak response difference (rad) of each joint in :func:`response_table` at scale 1.
AMPLITUDE_RAD = {"hip": 0.05, "knee": 0.12, "ankle": 0.02}


def response_table(scale: float = 1.0) -> pd.DataFrame:
    """A response table whose differences are 5 Hz sines of peak ``scale * AMPLITUDE_RAD[joint]``."""
    t = np.arange(-125, 301) / 1000.0  # 1 kHz grid; the 5 Hz sine peaks on it at 50 ms
    table = {"time_s": t}
    for joint in JOINTS:
        base = 0.3 * np.cos(2 * np.pi * t)
        diff = scale * AMPLITUDE_RAD[joint] * np.sin(2 * np.pi * 5.0 * t)
        table[f"{joint}_rad_mean"] = diff
        table[f"{joint}_rad_sd"] = np.full_like(t, 0.01)
        table[f"{joint}_perturbed_rad_mean"] = base + diff
        table[f"{joint}_unperturbed_rad_mean"] = base
    table["force_n_mean"] = 10 * np.sin(2 * np.pi * 4.0 * t)
    table["force_n_sd"] = 1.0
    table["n_pairs"] = 12
    table["analysis_window"] = (t >= -0.025) & (t <= 0.25)
    return pd.DataFrame(table)


def curves_table() -> pd.DataFrame:
    """A fit-curve table: measured (with a small 30 Hz ripple) and model response per joint."""
    t = np.arange(0.0, 0.2751, 0.001)
    table = {"time_s": t}
    for joint in JOINTS:
        measured = AMPLITUDE_RAD[joint] * np.sin(2 * np.pi * 4.0 * t)
        table[f"{joint}_measured_rad"] = measured + 0.002 * np.cos(2 * np.pi * 30 * t)
        table[f"{joint}_model_rad"] = measured
    return pd.DataFrame(table)


def impedance_table() -> pd.DataFrame:
    """Impedance rows of two recorded subjects and one synthetic one at three onsets.

    S02 failed at 175 ms (K/D empty), S01's hip at 300 ms is ``not_identifiable``
    (it still counts) and SYN1's knee at 50 ms is ``skipped`` with stray values (it does not).
    """
    k_col, d_col = parameter_column("K"), parameter_column("D")
    rng = np.random.default_rng(3)
    rows = []
    for subject, synthetic in (("S01", False), ("S02", False), ("SYN1", True)):
        for onset in (50, 175, 300):
            for joint in JOINTS:
                k, d = rng.uniform(5, 80), rng.uniform(0.1, 3)
                status = "ok"
                if subject == "S02" and onset == 175:
                    status = "failed"  # broken line; K/D empty
                rows.append(
                    {
                        "subject": subject,
                        "onset_ms": onset,
                        "joint": joint,
                        k_col: np.nan if status == "failed" else k,
                        d_col: np.nan if status == "failed" else d,
                        parameter_column("K", "ci95_low"): k - 1,
                        parameter_column("K", "ci95_high"): k + 1,
                        parameter_column("D", "ci95_low"): d - 0.1,
                        parameter_column("D", "ci95_high"): d + 0.1,
                        "vaf_pct": 90.0,
                        "n_strides": 20,
                        parameter_column("K", "true"): k * 1.05 if synthetic else np.nan,
                        parameter_column("D", "true"): d * 0.95 if synthetic else np.nan,
                        parameter_column("K", "error"): -0.05 * k if synthetic else np.nan,
                        parameter_column("D", "error"): 0.05 * d if synthetic else np.nan,
                        "sum_sq_error_rad2": 1e-4,
                        "n_starts": 3,
                        "n_starts_at_best": 2,
                        "status": status,
                        "reason": "" if status == "ok" else "diverged",
                    }
                )
    table = pd.DataFrame(rows)
    table.loc[(table.subject == "S01") & (table.onset_ms == 300) & (table.joint == "hip"), "status"] = (
        "not_identifiable"
    )
    table.loc[(table.subject == "SYN1") & (table.onset_ms == 50) & (table.joint == "knee"), "status"] = "skipped"
    return table
