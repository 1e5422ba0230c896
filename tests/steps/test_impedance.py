"""The file step of the impedance fit (loper_analysis.steps.impedance.fit) on files in tmp_path."""

from __future__ import annotations

import pandas as pd

from loper_analysis.io.truth import write_truth
from loper_analysis.steps.impedance import fit


def test_onset_without_trials_writes_missing_rows(tmp_path):
    anthropometry = {"subject": "S01", "sex": "male", "age_yr": 26, "height_m": 1.8, "mass_kg": 72}
    write_truth(
        tmp_path / "truth.yaml", anthropometry, {175: {j: {"K": 40.0, "D": 2.0} for j in ("hip", "knee", "ankle")}}
    )
    out = [tmp_path / n for n in ("r.tsv", "c.tsv", "f.tsv", "k.tsv")]
    rows = fit([], [], [], [], [], tmp_path / "segments.tsv", 175, "S01", *out, truth_yaml=tmp_path / "truth.yaml")
    assert (rows.status == "missing").all() and rows.K_nm_per_rad.isna().all()
    assert (rows.K_true_nm_per_rad == 40.0).all()
    assert all(p.is_file() for p in out)
    assert pd.read_csv(out[2], sep="\t").status.tolist() == ["missing"] * 3
