"""A split-belt treadmill walk with known answers for the force-plate contact tests: two plates, every step of
both feet, the plates' force and the heel markers (tests/gait/test_contacts.py, test_plate_contacts.py,
test_contact_flags.py)."""

import math

import numpy as np

from loper_analysis.gait.contacts import PlateForce, foot_contacts

FS = 2000.0  # analog rate, Hz
MARKER_HZ = 200.0
DURATION_S = 11.0
PEAK_N = 700.0
STANCE_S = 0.7
PERIOD_S = 1.1
REST_N = -40.0  # unloaded plates read this (not zeroed)
ON_N, OFF_N = 50.0, 20.0
SETTINGS = {"threshold_on_n": ON_N, "threshold_off_n": OFF_N, "min_stance_s": 0.08, "min_swing_s": 0.08}
# plate 1 under the left belt, plate 2 under the right one (walking along +y, surface z = 0)
CORNERS = {
    1: np.array([[-0.50, 0.0, 0.0], [-0.01, 0.0, 0.0], [-0.01, 1.6, 0.0], [-0.50, 1.6, 0.0]]),
    2: np.array([[0.01, 0.0, 0.0], [0.50, 0.0, 0.0], [0.50, 1.6, 0.0], [0.01, 1.6, 0.0]]),
}
HEEL_X = {1: -0.15, 2: 0.15}
CROSSOVER_X = 0.20  # the left foot's crossover step lands here, on the right belt
HAND = (2.22, 2.38, 150.0)  # a hand (object) load on plate 1 in the left swing: start, end, peak
MISSING = (8.60, 8.63)  # the right heel is missing around the start probe of its contact at 8.55 s (8.617 s)


def belt_steps():
    """(side, plate, heel strike s, toe-off s) of every foot contact; left step 5 crosses over to plate 2."""
    out = []
    for k in range(10):
        out.append(("left", 2 if k == 5 else 1, 0.3 + PERIOD_S * k, 0.3 + PERIOD_S * k + STANCE_S))
    for k in range(-1, 10):
        out.append(("right", 2, 0.85 + PERIOD_S * k, 0.85 + PERIOD_S * k + STANCE_S))
    return out


def hump(t, start, end, peak):
    inside = (t >= start) & (t <= end)
    return np.where(inside, peak * np.sin(np.pi * np.clip((t - start) / (end - start), 0, 1)), 0.0)


def crossings(start, end, peak):
    """Analytic times where a half-sine hump rises through ON_N and falls through OFF_N."""
    d = end - start
    return start + d / math.pi * math.asin(ON_N / peak), end - d / math.pi * math.asin(OFF_N / peak)


def heel_path(side, steps, t):
    """Heel marker (n, 3) in m: on its plate in stance (moving back with the belt), arcs up to 0.2 m in swing."""
    mine = sorted((s for s in steps if s[0] == side), key=lambda s: s[2])
    xyz = np.zeros((t.size, 3))
    first_x = CROSSOVER_X if (side == "left" and mine[0][1] == 2) else HEEL_X[mine[0][1]]
    xyz[t < mine[0][2]] = [first_x, 0.7, 0.2]  # in the air before the first step and after the last
    xyz[t > mine[-1][3]] = [HEEL_X[mine[-1][1]], 0.7, 0.2]
    for i, (_, plate, hs, to) in enumerate(mine):
        x = CROSSOVER_X if (side == "left" and plate == 2) else HEEL_X[plate]
        stance = (t >= hs) & (t <= to)
        xyz[stance] = np.column_stack(
            [np.full(stance.sum(), x), 1.1 - 1.0 * (t[stance] - hs), np.full(stance.sum(), 0.05)]
        )
        if i + 1 < len(mine):
            nxt = mine[i + 1]
            x2 = CROSSOVER_X if (side == "left" and nxt[1] == 2) else HEEL_X[nxt[1]]
            swing = (t > to) & (t < nxt[2])
            u = (t[swing] - to) / (nxt[2] - to)
            xyz[swing] = np.column_stack([x + (x2 - x) * u, 0.4 + 0.7 * u, 0.05 + 0.15 * np.sin(np.pi * u)])
    return xyz


def belt_walk(rng):
    steps = belt_steps()
    t = np.arange(int(DURATION_S * FS)) / FS
    raw = {1: np.full(t.size, REST_N), 2: np.full(t.size, REST_N)}
    for _, plate, hs, to in steps:
        raw[plate] += hump(t, hs, to, PEAK_N)
    raw[1] += hump(t, *HAND)
    for p in raw:
        raw[p] += rng.normal(0.0, 2.0, t.size)
    tm = np.arange(int(DURATION_S * MARKER_HZ)) / MARKER_HZ
    heels = {s: heel_path(s, steps, tm) for s in ("left", "right")}
    heels["right"][(tm >= MISSING[0]) & (tm <= MISSING[1])] = np.nan
    return t, raw, tm, heels, steps


def plates_above_rest(t, raw):
    """Force above the resting level: the median of a span where each plate is known to be unloaded."""
    quiet = {1: (0.0, 0.25), 2: (0.5, 0.8)}
    out = []
    for p in (1, 2):
        a, b = quiet[p]
        rest = np.median(raw[p][(t >= a) & (t < b)])
        assert abs(rest - REST_N) < 0.3
        out.append(PlateForce(p, t, raw[p] - rest, CORNERS[p]))
    return out


#: The seed of the belt walk the contact tests judge.
WALK_SEED = 20240612


def judged_walk(trial):
    """The contact table of a belt walk (:func:`belt_walk`), judged with :data:`SETTINGS`."""
    t, raw, tm, heels, _ = trial
    return foot_contacts(plates_above_rest(t, raw), tm, heels, **SETTINGS, source="S01/walk")
