"""The IK file steps (loper_analysis.steps.ik): a TRC solved in time chunks and joined equals one solve of it."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.opensim_tables import read_mot, write_trc
from loper_analysis.io.osim import write_model
from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.ik_settings import IKSettings
from loper_analysis.motion.model import MARKERS, build_lower_body_model
from loper_analysis.steps.ik import ik_chunk, ik_join, ik_trial

FS = 128.0


@pytest.fixture(scope="module")
def trial(tmp_path_factory):
    """A generic model (.osim) and a 2 s TRC of its markers moved through known angles."""
    tmp = tmp_path_factory.mktemp("ik_steps")
    model = build_lower_body_model(1.73, 64.9)
    t = np.arange(256) / FS
    w = 2 * np.pi * 0.6
    truth = {
        "pelvis_tx": 0.02 * np.sin(2 * w * t),
        "pelvis_ty": 0.93 + 0.01 * np.sin(2 * w * t),
        "pelvis_tilt": 0.05 * np.sin(w * t),
        "hip_flexion_l": 0.1 + 0.3 * np.sin(w * t),
        "knee_flexion_l": 0.6 + 0.5 * np.sin(w * t + 1),
        "ankle_dorsiflexion_l": 0.1 * np.sin(w * t + 2),
    }
    trc = write_trc(tmp / "trial.trc", t, marker_positions(model, truth), list(MARKERS))
    return write_model(model, tmp / "model.osim"), trc, truth


def test_chunks_joined_through_files_equal_the_whole_trial(trial, tmp_path):
    model_osim, trc, truth = trial
    fine = IKSettings(accuracy=1e-8)
    whole = ik_trial(model_osim, trc, tmp_path / "whole.mot", tmp_path / "whole.angles.tsv", fine)
    np.testing.assert_allclose(whole.knee_left_rad, truth["knee_flexion_l"], atol=np.deg2rad(0.1) / 10)
    mots = [tmp_path / f"chunk{c}.mot" for c in range(3)]
    for c, mot in enumerate(mots):
        ik_chunk(model_osim, trc, mot, c, 3, fine)
    assert [len(read_mot(m)) for m in mots] == [85, 86, 85]
    joined = ik_join(mots, tmp_path / "joined.mot", tmp_path / "joined.angles.tsv", summary_tsv=tmp_path / "j.ik.tsv")
    assert (tmp_path / "joined.mot").is_file() and (tmp_path / "joined.angles.tsv").is_file()
    summary = pd.read_csv(tmp_path / "j.ik.tsv", sep="\t").iloc[0]  # the chunks keep no marker errors
    assert (summary.n_frames, summary.n_frames_solved, summary.n_frames_left_out) == (256, 256, 0)
    assert np.isnan(summary.marker_rms_mean_m) and summary.last_solved_s == whole.time_s.iloc[-1]
    assert list(joined.columns) == list(whole.columns)
    np.testing.assert_allclose(joined.time_s, whole.time_s, atol=1e-9)
    np.testing.assert_allclose(joined.drop(columns="time_s"), whole.drop(columns="time_s"), atol=1e-7)


def test_joining_an_overlapping_chunk_names_its_file(trial, tmp_path):
    model_osim, trc, _ = trial
    first, again = tmp_path / "first.mot", tmp_path / "again.mot"
    ik_chunk(model_osim, trc, first, 0, 3)
    again.write_bytes(first.read_bytes())
    with pytest.raises(LoperInputError, match=r"again\.mot: starts at t = 0\.0000"):
        ik_join([first, again], tmp_path / "out.mot", tmp_path / "out.angles.tsv")
    assert not (tmp_path / "out.mot").exists() and not (tmp_path / "out.angles.tsv").exists()
