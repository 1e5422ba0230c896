"""checks.py: each input check returns the value in its working form, or refuses it with a message naming the
source, the field and the value (exact text)."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from loper_analysis import checks
from loper_analysis.errors import LoperInputError


def _refused(message: str):
    return pytest.raises(LoperInputError, match="^" + re.escape(message) + "$")


def test_where_prefixes_the_source_only_when_given():
    assert checks.where("trial.c3d") == "trial.c3d: "
    assert checks.where("") == ""


def test_number_converts_and_names_the_bounds():
    assert checks.number("k", "2.5") == 2.5
    assert checks.number("k", 3, minimum=3, maximum=3) == 3.0  # bounds are inclusive
    with _refused("a.tsv: k must be a finite number in 0 .. 1, got 1.5"):
        checks.number("k", 1.5, "a.tsv", minimum=0, maximum=1)
    with _refused("k must be a finite number >= 0, got -0.25"):
        checks.number("k", -0.25, minimum=0)
    with _refused("k must be a finite number <= 2, got 3.0"):
        checks.number("k", 3, maximum=2)
    with _refused("k must be a finite number, got inf"):
        checks.number("k", float("inf"))
    with _refused("k must be a number, got True"):
        checks.number("k", True)
    with _refused("k must be a number, got 'x'"):
        checks.number("k", "x")


def test_positive_refuses_zero_and_booleans():
    assert checks.positive("mass", "70") == 70.0
    for bad in (0, -1.0, float("nan"), True, "heavy"):
        with _refused(f"s: mass must be a positive number, got {bad!r}"):
            checks.positive("mass", bad, "s")


def test_integer_takes_integral_floats_only():
    assert checks.integer("n", 3.0) == 3 and isinstance(checks.integer("n", 3.0), int)
    assert checks.integer("n", np.int64(7), minimum=7) == 7
    with _refused("n must be an integer >= 1, got 0"):
        checks.integer("n", 0, minimum=1)
    for bad in (2.5, True, "3", float("inf")):
        with _refused(f"n must be an integer, got {bad!r}"):
            checks.integer("n", bad)


def test_side_lists_the_options():
    assert checks.side("right") == "right"
    with _refused("f: side must be one of ('left', 'right'), got 'Left'"):
        checks.side("Left", "f")


def test_time_vector_names_the_first_bad_sample():
    np.testing.assert_array_equal(checks.time_vector([0, 0.5, 1.0]), [0.0, 0.5, 1.0])
    with _refused("f: time_s must increase strictly; sample 2 (0.5 s) follows 0.5 s"):
        checks.time_vector([0.0, 0.5, 0.5, 1.0], "f")
    with _refused("time_s is not finite at frame 1: nan"):
        checks.time_vector([0.0, np.nan, 1.0], item="frame")
    with _refused("t must be 1-D with >= 3 rows, got shape (2,)"):
        checks.time_vector([0.0, 1.0], name="t", min_count=3, item="row")


def test_uniform_step_is_the_mean_step_and_refuses_a_gap():
    assert checks.uniform_step_s(np.arange(11) * 0.01) == pytest.approx(0.01, rel=1e-12)
    t = np.array([0.0, 0.01, 0.02, 0.04, 0.05])  # mean step 0.0125; row 2 steps 0.02
    with _refused("f: time_s must be equally spaced; step 0.02 s at row 2 differs from the mean step 0.0125 s"):
        checks.uniform_step_s(t, "f")


def test_signal_vectors_and_rows():
    assert checks.signal("x", np.zeros((4, 2)), 4).shape == (4, 2)
    with _refused("x must have shape (4,) or (4, k) like time_s, got (3,)"):
        checks.signal("x", np.zeros(3), 4)
    with _refused("v is not finite at sample 2: nan"):
        checks.finite_vector("v", [1.0, 2.0, np.nan])
    with _refused("v needs >= 2 samples, got 1"):
        checks.finite_vector("v", [1.0])
    rows, single = checks.finite_rows("p", [1.0, 2.0, 3.0], 3)
    assert single and rows.shape == (1, 3)
    rows, single = checks.finite_rows("p", np.ones((2, 3)), 3)
    assert not single and rows.shape == (2, 3)
    with _refused("p is not finite at row 1, column 2: inf"):
        checks.finite_rows("p", [[0, 0, 0], [0, 0, np.inf]], 3)
    with _refused("p must have shape (3,) or (n, 3), got (2, 2)"):
        checks.finite_rows("p", np.zeros((2, 2)), 3)


def test_marker_array_wants_three_coordinates():
    assert checks.marker_array(np.zeros((5, 2, 3))).shape == (5, 2, 3)
    with _refused("trial.c3d: markers_m must have shape (n_frames, n_markers, 3), got (5, 2)"):
        checks.marker_array(np.zeros((5, 2)), "trial.c3d")
    with _refused("markers: markers_m must have shape (n_frames, n_markers, 3), got (5, 2, 2)"):
        checks.marker_array(np.zeros((5, 2, 2)))


def test_require_columns_and_bool_column():
    table = pd.DataFrame({"a": [1, 0, 1], "b": ["true", "False", True]})
    assert checks.require_columns(table, ["a", "b"]) is table
    with _refused("f: strides: column(s) ['c', 'd'] missing"):
        checks.require_columns(table, ["a", "c", "d"], "f", "strides")
    with _refused("f: table must be a pandas DataFrame, got dict"):
        checks.require_columns({"a": 1}, ["a"], "f")
    np.testing.assert_array_equal(checks.bool_column(table, "a"), [True, False, True])
    np.testing.assert_array_equal(checks.bool_column(table, "b"), [True, False, True])
    bad = pd.DataFrame({"ok": ["yes", "no"]})
    with _refused("f: strides: column 'ok' must be boolean; row 0 holds 'yes'"):
        checks.bool_column(bad, "ok", "f", "strides")


def test_unique_names_rules():
    assert checks.unique_names(["r heel", "LASI"], "labels", allow_whitespace=False, allow_spaces=True) == [
        "r heel",
        "LASI",
    ]
    with _refused("f: labels duplicated: A, B"):
        checks.unique_names(["B", "A", "B", "A", "C"], "labels", "f")
    with _refused("labels must be non-empty strings without leading/trailing blanks, got ' A'"):
        checks.unique_names([" A"], "labels")
    with _refused("labels must be non-empty strings without whitespace, got 'r heel'"):
        checks.unique_names(["r heel"], "labels", allow_whitespace=False)
    with _refused(
        "labels must be non-empty strings of at most 4 characters without leading/trailing blanks or whitespace "
        "other than inner spaces, got 'a\\tb'"
    ):
        checks.unique_names(["a\tb"], "labels", max_chars=4, allow_whitespace=False, allow_spaces=True)
    with _refused(
        "labels must be non-empty strings of at most 4 characters without leading/trailing blanks, got 'LASIS'"
    ):
        checks.unique_names(["LASIS"], "labels", max_chars=4)


def test_generator_is_a_numpy_generator(rng):
    assert checks.generator(rng) is rng
    with _refused("seed must be a numpy.random.Generator, got int"):
        checks.generator(3, "seed")
