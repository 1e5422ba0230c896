"""The installed console script."""

import subprocess

import numpy as np

from loper_analysis.dynamics import SegmentParameters, segment_parameters_from_anthropometry


def test_segments_command_writes_winter_table(tmp_path):
    out = tmp_path / "seg.tsv"
    res = subprocess.run(
        ["loper-analysis", "segments", "--height-m", "1.8", "--mass-kg", "70", "--out", str(out)],
        capture_output=True, text=True,
    )
    assert res.returncode == 0, res.stderr
    p = SegmentParameters.from_tsv(out)
    ref = segment_parameters_from_anthropometry(1.8, 70)
    np.testing.assert_allclose(p.packed, ref.packed, rtol=1e-9)
    np.testing.assert_allclose(p.mass_kg[0], 7.0, rtol=1e-12)  # Winter: thigh 0.100 of body mass


def test_segments_command_rejects_bad_height(tmp_path):
    out = tmp_path / "seg.tsv"
    res = subprocess.run(
        ["loper-analysis", "segments", "--height-m", "3.1", "--mass-kg", "70", "--out", str(out)],
        capture_output=True, text=True,
    )
    assert res.returncode == 2
    assert "height_m" in res.stderr and "3.1" in res.stderr
    assert not out.exists()
