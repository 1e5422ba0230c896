"""A lab-to-model rotation that hangs the subject below the floor stops the markers step, an absurd one the option:
on every real static and walk (the seven clinical labs', OpenSim's walking5) the feet-to-pelvis direction lies
within a few degrees of the model's +Y with the labs' rotation, and [90, 0, 0] is refused naming the one to try.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from loper_analysis.cli import main
from loper_analysis.io.c3d import read_c3d
from loper_analysis.motion.label_matching import landmark_indices
from loper_analysis.motion.markers import rotate_markers
from loper_analysis.motion.upright import markers_up

DATA = Path(__file__).resolve().parents[1] / "data"
LABS = ("AUC", "FMC", "MH", "QCMAS", "RBWH", "RCH", "SYD")
WALKS = [f"c3d-parser/{lab}/walk-nodevice.c3d" for lab in LABS] + ["opensim-core/walking5.c3d"]
STATICS = [f"c3d-parser/{lab}/static.c3d" for lab in LABS]


@pytest.mark.parametrize("trial", WALKS + STATICS)
def test_the_rotation_of_the_wrong_sign_stops_the_markers_command_and_names_the_right_one(trial, tmp_path, capsys):
    path, out = DATA / trial, tmp_path / "m.trc"
    names = [label.split(":")[-1] for label in read_c3d(path).marker_labels]
    X = rotate_markers(read_c3d(path).markers_m, (-90.0, 0.0, 0.0))
    upper = landmark_indices(names, ["asis", "psis", "sacrum"])
    lower = landmark_indices(names, ["heel", "toe", "mt1", "mt5", "ankle_lateral", "ankle_medial"])
    up, _, agreement = markers_up(X, upper, lower)
    assert np.degrees(np.arccos(up[1])) < 5  # measured 0.4 .. 4.4 deg; the limit is 45
    assert agreement > 0.99  # measured 0.9905 (walking5) .. 1.0; judged from 0.9
    assert main(["markers", str(path), "--out", str(out), "--rotate-deg", "90", "0", "0"]) == 2
    err = capsys.readouterr().err
    assert f"{path}: markers.lab_to_model_rotation_deg (--rotate-deg) [90, 0, 0] does not stand the subject up" in err
    assert "the markers' up is model -Y: try [-90, 0, 0]" in err
    assert not out.exists()


@pytest.mark.parametrize("value", ["1e308", "-400"])
def test_an_absurd_rotation_is_refused_at_the_option(value, tmp_path, capsys):
    out = tmp_path / "m.trc"
    walk = DATA / WALKS[0]
    assert main(["markers", str(walk), "--out", str(out), "--rotate-deg", value, "0", "0"]) == 2
    err = capsys.readouterr().err
    assert "--rotate-deg [" in err and "(the limits of markers.lab_to_model_rotation_deg" in err
    assert not out.exists()


def test_a_rotation_that_lays_the_subject_down_is_warned_about_and_kept(tmp_path, caplog):
    """The lab's frame as it is ([0, 0, 0] for Z-up walking5: a way to compare with OpenSim's own reading): the
    subject lies along the model's +Z, 90 deg from +Y, a warning naming the rotation that stands it up."""
    import logging

    from loper_analysis.stages.markers.step import MarkerSettings, markers

    caplog.set_level(logging.WARNING)
    walking5, out = DATA / "opensim-core/walking5.c3d", tmp_path / "w5.trc"
    markers(walking5, out, settings=MarkerSettings(rotation_deg=(0, 0, 0), walking_direction="fixed"))
    assert out.is_file()
    assert (
        f"{walking5}: markers.lab_to_model_rotation_deg (--rotate-deg) [0, 0, 0] does not stand the subject up: its "
        "pelvis lies along the model's +Z from its feet (90 deg from the model's up, +Y;"
    ) in caplog.text
    assert "so the markers' up is model +Z: try [-90, 0, 0] (the subject lies" in caplog.text
