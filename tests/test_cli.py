"""The ``loper-analysis`` command (loper_analysis.cli): the installed console script and ``main(argv)``."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

from loper_analysis.cli import main
from loper_analysis.io.c3d_writer import write_c3d
from loper_analysis.io.opensim_tables import read_mot, write_trc
from loper_analysis.io.osim import quiet_opensim, write_model
from loper_analysis.io.segment_table import read_segments
from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.model import MARKERS, build_lower_body_model
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry


def test_segments_command_writes_winter_table(tmp_path):
    """Through the installed console script."""
    out = tmp_path / "seg.tsv"
    res = subprocess.run(
        ["loper-analysis", "segments", "--height-m", "1.8", "--mass-kg", "70", "--out", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert res.returncode == 0, res.stderr
    p = read_segments(out)
    ref = segment_parameters_from_anthropometry(1.8, 70)
    np.testing.assert_allclose(p.packed, ref.packed, rtol=1e-9)
    np.testing.assert_allclose(p.mass_kg[0], 7.0, rtol=1e-12)  # Winter: thigh 0.100 of body mass


def test_segments_command_rejects_bad_height(tmp_path, capsys):
    out = tmp_path / "seg.tsv"
    assert main(["segments", "--height-m", "3.1", "--mass-kg", "70", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "height_m" in err and "3.1" in err
    assert not out.exists()


@pytest.mark.parametrize(
    "solver, atol",
    [
        ("opensim", 1e-6),  # the same engine: the two stop at the same place
        ("tree", 5e-6),  # the tree converges further than the tool at 1e-8 does: measured 1.1e-6 rad
    ],
)
def test_ik_command_matches_opensims_tool(tmp_path, capsys, solver, atol):
    """`loper-analysis ik` on a C3D (mm, lab frame) and an IK task-set XML against InverseKinematicsTool on a TRC,
    with either solver."""
    osim = quiet_opensim()
    generic = build_lower_body_model(1.73, 64.9)
    model = write_model(generic, tmp_path / "model.osim")
    t = np.arange(64) / 128.0
    w = 2 * np.pi * 0.6
    truth = {
        "pelvis_ty": 0.93 + 0.01 * np.sin(2 * w * t),
        "hip_flexion_l": 0.1 + 0.3 * np.sin(w * t),
        "knee_flexion_l": 0.6 + 0.5 * np.sin(w * t + 1),
        "ankle_dorsiflexion_r": -0.1 * np.sin(w * t + 2),
    }
    X = marker_positions(generic, truth) + np.random.default_rng(0).normal(0, 0.002, (t.size, len(MARKERS), 3))
    write_trc(tmp_path / "trial.trc", t, X, list(MARKERS))
    lab = np.stack([X[..., 0], -X[..., 2], X[..., 1]], axis=-1)  # model (Y up) -> Qualisys lab (Z up)
    write_c3d(tmp_path / "trial.c3d", list(MARKERS), lab, 128.0)
    tasks = osim.IKTaskSet()
    for m in MARKERS:
        mt = osim.IKMarkerTask()
        mt.setName(m)
        mt.setWeight(3.0 if m.endswith("ASI") else 1.0)
        tasks.cloneAndAppend(mt)
    ct = osim.IKCoordinateTask()
    ct.setName("ankle_dorsiflexion_l")
    ct.setWeight(5.0)
    ct.setValueType(osim.IKCoordinateTask.ManualValue)
    ct.setValue(0.05)
    tasks.cloneAndAppend(ct)
    tasks.printToXML(str(tmp_path / "tasks.xml"))
    tool = osim.InverseKinematicsTool()
    tool_model = osim.Model(str(model))
    tool.setModel(tool_model)
    tool.setMarkerDataFileName(str(tmp_path / "trial.trc"))
    tool.set_IKTaskSet(osim.IKTaskSet(str(tmp_path / "tasks.xml")))
    tool.setStartTime(0.1)
    tool.setEndTime(0.4)
    tool.set_accuracy(1e-8)
    tool.setOutputMotionFileName(str(tmp_path / "tool.mot"))
    tool.set_results_directory(str(tmp_path))
    assert tool.run()
    code = main(
        [
            "ik",
            "--model",
            str(model),
            "--markers",
            str(tmp_path / "trial.c3d"),
            "--out",
            str(tmp_path / "ours.mot"),
            "--tasks",
            str(tmp_path / "tasks.xml"),
            "--start",
            "0.1",
            "--end",
            "0.4",
            "--tree-step-tolerance",
            "1e-8",
            "--opensim-accuracy",
            "1e-8",
            "--solver",
            solver,
        ]
    )
    assert code == 0, capsys.readouterr().err
    ours, ref = read_mot(tmp_path / "ours.mot"), read_mot(tmp_path / "tool.mot")
    assert len(ours) == len(ref) == 39  # frames 0.1 .. 0.4 s at 128 Hz
    np.testing.assert_allclose(ours.time_s, ref.time_s, atol=1e-9)
    for c in ref.columns[1:]:
        np.testing.assert_allclose(ours[c], ref[c], atol=atol, err_msg=c)


def test_ik_command_refuses_the_former_accuracy_naming_its_two_options(tmp_path, capsys):
    """``--accuracy`` set the tree solver's step tolerance and OpenSim's accuracy at once: refused, naming the two
    options that replace it, before anything is read."""
    out = tmp_path / "out.mot"
    with pytest.raises(SystemExit) as stop:
        main(["ik", "--model", "m.osim", "--markers", "t.trc", "--out", str(out), "--accuracy", "1e-6"])
    assert stop.value.code == 2 and not out.exists()
    err = capsys.readouterr().err
    assert "--accuracy is no longer an option" in err
    assert "--tree-step-tolerance" in err and "ik.tree_step_tolerance" in err
    assert "--opensim-accuracy" in err and "ik.opensim_accuracy" in err


def test_ik_command_names_a_missing_marker(tmp_path, capsys):
    model = write_model(build_lower_body_model(1.73, 64.9), tmp_path / "model.osim")
    write_trc(tmp_path / "trial.trc", np.arange(3) / 128.0, np.zeros((3, 1, 3)), ["LASI"])
    (tmp_path / "tasks.tsv").write_text("name\tkind\tweight\nLASI\tmarker\t1\nRASI\tmarker\t1\n")
    code = main(
        [
            "ik",
            "--model",
            str(model),
            "--markers",
            str(tmp_path / "trial.trc"),
            "--out",
            str(tmp_path / "out.mot"),
            "--tasks",
            str(tmp_path / "tasks.tsv"),
        ]
    )
    assert code == 2
    err = capsys.readouterr().err
    assert "trial.trc" in err and "['RASI']" in err and "not in the marker data" in err
    assert not (tmp_path / "out.mot").exists()
