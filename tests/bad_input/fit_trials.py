"""Trials for :func:`loper_analysis.impedance.identification.impedance.fit_onset` built from the twin strides of
``tests.impedance.responses.twin_strides``: joint angles, stride table, rod force and the two brace markers."""

from __future__ import annotations

import numpy as np

from loper_analysis.swing_leg.dynamics import segment_coordinates
from tests.impedance.responses.twin_strides import JOINT_COLS, make_trial

ONSET_MS = 100  # the planted onsets lie 13 frames (101.6 ms) after toe-off


def brace_markers(trial) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Frame times (s), brace markers (n, 2, 3) on the thigh and their labels, so that the rods push along
    the trial's force direction (forward, perpendicular to the thigh)."""
    a = trial.angles
    q = segment_coordinates(a[JOINT_COLS].to_numpy(), a["pelvis_angle_rad"].to_numpy(), a["pelvis_x_m"].to_numpy())
    axis = np.stack([-np.sin(q[:, 1]), -np.cos(q[:, 1]), np.zeros(len(q))], axis=-1)  # hip -> knee
    return a["time_s"].to_numpy(), np.stack([0.2 * axis, 0.35 * axis], axis=1), ["LBRA_P", "LBRA_D"]


def fit_inputs(trial) -> dict:
    """The mapping :func:`loper_analysis.impedance.identification.impedance.fit_onset` takes for one trial."""
    return {
        "name": trial.name,
        "angles": trial.angles,
        "strides": trial.strides,
        "force": trial.force,
        "markers": brace_markers(trial),
    }


def walking_trial(
    name: str,
    seed: int,
    n_strides: int = 26,
    swing_frames: int | None = None,
    spread: float = 0.05,
    perturbed=(4, 8, 12, 16),
    amplitude=(0.02, 0.04, 0.01),
):
    """Strides with varied stance and swing (or every swing ``swing_frames`` long), per-stride offsets uniform in
    +-``spread`` rad; the ``perturbed`` strides carry a bump of ``amplitude`` (rad, hip knee ankle)."""
    rng = np.random.default_rng(seed)
    i = np.arange(n_strides)
    stance = 88 + (7 * i) % 5
    swing = 58 + (3 * i) % 5 if swing_frames is None else np.full(n_strides, swing_frames)
    offsets = rng.uniform(-spread, spread, (n_strides, 3))
    return make_trial(name, stance, swing, offsets, {p: np.asarray(amplitude) for p in perturbed})
