"""The segment table file (io.segment_table): TSV round trips of segment parameters to 10 significant digits,
the text written, and a missing file or column named."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.segment_table import (
    SEGMENT_FLOAT_FORMAT,
    read_segment_table,
    read_segments,
    write_segment_table,
    write_segments,
)
from loper_analysis.swing_leg.dynamics import SegmentParameters
from tests.parameter_sets import ASYMMETRIC, WINTER

PARAMETER_SETS = {"winter": WINTER, "asymmetric": ASYMMETRIC}


@pytest.fixture(params=sorted(PARAMETER_SETS))
def params(request) -> SegmentParameters:
    return PARAMETER_SETS[request.param]


def _fields(p: SegmentParameters) -> np.ndarray:
    return np.asarray(p.packed, dtype=float)


def _edited_frame(row: str, column: str, value: str) -> pd.DataFrame:
    df = PARAMETER_SETS["asymmetric"].to_frame().astype(object).set_index("segment")
    df.loc[row, column] = value
    return df.reset_index()


def test_segment_parameters_tsv_round_trip(tmp_path, params):
    path = tmp_path / "segments.tsv"
    write_segments(params, path)
    back = read_segments(path)
    # %.10g in write_segments: measured 6.3e-11 relative for the Winter set, 0 for the asymmetric set
    np.testing.assert_allclose(_fields(back), _fields(params), rtol=1e-10, atol=0)


def test_segment_parameters_tsv_round_trip_many_digits(tmp_path):
    """Values with 16 significant digits survive to the 10 digits that write_segments writes (<= 5e-10)."""
    rng = np.random.default_rng(9)
    p = SegmentParameters(
        cart_mass_kg=rng.uniform(40, 60),
        mass_kg=tuple(rng.uniform(1, 8, 3)),
        inertia_kg_m2=tuple(rng.uniform(0.005, 0.15, 3)),
        length_m=tuple(rng.uniform(0.25, 0.45, 3)),
        com_x_m=tuple(rng.uniform(-0.05, 0.05, 3)),
        com_y_m=tuple(rng.uniform(-0.2, -0.02, 3)),
        attachment_m=0.27123456789012345,
        gravity_m_per_s2=9.80665,
    )
    write_segments(p, tmp_path / "s.tsv")
    back = read_segments(tmp_path / "s.tsv")
    np.testing.assert_allclose(_fields(back), _fields(p), rtol=5e-10, atol=0)


def test_read_segments_names_the_file_and_the_missing_column(tmp_path):
    good = tmp_path / "good.tsv"
    write_segments(PARAMETER_SETS["asymmetric"], good)
    bad = tmp_path / "no_com_x.tsv"
    pd.read_csv(good, sep="\t").drop(columns="com_x_m").to_csv(bad, sep="\t", index=False)
    with pytest.raises(LoperInputError) as info:
        read_segments(bad)
    assert str(bad) in str(info.value) and "com_x_m" in str(info.value)


def test_read_segments_names_the_file_of_a_non_numeric_cell(tmp_path):
    bad = tmp_path / "bad.tsv"
    _edited_frame("shank", "mass_kg", "abc").to_csv(bad, sep="\t", index=False)
    with pytest.raises(LoperInputError) as info:
        read_segments(bad)
    msg = str(info.value)
    assert str(bad) in msg and "mass_kg" in msg and "abc" in msg, msg


def test_the_file_is_one_row_per_segment_at_ten_digits(tmp_path):
    """The asymmetric set's rows as text: empty cells where a segment has no value, 1/3 as 10 digits."""
    assert SEGMENT_FLOAT_FORMAT == "%.10g"
    path = write_segments(ASYMMETRIC, tmp_path / "segments.tsv")
    lines = path.read_text().splitlines()
    assert lines[0] == "segment\tmass_kg\tinertia_kg_m2\tlength_m\tcom_x_m\tcom_y_m\tattachment_m\tgravity_m_per_s2"
    assert lines[1:3] == ["cart\t41.3\t\t\t\t\t\t9.79", "thigh\t7.9\t0.151\t0.43\t0.021\t-0.185\t0.29\t"]
    write_segment_table(pd.DataFrame({"segment": ["x"], "v": [1 / 3]}), tmp_path / "third.tsv")
    assert (tmp_path / "third.tsv").read_text().splitlines()[1] == "x\t0.3333333333"
    assert read_segment_table(tmp_path / "third.tsv")["v"].iloc[0] == 0.3333333333


def test_a_missing_file_is_named(tmp_path):
    with pytest.raises(LoperInputError, match=rf"^{tmp_path / 'none.tsv'}: segment table not found$"):
        read_segments(tmp_path / "none.tsv")
