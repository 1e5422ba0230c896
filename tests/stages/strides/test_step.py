"""The strides step and the per-trial summary on files: trials of zero, one and enough strides written and read
back."""

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import TooFewStridesWarning
from loper_analysis.gait.stride_settings import StrideSettings
from tests.gait.test_strides import STRIDE_COLUMNS, _overground


def test_the_steps_write_and_summarise_trials_with_zero_and_one_stride(tmp_path):
    """The files of 0 and 1 strides hold every column; read back as strides_summary reads them they give
    n_strides 0 and 1 and too_few_strides, next to a trial with enough strides."""
    from loper_analysis.io.atomic import write_tsv
    from loper_analysis.io.readers import read_tsv
    from loper_analysis.stages.strides.step import strides, strides_summary

    files = {}
    for n_heel_strikes in (1, 2, 6):
        angles, events, force = _overground(n_heel_strikes)
        for name, frame in (("angles", angles), ("events", events), ("force", force)):
            write_tsv(frame, tmp_path / f"{n_heel_strikes}.{name}.tsv")
        out = tmp_path / f"{n_heel_strikes}.strides.tsv"
        with pytest.warns(TooFewStridesWarning) if n_heel_strikes < 6 else _no_warning():
            strides(
                tmp_path / f"{n_heel_strikes}.angles.tsv",
                tmp_path / f"{n_heel_strikes}.events.tsv",
                out,
                tmp_path / f"{n_heel_strikes}.cycles.tsv",
                tmp_path / f"{n_heel_strikes}.force.tsv",
                StrideSettings(min_valid=5 if n_heel_strikes < 6 else 4),
            )
        files[n_heel_strikes] = out
    assert files[1].read_text() == "\t".join(STRIDE_COLUMNS) + "\n"  # the header only, every column
    assert (tmp_path / "1.cycles.tsv").read_text().splitlines() == [
        "stride\tphase\tpoint\tpercent\thip_left_rad\tknee_left_rad\tankle_left_rad\tforce_n"
    ]
    back = read_tsv(files[1], "stride table", keep_default_na=False, na_values=[""])
    assert list(back.columns) == STRIDE_COLUMNS and len(back) == 0
    keys = [("S01", "overground-0"), ("S01", "overground-1"), ("S01", "overground-5")]
    table = strides_summary(keys, [files[1], files[2], files[6]], tmp_path / "summary.tsv", min_valid=4)
    assert table[["trial", "n_strides", "n_perturbed", "n_removed", "n_kept", "status"]].values.tolist() == [
        ["overground-0", 0, 0, 0, 0, "too_few_strides"],
        ["overground-1", 1, 0, 0, 1, "too_few_strides"],
        ["overground-5", 5, 0, 0, 5, "ok"],
    ]
    assert np.isnan(table["mean_stride_s"].iloc[0])
    np.testing.assert_allclose(table["mean_stride_s"].iloc[1:], 1.2, rtol=0, atol=1e-12)
    written = pd.read_csv(tmp_path / "summary.tsv", sep="\t")
    assert written["status"].tolist() == ["too_few_strides", "too_few_strides", "ok"]
    assert written["n_strides"].tolist() == [0, 1, 5]


def _no_warning():
    import contextlib
    import warnings

    @contextlib.contextmanager
    def guard():
        with warnings.catch_warnings():
            warnings.simplefilter("error", TooFewStridesWarning)
            yield

    return guard()
