"""Whose markers: a trial's distances between markers on one body against the model's (the generated model,
its own markers as the trial, and the same trial of a smaller subject)."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.motion.marker_geometry import (
    MIN_PAIR_DISTANCE_M,
    geometry_change,
    geometry_message,
    marker_geometry,
    same_body_marker_pairs,
)
from loper_analysis.motion.model import build_lower_body_model


def _marker_positions(model) -> tuple[np.ndarray, list[str]]:
    state = model.initSystem()
    markers = model.getMarkerSet()
    labels = [markers.get(i).getName() for i in range(markers.getSize())]
    X = np.array([markers.get(i).getLocationInGround(state).to_numpy() for i in range(markers.getSize())])
    return X, labels


def test_the_models_own_markers_have_its_distances_and_a_smaller_subjects_differ_by_the_ratio():
    model = build_lower_body_model(1.80, 72.0)
    X, labels = _marker_positions(model)
    pairs = same_body_marker_pairs(model, labels)
    assert len(pairs) >= 6 and (pairs["model_distance_m"] >= MIN_PAIR_DISTANCE_M).all()
    assert pairs["body"].nunique() >= 4
    own = marker_geometry(pairs, np.repeat(X[None], 5, axis=0), labels)
    assert np.abs(own["change"]).max() < 1e-12 and geometry_change(own) < 1e-12
    # every length 0.9 times as long: every pair's distance too
    other = marker_geometry(pairs, np.repeat(0.9 * X[None], 5, axis=0), labels)
    assert np.allclose(other["change"], -0.1) and geometry_change(other) == pytest.approx(0.1)
    # the generated model of a subject 1.62 m tall (the markers' offsets from the bones do not all scale)
    small, small_labels = _marker_positions(build_lower_body_model(1.62, 56.0))
    order = [small_labels.index(n) for n in labels]
    s02 = marker_geometry(pairs, np.repeat(small[order][None], 5, axis=0), labels)
    assert 0.08 < geometry_change(s02) < 0.1
    text = geometry_message(other, 0.08, "opensim.geometry_stop_change")
    assert "by 10.0 % in the median of" in text and "opensim.geometry_stop_change 0.08" in text
    assert "ratio 0.900" in text and " mm against " in text


def test_missing_frames_and_markers_are_left_out_of_the_distances():
    model = build_lower_body_model(1.80, 72.0)
    X, labels = _marker_positions(model)
    pairs = same_body_marker_pairs(model, labels[:-1])  # the last marker not in the trial
    assert labels[-1] not in set(pairs["marker_a"]) | set(pairs["marker_b"])
    trial = np.repeat(X[None], 4, axis=0)
    trial[0, 0] = np.nan
    table = marker_geometry(pairs, trial, labels)
    first = table[(table["marker_a"] == labels[0]) | (table["marker_b"] == labels[0])]
    assert len(first) and (first["n_frames"] == 3).all()
    assert np.abs(table["change"]).max() < 1e-12
