"""File steps of the validation study: the subject's segment table from Winter's fractions, and the chunks'
tables gathered and written with enough digits for errors of 1e-5 N·m/rad."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.constants import PARAMETERS
from loper_analysis.io.segment_table import read_segments
from loper_analysis.stages.validation.step import validation_figure, validation_segments, validation_tables


def test_the_segment_table_holds_winter_s_masses_and_lengths(tmp_path):
    validation_segments(tmp_path / "segments.tsv", 1.80, 80.0, 0.5)
    params = read_segments(tmp_path / "segments.tsv")
    # Winter: thigh 0.100, shank 0.0465, foot 0.0145 of the body mass; 0.245, 0.246, 0.152 of the height
    np.testing.assert_allclose(params.mass_kg, [8.0, 3.72, 1.16], rtol=1e-12)
    np.testing.assert_allclose(params.length_m, [0.441, 0.4428, 0.2736], rtol=1e-12)
    assert params.attachment_m == pytest.approx(0.5 * 0.441, rel=1e-12)  # the brace halfway down the thigh
    assert params.cart_mass_kg == pytest.approx(80.0 - 8.0 - 3.72 - 1.16, rel=1e-12)  # the body but the swing leg


def _errors(combination: int, condition: str, base: float) -> pd.DataFrame:
    return pd.DataFrame(
        {
            "condition": condition,
            "combination": combination,
            "parameter": list(PARAMETERS),
            "error": base + 1.23456789e-5 * np.arange(1, 7),
        }
    )


def _fits(combination: int, condition: str) -> pd.DataFrame:
    return pd.DataFrame({"condition": [condition], "combination": [combination], "cost_rad2": [1e-9 * combination]})


def test_gathered_tables_read_back_to_the_chunks_values(tmp_path):
    chunks = {1: (_errors(1, "noise", 149.9), _fits(1, "noise")), 0: (_errors(0, "noise", -0.7), _fits(0, "noise"))}
    error_paths, fit_paths = [], []
    for k, (errors, fits) in chunks.items():
        errors.to_csv(tmp_path / f"errors_{k}.tsv", sep="\t", index=False, float_format="%.17g")
        fits.to_csv(tmp_path / f"fits_{k}.tsv", sep="\t", index=False, float_format="%.17g")
        error_paths.append(tmp_path / f"errors_{k}.tsv")
        fit_paths.append(tmp_path / f"fits_{k}.tsv")
    summary = validation_tables(
        error_paths, fit_paths, tmp_path / "errors.tsv", tmp_path / "fits.tsv", tmp_path / "summary.tsv"
    )
    errors = pd.read_csv(tmp_path / "errors.tsv", sep="\t")
    assert errors["combination"].tolist() == [0] * 6 + [1] * 6  # sorted by combination
    expected = np.concatenate([-0.7 + 1.23456789e-5 * np.arange(1, 7), 149.9 + 1.23456789e-5 * np.arange(1, 7)])
    np.testing.assert_allclose(errors["error"], expected, rtol=1e-14, atol=0)  # 15 significant digits
    np.testing.assert_allclose(pd.read_csv(tmp_path / "fits.tsv", sep="\t")["cost_rad2"], [0.0, 1e-9], rtol=1e-14)
    written = pd.read_csv(tmp_path / "summary.tsv", sep="\t")
    assert len(written) == len(summary) and written["parameter"].tolist() == list(PARAMETERS)
    k_hip = written.iloc[0]  # errors -0.7 + 1.23456789e-5 and 149.9 + 1.23456789e-5
    assert (k_hip.min_error, k_hip.max_error) == pytest.approx((-0.7 + 1.23456789e-5, 149.9 + 1.23456789e-5), 1e-13)
    assert k_hip.sd_error == pytest.approx(150.6 / np.sqrt(2.0), rel=1e-13) and k_hip.n == 2  # SD of two values
    validation_figure(tmp_path / "errors.tsv", tmp_path / "errors.png")
    assert (tmp_path / "errors.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
