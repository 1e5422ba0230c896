"""Marker arrays shared by the C3D and TRC tests."""

import numpy as np

POINT_HZ = 128.0
N_FRAMES = 40
LABELS = ["RASI", "LASI", "RKNE"]
N_MARKERS = len(LABELS)


def lab_markers(rng, n_frames=N_FRAMES, n_markers=N_MARKERS):
    """Plausible lab coordinates (m) with two gaps: marker 1 frames 5..7, marker 2 frame 0."""
    X = rng.uniform(-1.5, 1.5, size=(n_frames, n_markers, 3))
    X[5:8, 1] = np.nan
    X[0, 2] = np.nan
    return X


def as_stored(X_m, units_per_m):
    """What a float C3D holds, read back in m: float32 in the file's unit."""
    return (X_m * units_per_m).astype(np.float32).astype(np.float64) / units_per_m
