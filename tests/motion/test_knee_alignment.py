"""The knee marker of a knee alignment device: a device built around the clinical lab's own knee markers gives
them back."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import read_c3d
from loper_analysis.motion.knee_alignment import kad_knee_markers
from tests.knee_device import device_markers

QCMAS = Path(__file__).resolve().parents[1] / "data" / "c3d-parser" / "QCMAS"


def test_a_device_around_the_lab_knee_markers_gives_them_back_to_a_tenth_of_a_millimetre():
    rec = read_c3d(QCMAS / "static.c3d")
    names = list(rec.marker_labels)
    X = rec.markers_m
    kept = [i for i, n in enumerate(names) if n not in ("LKNE", "RKNE")]
    out_names, out_X = [names[i] for i in kept], X[:, kept]
    truth = {}
    for side, seed in (("L", 1), ("R", 2)):
        knee, medial = X[:, names.index(f"{side}KNE")], X[:, names.index(f"{side}MKNE")]
        truth[f"{side}KNE"] = knee
        for code, marker in zip(("KAX", "KD1", "KD2"), device_markers(knee, medial, seed)):
            out_names.append(f"{side}{code}")
            out_X = np.concatenate([out_X, marker[:, None, :]], axis=1)
    names2, X2, added = kad_knee_markers(out_names, out_X, source="static.c3d")
    assert added == ["LKNE", "RKNE"] and names2[-2:] == added
    for knee in added:
        np.testing.assert_allclose(X2[:, names2.index(knee)], truth[knee], atol=1e-4)


def test_a_trial_with_its_knee_marker_is_left_alone_and_a_lone_device_stops():
    X = np.random.default_rng(0).normal(size=(4, 4, 3))
    names, X2, added = kad_knee_markers(["LKAX", "LKD1", "LKD2", "LKNE"], X, source="s.c3d")
    assert added == [] and names == ["LKAX", "LKD1", "LKD2", "LKNE"] and X2.shape == X.shape
    with pytest.raises(LoperInputError, match="s.c3d: knee alignment device LKAX, LKD1, LKD2: no other knee"):
        kad_knee_markers(["LKAX", "LKD1", "LKD2"], X[:, :3], source="s.c3d")
