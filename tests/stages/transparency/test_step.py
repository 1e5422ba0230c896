"""The transparency step on the stride and cycle tables the strides step writes."""

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import TooFewStridesWarning
from tests.gait.test_strides import _overground
from tests.stages.strides.test_step import _no_warning


def test_transparency_leaves_out_a_subject_with_zero_or_one_stride(tmp_path):
    """The transparency step on stride tables of 0 and 1 strides (as the strides step writes them): the subject
    is left out with its counts, nothing crashes; the other subject is compared with itself (RMSD 0)."""
    from loper_analysis.io.atomic import write_tsv
    from loper_analysis.stages.strides.step import strides
    from loper_analysis.stages.transparency.files import TransparencyFiles
    from loper_analysis.stages.transparency.step import transparency

    paths = {}
    for n_heel_strikes in (1, 2, 6):
        angles, events, force = _overground(n_heel_strikes)
        for name, frame in (("angles", angles), ("events", events), ("force", force)):
            write_tsv(frame, tmp_path / f"{n_heel_strikes}.{name}.tsv")
        with pytest.warns(TooFewStridesWarning) if n_heel_strikes < 6 else _no_warning():
            strides(
                tmp_path / f"{n_heel_strikes}.angles.tsv",
                tmp_path / f"{n_heel_strikes}.events.tsv",
                tmp_path / f"{n_heel_strikes}.strides.tsv",
                tmp_path / f"{n_heel_strikes}.cycles.tsv",
                tmp_path / f"{n_heel_strikes}.force.tsv",
            )
        paths[n_heel_strikes] = (tmp_path / f"{n_heel_strikes}.strides.tsv", tmp_path / f"{n_heel_strikes}.cycles.tsv")
    pairs = {"S01": (6, 6), "S02": (6, 1), "S03": (2, 6)}  # heel strikes without, with the device
    with pytest.warns(TooFewStridesWarning) as caught:
        transparency(
            {s: TransparencyFiles(*paths[a], *paths[b]) for s, (a, b) in pairs.items()},
            tmp_path / "rmsd.tsv",
            tmp_path / "force.tsv",
            tmp_path / "t.png",
        )
    assert sorted(str(w.message).split(":")[0] for w in caught) == ["subject S02", "subject S03"]
    rmsd = pd.read_csv(tmp_path / "rmsd.tsv", sep="\t")
    assert rmsd.subject.tolist() == ["S01"] * 6 + ["S02"] * 6 + ["S03"] * 6 + ["all"] * 6
    counts = rmsd.groupby("subject", sort=False)[["n_strides_no_device", "n_strides_device"]].first()
    assert counts.loc[["S01", "S02", "S03"]].values.tolist() == [[5, 5], [5, 0], [1, 5]]
    assert rmsd.loc[rmsd.subject.isin(["S02", "S03"]), "rmsd_rad"].isna().all()
    np.testing.assert_allclose(rmsd.loc[rmsd.subject == "S01", "rmsd_rad"], 0.0, atol=1e-12)
