"""The trial inputs of a response: joint angles, stride table and interaction force of one trial, as frames.

A trial is a mapping with ``name`` (str), ``angles`` (DataFrame: ``time_s``,
``pelvis_x_m``, ``pelvis_angle_rad``, ``{hip,knee,ankle}_<side>_rad``),
``strides`` (stride table of ``side``, :func:`loper_analysis.gait.strides.stride_tables`)
and, for perturbed trials, ``force`` (``time_s``, ``force_measured_n``) and
``force_direction`` (array (n_frames, 2), unit vectors of the rod force).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from loper_analysis.checks import require_columns, time_vector
from loper_analysis.constants import JOINTS, angle_column
from loper_analysis.errors import LoperInputError

__all__ = ["trial_name", "trial_table", "trial_angles"]


def trial_name(trial, k: int, keys: tuple[str, ...], source: str = "") -> str:
    """The trial's name (``trial k`` without one); refuses a trial that is not a mapping holding ``keys``."""
    if not isinstance(trial, Mapping):
        raise LoperInputError(
            f"{source + ': ' if source else ''}trial {k} must be a mapping with name, {', '.join(keys)}"
        )
    name = str(trial.get("name", f"trial {k}"))
    missing = [key for key in keys if key not in trial]
    if missing:
        raise LoperInputError(f"{source + ': ' if source else ''}{name}: trial input(s) {missing} missing")
    return name


def trial_table(trial: Mapping, key: str, name: str, columns=()) -> tuple[pd.DataFrame, str]:
    """The frame ``trial[key]`` holding ``columns``, and the label that names it in messages (``name (key)``)."""
    label = f"{name} ({key})"
    return require_columns(trial[key], columns, label), label


def trial_angles(trial: Mapping, name: str, side: str) -> tuple[np.ndarray, dict[str, np.ndarray], str]:
    """Frame times (s), the signals to window (``joints`` (n, 3) rad, ``pelvis_angle`` rad, ``pelvis_x`` m) and the
    label."""
    joints = [angle_column(j, side) for j in JOINTS]
    angles, label = trial_table(trial, "angles", name, ("time_s", "pelvis_x_m", "pelvis_angle_rad", *joints))
    t = time_vector(angles["time_s"].to_numpy(float), label, min_count=4, item="frame")
    columns = {
        "joints": angles[joints].to_numpy(float),
        "pelvis_angle": angles["pelvis_angle_rad"].to_numpy(float),
        "pelvis_x": angles["pelvis_x_m"].to_numpy(float),
    }
    return t, columns, label
