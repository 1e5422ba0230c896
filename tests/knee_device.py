"""A knee alignment device built around known knee markers, for the tests of its knee marker."""

from __future__ import annotations

import numpy as np

#: Arm length of the device (m).
ARM_M = 0.10


def device_markers(knee_m: np.ndarray, medial_m: np.ndarray, seed: int) -> list[np.ndarray]:
    """The markers ``KAX``, ``KD1``, ``KD2`` (each (n_frames, 3), m) of a device whose origin is ``knee_m`` and
    whose arms point away from the body: a cube corner with its diagonal along ``knee_m - medial_m``, turned
    about that diagonal by an angle drawn from ``seed``."""
    turn = np.random.default_rng(seed).uniform(0, 2 * np.pi)
    out = [[], [], []]
    for knee, medial in zip(np.asarray(knee_m, float), np.asarray(medial_m, float)):
        d = (knee - medial) / np.linalg.norm(knee - medial)
        u = np.cross(d, [0.0, 0.0, 1.0])
        u /= np.linalg.norm(u)
        w = np.cross(d, u)
        for k in range(3):  # three unit vectors at 54.7 deg from the diagonal, 120 deg apart about it
            phi = turn + 2 * np.pi * k / 3
            out[k].append(knee + ARM_M * (d / np.sqrt(3) + np.sqrt(2 / 3) * (np.cos(phi) * u + np.sin(phi) * w)))
    return [np.array(o) for o in out]
