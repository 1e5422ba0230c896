"""The validation study (loper_analysis.impedance.identification.validation): the impedance grid, chunking, the
error summary,
the gathered tables and one small chunk run."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
import pytest

from loper_analysis.constants import JOINTS, PARAMETERS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.validation import (
    CONDITIONS,
    ValidationSettings,
    chunk_combinations,
    gather_validation_tables,
    impedance_grid,
    run_validation_chunk,
    summarize_errors,
)
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry

K_LEVELS = (0.0, 75.0, 150.0)
D_LEVELS = (0.0, 2.0, 4.0)


# ---------------------------------------------------------------- grid


def test_impedance_grid_holds_every_combination_once():
    grid = impedance_grid(K_LEVELS, D_LEVELS)
    assert grid.shape == (729, 6)
    assert len(np.unique(grid, axis=0)) == 729
    expected = set(itertools.product(K_LEVELS, D_LEVELS, K_LEVELS, D_LEVELS, K_LEVELS, D_LEVELS))
    assert {tuple(row) for row in grid} == expected
    # K columns hold K levels, D columns D levels, each level 729 / 3 times
    for j in range(6):
        levels = K_LEVELS if j % 2 == 0 else D_LEVELS
        values, counts = np.unique(grid[:, j], return_counts=True)
        np.testing.assert_array_equal(values, levels)
        np.testing.assert_array_equal(counts, [243, 243, 243])
    # documented order: D_ankle varies fastest, K_hip slowest
    np.testing.assert_array_equal(grid[0], np.zeros(6))
    np.testing.assert_array_equal(grid[1] - grid[0], [0, 0, 0, 0, 0, 2.0])
    np.testing.assert_array_equal(grid[-1], [150.0, 4.0, 150.0, 4.0, 150.0, 4.0])
    np.testing.assert_array_equal(grid[:243, 0], 0.0)


def test_impedance_grid_other_level_counts():
    grid = impedance_grid((10.0, 20.0), (1.0,))
    assert grid.shape == (8, 6)
    assert len(np.unique(grid, axis=0)) == 8
    np.testing.assert_array_equal(grid[:, 1::2], 1.0)


@pytest.mark.parametrize("n_chunks", [1, 2, 7, 50, 728, 729])
def test_chunk_combinations_cover_everything_once(n_chunks):
    # the contract is a partition of 0 .. 728 into balanced chunks; contiguous or strided does not matter
    chunks = [chunk_combinations(729, n_chunks, c) for c in range(n_chunks)]
    everything = np.concatenate(chunks)
    assert np.issubdtype(everything.dtype, np.integer)
    np.testing.assert_array_equal(np.sort(everything), np.arange(729))
    sizes = [len(c) for c in chunks]
    assert max(sizes) - min(sizes) <= 1 and min(sizes) >= 1
    # the same call gives the same chunk
    np.testing.assert_array_equal(chunk_combinations(729, n_chunks, n_chunks - 1), chunks[-1])


@pytest.mark.parametrize(
    "n_chunks, chunk, words",
    [
        (0, 0, ["n_chunks", "0"]),
        (730, 0, ["n_chunks", "730"]),
        (-3, 0, ["n_chunks", "-3"]),
        (10, 10, ["chunk", "10"]),
        (10, -1, ["chunk", "-1"]),
    ],
)
def test_chunk_combinations_rejects_bad_arguments(n_chunks, chunk, words):
    with pytest.raises(LoperInputError) as info:
        chunk_combinations(729, n_chunks, chunk)
    for w in words:
        assert w in str(info.value), (w, str(info.value))


@pytest.mark.parametrize("n_chunks, chunk", [(2.5, 0), (3, 0.5)])
def test_chunk_combinations_rejects_non_integers(n_chunks, chunk):
    with pytest.raises(LoperInputError):
        chunk_combinations(729, n_chunks, chunk)


# ---------------------------------------------------------------- summary


def test_summarize_errors_on_a_handmade_table():
    rows = []
    # given out of order on purpose: the summary is sorted by condition, then parameter order
    table = {
        ("noise", "D_hip"): [0.5, -0.25, 0.0, 1.0],
        ("no_noise", "K_knee"): [2.0, -4.0, 5.0],
        ("noise", "K_hip"): [-3.0, 3.0],
        ("no_noise", "K_hip"): [1.0, 1.0, 1.0],
    }
    for (cond, par), errs in table.items():
        for k, e in enumerate(errs):
            rows.append({"condition": cond, "combination": k, "parameter": par, "error": e})
    out = summarize_errors(pd.DataFrame(rows))
    assert list(out[["condition", "parameter"]].itertuples(index=False, name=None)) == [
        ("no_noise", "K_hip"),
        ("no_noise", "K_knee"),
        ("noise", "K_hip"),
        ("noise", "D_hip"),
    ]
    # hand-computed: mean 1, 1, 0, 0.3125; SD with ddof = 1
    np.testing.assert_allclose(out.min_error, [1.0, -4.0, -3.0, -0.25], rtol=0, atol=0)
    np.testing.assert_allclose(out.max_error, [1.0, 5.0, 3.0, 1.0], rtol=0, atol=0)
    np.testing.assert_allclose(out.max_abs_error, [1.0, 5.0, 3.0, 1.0], rtol=0, atol=0)
    np.testing.assert_allclose(
        out.sd_error,
        [0.0, np.sqrt((1 + 25 + 16) / 2), np.sqrt(18.0), np.sqrt((0.1875**2 + 0.5625**2 + 0.3125**2 + 0.6875**2) / 3)],
        rtol=1e-14,
        atol=1e-15,
    )
    np.testing.assert_array_equal(out.n, [3, 3, 2, 4])


def test_summarize_errors_needs_its_columns():
    with pytest.raises(LoperInputError) as info:
        summarize_errors(pd.DataFrame({"condition": ["noise"], "parameter": ["K_hip"], "err": [1.0]}))
    assert "error" in str(info.value)


def test_gather_validation_tables_sorts_the_chunks_and_adds_the_study_values():
    """Chunks arrive in any order: rows sort by condition (no_noise first), combination and parameter order."""

    def errors(combination, condition, offset):
        return pd.DataFrame(
            {
                "condition": condition,
                "combination": combination,
                "parameter": list(PARAMETERS)[::-1],
                "error": offset + np.arange(6.0),
            }
        )

    def fits(combination, condition):
        return pd.DataFrame({"condition": [condition], "combination": [combination], "cost_rad2": [combination]})

    error_chunks = [
        pd.concat([errors(3, "noise", 10.0), errors(1, "no_noise", 0.0)]),
        pd.concat([errors(0, "noise", 20.0), errors(2, "no_noise", 30.0)]),
    ]
    fit_chunks = [
        pd.concat([fits(3, "noise"), fits(1, "no_noise")]),
        pd.concat([fits(0, "noise"), fits(2, "no_noise")]),
    ]
    gathered, fit_table, summary = gather_validation_tables(error_chunks, fit_chunks)
    assert list(zip(fit_table.condition, fit_table.combination)) == [
        ("no_noise", 1),
        ("no_noise", 2),
        ("noise", 0),
        ("noise", 3),
    ]
    assert list(gathered.parameter[:6]) == list(PARAMETERS) and len(gathered) == 24
    assert list(zip(gathered.condition[::6], gathered.combination[::6])) == list(
        zip(fit_table.condition, fit_table.combination)
    )
    # the summary is summarize_errors of the gathered errors, with the study's columns beside it
    pd.testing.assert_frame_equal(summary[summarize_errors(gathered).columns], summarize_errors(gathered))
    noise = summary[summary.condition == "noise"]
    assert noise[["study_min_error", "study_max_error", "study_sd_error"]].notna().all().all()
    assert summary[summary.condition == "no_noise"].study_sd_error.isna().all()


# ---------------------------------------------------------------- one small chunk


@pytest.fixture(scope="module")
def chunk_run():
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    settings = ValidationSettings(n_starts=3)
    combos = [0, 400]
    first = run_validation_chunk(params, settings, combos)
    second = run_validation_chunk(params, settings, combos)
    return settings, combos, first, second


def test_run_validation_chunk_tables(chunk_run):
    settings, combos, (errors, fits), _ = chunk_run
    assert len(errors) == 2 * 2 * 6
    assert {"condition", "combination", "parameter", "true", "estimate", "error", "ci95_low", "ci95_high"} <= set(
        errors.columns
    )
    assert len(fits) == 2 * 2
    assert {"condition", "combination", "cost_rad2", "success", "message"} | {f"vaf_{j}_pct" for j in JOINTS} <= set(
        fits.columns
    )
    grid = impedance_grid(settings.stiffness_levels_nm_per_rad, settings.damping_levels_nms_per_rad)
    for c in combos:
        for cond in CONDITIONS:
            sub = errors[(errors.combination == c) & (errors.condition == cond)]
            assert list(sub.parameter) == list(PARAMETERS)
            np.testing.assert_array_equal(sub["true"].to_numpy(), grid[c])
            np.testing.assert_array_equal(sub.error.to_numpy(), sub.estimate.to_numpy() - grid[c])
            assert np.all(sub.ci95_low <= sub.estimate) and np.all(sub.estimate <= sub.ci95_high)
    # noise-free: hip and knee recovered (measured |error| <= 2e-5)
    clean = errors[(errors.condition == "no_noise") & errors.parameter.isin(["K_hip", "K_knee"])]
    np.testing.assert_allclose(clean.error, 0.0, rtol=0, atol=0.05)
    clean = errors[(errors.condition == "no_noise") & errors.parameter.isin(["D_hip", "D_knee"])]
    np.testing.assert_allclose(clean.error, 0.0, rtol=0, atol=0.005)


def test_run_validation_chunk_is_bit_identical_on_repeat(chunk_run):
    _, _, (errors1, fits1), (errors2, fits2) = chunk_run
    pd.testing.assert_frame_equal(errors1, errors2, check_exact=True)
    # wall-clock columns (if any) are the only thing allowed to differ
    drop = [c for c in ("seconds",) if c in fits1.columns]
    pd.testing.assert_frame_equal(fits1.drop(columns=drop), fits2.drop(columns=drop), check_exact=True)


def test_run_validation_chunk_rejects_unknown_combination():
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    with pytest.raises(LoperInputError) as info:
        run_validation_chunk(params, ValidationSettings(n_starts=1), [729])
    assert "729" in str(info.value)
