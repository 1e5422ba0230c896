"""Swing-locked synthetic strides with planted response bumps, shared by the tests of
loper_analysis.impedance.responses.

Every stride's joint angles are one smooth curve of the time since its own
toe-off plus a per-stride offset, so two strides with equal offsets are exact
twins once aligned at their toe-offs. Perturbed strides get a known bump after
the onset (and a 40 N pulse on the force); all event times are 128 Hz frames,
so the windows sample frames and the planted answers come back to round-off.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS
from loper_analysis.swing_leg.dynamics import segment_coordinates
from loper_analysis.synthetic.response import thigh_normal

RATE = 128.0
DELAY = 13  # onset 13 frames (101.6 ms) after toe-off: the first flagged frame of a 100 ms onset
BUMP_AMP = np.array([0.1, 0.2, 0.05])  # rad, hip knee ankle
PULSE_N = 40.0
JOINT_COLS = [f"{j}_left_rad" for j in JOINTS]


def swing_curve(tau):
    """Smooth joint angles (n, 3), rad, as a function of the time since toe-off (s)."""
    return np.stack(
        [
            0.4 * np.sin(2 * np.pi * tau / 1.1 + 0.3),
            0.6 * np.sin(2 * np.pi * tau / 0.9 + 1.0),
            0.2 * np.sin(2 * np.pi * tau / 1.3 - 0.5),
        ],
        axis=-1,
    )


def bump(tau):
    """Planted response shape: sin^2 over 0 .. 0.3 s after the onset, 0 elsewhere."""
    return np.where((tau > 0) & (tau < 0.3), np.sin(np.pi * tau / 0.3) ** 2, 0.0)


@dataclass
class Trial:
    name: str
    angles: pd.DataFrame
    force: pd.DataFrame
    direction: np.ndarray
    strides: pd.DataFrame
    toe_off: np.ndarray  # frame index of each stride's toe-off
    onset: dict  # perturbed stride -> onset frame

    def inputs(self) -> dict:
        return {
            "name": self.name,
            "angles": self.angles,
            "strides": self.strides,
            "force": self.force,
            "force_direction": self.direction,
        }


def make_trial(name, stance, swing, offsets, perturbed, removed=(), lead=40, tail=60) -> Trial:
    """Trial with strides of ``stance`` + ``swing`` frames; ``perturbed``: stride -> bump amplitudes (3,)."""
    stance, swing = np.asarray(stance), np.asarray(swing)
    n_strides = stance.size
    hs = lead + np.concatenate([[0], np.cumsum(stance + swing)])
    to = hs[:-1] + stance
    n = int(hs[-1]) + tail
    frame = np.arange(n)
    t = frame / RATE
    sid = np.clip(np.searchsorted(hs, frame, side="right") - 1, 0, n_strides - 1)
    tau = (frame - to[sid]) / RATE
    angles = swing_curve(tau) + np.asarray(offsets)[sid]
    pelvis = 0.05 * np.sin(2 * np.pi * tau) + 0.001 * sid
    pelvis_x = 0.02 * np.cos(2 * np.pi * tau / 1.2)
    force = 2.0 + 0.5 * np.cos(2 * np.pi * tau)
    onset_s = np.full(n_strides, np.nan)
    onsets = {}
    for s, amp in perturbed.items():
        k0 = int(to[s] + DELAY)
        angles = angles + np.asarray(amp) * bump((frame - k0) / RATE)[:, None]
        force = force + PULSE_N * ((frame >= k0) & (frame < k0 + 13))
        onset_s[s] = t[k0]
        onsets[s] = k0
    q = segment_coordinates(angles, pelvis, pelvis_x)
    direction = thigh_normal(q[:, 1])
    table = pd.DataFrame(
        {
            "stride": np.arange(n_strides),
            "side": "left",
            "heel_strike_s": t[hs[:-1]],
            "toe_off_s": t[to],
            "end_s": t[hs[1:]],
            "duration_s": (hs[1:] - hs[:-1]) / RATE,
            "stance_s": stance / RATE,
            "swing_s": swing / RATE,
            "perturbed": np.isfinite(onset_s),
            "onset_s": onset_s,
            "removed": np.isin(np.arange(n_strides), list(removed)),
            "reason": "",
        }
    )
    frame_angles = pd.DataFrame({"time_s": t, "pelvis_x_m": pelvis_x, "pelvis_angle_rad": pelvis})
    for j, c in enumerate(JOINT_COLS):
        frame_angles[c] = angles[:, j]
    frame_force = pd.DataFrame({"time_s": t, "force_measured_n": force, "force_desired_n": 0.0, "perturbation": 0})
    return Trial(name, frame_angles, frame_force, direction, table, to, onsets)


def twin_trial(rng, name="walk-1", twins=None, amplitudes=None, removed=(), short=(), n_strides=26):
    """Strides with varied stance and swing (``short``: 40-frame swings) and random offsets;
    each perturbed stride in ``twins`` has a twin."""
    twins = {4: 1, 8: 6, 12: 10, 16: 14} if twins is None else twins
    i = np.arange(n_strides)
    stance, swing = 88 + (7 * i) % 5, np.where(np.isin(i, list(short)), 40, 58 + (3 * i) % 5)
    offsets = rng.uniform(-0.05, 0.05, (n_strides, 3))
    for p, u in twins.items():
        offsets[u] = offsets[p]
    if amplitudes is None:
        amplitudes = {p: BUMP_AMP * (1.0 + 0.1 * k) for k, p in enumerate(sorted(twins))}
    return make_trial(name, stance, swing, offsets, amplitudes, removed=removed), offsets


def expected_match(trial, offsets, p, excluded=()):
    """Brute force: the allowed unperturbed stride of least RMS offset difference (the shapes coincide)."""
    table = trial.strides
    cand = np.flatnonzero(~table["perturbed"].to_numpy() & ~table["removed"].to_numpy())
    cand = np.array([c for c in cand if c not in excluded])
    rmsd = np.sqrt(np.mean((offsets[cand] - offsets[p]) ** 2, axis=1))
    return int(cand[np.argmin(rmsd)]), float(rmsd.min())


def null_trial(rng):
    """Unperturbed strides in twin pairs (equal offsets); perturbed strides 4 and 8 copy stride 10's
    offsets, so a stride 10 that could match them would tie with them (and ties go to the first).
    Returns the trial and the twin of every paired stride."""
    n = 16
    i = np.arange(n)
    stance, swing = 88 + (7 * i) % 5, 58 + (3 * i) % 5
    offsets = rng.uniform(-0.05, 0.05, (n, 3))
    twins = {0: 1, 2: 3, 5: 6, 7: 9, 10: 11, 12: 13, 14: 15}
    for a, b in twins.items():
        offsets[b] = offsets[a]
    offsets[4] = offsets[8] = offsets[10]
    trial = make_trial("walk-n", stance, swing, offsets, {4: BUMP_AMP, 8: BUMP_AMP})
    return trial, {**twins, **{b: a for a, b in twins.items()}}
