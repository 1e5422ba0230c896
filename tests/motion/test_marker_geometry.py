"""Whose markers: a trial's distances between markers on one body against the static trial's, or the model's (the
generated model, its own markers as the trial and as the static trial, and the same trial of a smaller subject);
a clinical lab's real pair in tests/stages/ik/test_step.py."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.motion.marker_geometry import (
    MIN_PAIR_DISTANCE_M,
    geometry_change,
    geometry_message,
    geometry_ratio,
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
    text = geometry_message(other, 0.08, "ik.geometry_stop_change")
    assert "by 10.0 % in the median of" in text and "ik.geometry_stop_change 0.08" in text
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


def test_a_trial_against_a_static_trial_compares_the_pairs_both_hold():
    model = build_lower_body_model(1.80, 72.0)
    X, labels = _marker_positions(model)
    pairs = same_body_marker_pairs(model, labels, min_distance_m=0.0)
    static = np.repeat(X[None], 3, axis=0)
    static[0] = np.nan  # a frame without markers
    # the static trial lacks the first marker: its pairs are not compared
    table = marker_geometry(pairs, np.repeat(0.9 * X[None], 5, axis=0), labels, static[:, 1:], labels[1:])
    compared = set(table["marker_a"]) | set(table["marker_b"])
    assert labels[0] not in compared and len(table) == sum(
        (a != labels[0]) & (b != labels[0]) & (d >= MIN_PAIR_DISTANCE_M)
        for a, b, d in zip(pairs["marker_a"], pairs["marker_b"], pairs["model_distance_m"], strict=True)
    )
    np.testing.assert_allclose(table["reference_distance_m"] * 0.9, table["trial_distance_m"], rtol=1e-12)
    assert np.allclose(table["change"], -0.1) and geometry_ratio(table) == pytest.approx(0.9)
    assert (table["reference_distance_m"] >= MIN_PAIR_DISTANCE_M).all() and (table["n_frames"] == 5).all()
    text = geometry_message(table, 0.08, "ik.geometry_stop_change", "results/markers/S01/static.trc")
    assert text.startswith(
        "the distances between markers on one body differ from the same pairs in the static trial "
        "results/markers/S01/static.trc by 10.0 % in the median of "
    )
    assert "(limit ik.geometry_stop_change 0.08; trial/static ratio 0.900)" in text
    assert "another subject" in text
    # a walking trial in mm against a static trial in m: a unit, named against the static trial
    table = marker_geometry(pairs, np.repeat(1000.0 * X[None], 5, axis=0), labels, static, labels)
    text = geometry_message(table, 0.08, "ik.geometry_stop_change", "static.trc")
    assert "trial/static ratio 1000.000" in text and "1000 times the static trial's: markers in another length" in text
    # without a static trial the model's markers are the reference, and the message says so
    text = geometry_message(marker_geometry(pairs, np.repeat(0.9 * X[None], 5, axis=0), labels), 0.08, "x")
    assert "differ from the subject's model's markers (no static trial to compare with) by 10.0 %" in text
    assert "trial/model ratio 0.900" in text
