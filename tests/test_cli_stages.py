"""Each stage as a command (``loper-analysis markers|grf|events|scale|segments``) on files others wrote.

walking5.c3d (Vicon, from opensim-core's tests) with OpenSim's own reading of it, and gait2392 with a
lab's ScaleTool setup; the commands call the functions the rules call, and every failure is one line
on standard error with exit code 2.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.cli import main
from loper_analysis.io.c3d_writer import write_c3d
from loper_analysis.io.opensim_tables import read_markers, read_mot, write_trc
from loper_analysis.io.osim import read_model
from loper_analysis.io.segment_table import read_segments
from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.segments import segments_from_model
from loper_analysis.stages.model.step import ScaleFiles, scale_with_setup
from tests.gait2392_models import scaled_gait2392

ROOT = Path(__file__).resolve().parents[1]
WALKING5 = ROOT / "tests" / "data" / "opensim-core" / "walking5.c3d"
GAIT2392 = ROOT / "examples" / "gait2392"


def _sto(path: Path) -> pd.DataFrame:
    """OpenSim's storage file std_walking5_grfs.sto as a table (header up to 'endheader')."""
    lines = path.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.strip() == "endheader") + 1
    return pd.read_csv(path, sep=r"\s+", skiprows=start)


def _one_line_error(capsys, *needles: str) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert "Traceback" not in err
    for needle in needles:
        assert needle in err, (needle, err)
    return err


def test_grf_command_on_walking5_agrees_with_opensims_reading(tmp_path, capsys):
    """Force on the body, model frame = lab frame (no rotation), at the rows OpenSim's file holds, loaded only."""
    out = tmp_path / "w5.grf.mot"
    assert main(["grf", str(WALKING5), "--out", str(out), "--rotate-deg", "0", "0", "0"]) == 0, capsys.readouterr()
    mot = read_mot(out)
    ref = _sto(ROOT / "tests" / "data" / "opensim-core" / "std_walking5_grfs.sto")
    rows = np.searchsorted(mot["time_s"].to_numpy(), ref["time"].to_numpy() - 1e-9)
    np.testing.assert_allclose(mot["time_s"].to_numpy()[rows], ref["time"].to_numpy(), atol=1e-9)
    for n in (1, 2):
        ours = mot[[f"{n}_ground_force_v{a}" for a in "xyz"]].to_numpy()[rows]
        theirs = ref[[f"f{n}_{k}" for k in (1, 2, 3)]].to_numpy()
        loaded = ours[:, 2] != 0.0
        assert loaded.sum() >= 10
        rest = np.median(theirs[~loaded], axis=0)  # the plate's unloaded reading, which our output removes
        np.testing.assert_allclose(
            ours[loaded], theirs[loaded] - rest, atol=0.5
        )  # the resting levels differ by < 0.5 N
        np.testing.assert_array_equal(ours[~loaded], 0.0)


def test_markers_command_on_walking5_equals_opensims_reading(tmp_path, capsys):
    out = tmp_path / "w5.trc"
    code = main(
        [
            "markers",
            str(WALKING5),
            "--out",
            str(out),
            "--rotate-deg",
            "0",
            "0",
            "0",
            "--cutoff-hz",
            "0",
            "--max-gap-frames",
            "0",
        ]
    )
    assert code == 0, capsys.readouterr()
    assert "40 markers, 1103 frames; 0 gap(s) filled, 40 marker(s) still missing" in capsys.readouterr().out
    t, X, labels = read_markers(out)
    t_ref, X_ref, labels_ref = read_markers(ROOT / "tests" / "data" / "opensim-core" / "std_walking5_markers.trc")
    assert labels == labels_ref
    frames = np.round(t_ref * 250.0).astype(int)
    np.testing.assert_allclose(t[frames], t_ref, atol=1e-9)
    ours, theirs = 1e3 * X[frames], 1e3 * X_ref
    np.testing.assert_array_equal(np.isnan(ours), np.isnan(theirs))
    both = np.isfinite(theirs) & (np.abs(theirs) < 1000.0)  # below 1 m the reference prints 0.01 mm
    assert np.abs(ours - theirs)[both].max() < 0.01


def test_events_command_on_walking5(tmp_path, capsys):
    """Plate 2 is a clean right-foot contact; the left heel landed behind plate 1 (flagged, no events)."""
    out = tmp_path / "w5.events.tsv"
    assert main(["events", str(WALKING5), "--out", str(out), "--feet", "LCAL", "RCAL"]) == 0, capsys.readouterr()
    events = pd.read_csv(out, sep="\t")
    plain = events[events.event.isin(["heel_strike", "toe_off"])]
    assert plain[["side", "event", "sample"]].values.tolist() == [
        ["right", "heel_strike", 4767],
        ["right", "toe_off", 5954],
    ]
    np.testing.assert_allclose(plain["time_s"], [4767 / 2000.0, 5954 / 2000.0], atol=1e-12)
    assert "1 contact(s) flagged" in capsys.readouterr().out


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """gait2392 scaled with known factors to 80 kg; its markers in the default pose as a static TRC and C3D (Z up)."""
    d = tmp_path_factory.mktemp("scale")
    factors = {"pelvis": 1.05, "torso": 1.05, "femur": 1.10, "tibia": 0.95, "talus": 1.05, "calcn": 1.05, "toes": 1.05}
    model = scaled_gait2392(factors, 80.0, markers=True)
    markers = model.getMarkerSet()
    labels = [markers.get(i).getName() for i in range(markers.getSize())]
    X = np.repeat(marker_positions(model, {}, labels), 20, axis=0)
    write_trc(d / "static.trc", np.arange(20) / 100.0, X, labels)
    lab_frame = np.stack([X[..., 0], -X[..., 2], X[..., 1]], axis=-1)  # model (Y up) -> lab (Z up)
    write_c3d(d / "static.c3d", [f"Anna:{lab}" for lab in labels], lab_frame, 100.0)
    return d


def test_scale_command_on_a_c3d_equals_the_step_on_the_trc(lab, tmp_path, capsys):
    out = tmp_path / "scaled.osim"
    code = main(
        [
            "scale",
            "--model",
            str(GAIT2392 / "gait2392_simbody.osim"),
            "--setup",
            str(GAIT2392 / "scale_setup.xml"),
            "--static",
            str(lab / "static.c3d"),
            "--mass-kg",
            "80",
            "--out",
            str(out),
        ]
    )
    assert code == 0, capsys.readouterr()
    files = ScaleFiles(
        GAIT2392 / "gait2392_simbody.osim", lab / "static.trc", tmp_path / "step.osim", GAIT2392 / "scale_setup.xml"
    )
    scale_with_setup(files, 80.0)
    ours = segments_from_model(read_model(out), "l")
    step = segments_from_model(read_model(tmp_path / "step.osim"), "l")
    generic = segments_from_model(read_model(GAIT2392 / "gait2392_simbody.osim"), "l")
    np.testing.assert_allclose(ours.packed, step.packed, rtol=1e-6)  # the C3D stores float32 mm
    np.testing.assert_allclose(np.array(ours.length_m) / generic.length_m, (1.10, 0.95, 1.05), rtol=1e-5)


def test_segments_command_from_a_model(lab, tmp_path, capsys):
    out = tmp_path / "segments.tsv"
    assert main(["segments", "--model", str(GAIT2392 / "gait2392_simbody.osim"), "--out", str(out)]) == 0
    table = read_segments(out)
    np.testing.assert_allclose(table.mass_kg, (9.3014, 3.7075, 1.5666), rtol=1e-9)  # femur; tibia; talus+calcn+toes
    assert (
        subprocess.run(
            [
                "loper-analysis",
                "segments",
                "--model",
                str(GAIT2392 / "gait2392_simbody.osim"),
                "--side",
                "right",
                "--out",
                str(tmp_path / "r.tsv"),
            ],
            capture_output=True,
            check=False,
        ).returncode
        == 0
    )
    np.testing.assert_allclose(read_segments(tmp_path / "r.tsv").mass_kg, table.mass_kg, rtol=1e-12)


def test_a_file_without_platforms_or_channels(tmp_path, capsys):
    path = tmp_path / "plain.c3d"
    write_c3d(path, ["LHEE", "RHEE"], np.ones((50, 2, 3)), 100.0)
    assert main(["grf", str(path), "--out", str(tmp_path / "g.mot")]) == 2
    _one_line_error(capsys, "plain.c3d", "FORCE_PLATFORM")
    assert main(["events", str(path), "--out", str(tmp_path / "e.tsv")]) == 2  # the config's belt channels
    _one_line_error(capsys, "plain.c3d", "no analog channel 'Fz_left' (events.grf_channels.left)", "no force platforms")
    assert not any(tmp_path.glob("[ge].*"))


def test_a_label_map_naming_a_marker_the_file_lacks(tmp_path, capsys):
    (tmp_path / "map.tsv").write_text("label\tmarker\nL_FCC\tLHEE\nNOPE\tRHEE\n")
    path = tmp_path / "trial.c3d"
    write_c3d(path, ["Anna:L_FCC", "Anna:R_FCC"], np.ones((50, 2, 3)), 100.0)
    out = tmp_path / "t.trc"
    assert main(["markers", str(path), "--out", str(out), "--label-map", str(tmp_path / "map.tsv")]) == 2
    _one_line_error(capsys, "trial.c3d", "NOPE")
    assert not out.exists()


def test_a_setup_that_is_not_a_scale_setup(lab, tmp_path, capsys):
    shutil.copy(GAIT2392 / "gait2392_Scale_MarkerSet.xml", tmp_path / "setup.xml")
    out = tmp_path / "scaled.osim"
    assert (
        main(
            [
                "scale",
                "--model",
                str(GAIT2392 / "gait2392_simbody.osim"),
                "--setup",
                str(tmp_path / "setup.xml"),
                "--static",
                str(lab / "static.trc"),
                "--mass-kg",
                "80",
                "--out",
                str(out),
            ]
        )
        == 2
    )
    _one_line_error(capsys, "setup.xml")
    assert not out.exists()


def test_a_model_without_the_bodies_and_a_file_that_is_no_model(tmp_path, capsys):
    from loper_analysis.io.osim import write_model
    from loper_analysis.motion.model import build_lower_body_model

    model = build_lower_body_model(1.7, 70.0)
    model.setName("renamed")
    text = write_model(model, tmp_path / "m.osim").read_text().replace("thigh_l", "upperleg_l")
    (tmp_path / "m.osim").write_text(text)
    out = tmp_path / "s.tsv"
    assert main(["segments", "--model", str(tmp_path / "m.osim"), "--out", str(out)]) == 2
    _one_line_error(capsys, "m.osim", "model.segment_bodies")
    (tmp_path / "not.osim").write_text("this is no model\n")
    assert main(["segments", "--model", str(tmp_path / "not.osim"), "--out", str(out)]) == 2
    _one_line_error(capsys, "not.osim")
    assert not out.exists()


def test_ik_command_reads_a_labs_labels(tmp_path, capsys):
    """Prefixed lab labels with a label map give the same .mot as the model's own names."""
    from loper_analysis.io.osim import write_model
    from loper_analysis.motion.model import MARKERS, build_lower_body_model

    generic = build_lower_body_model(1.73, 64.9)
    model = write_model(generic, tmp_path / "model.osim")
    t = np.arange(32) / 128.0
    X = marker_positions(
        generic,
        {"pelvis_ty": 0.93 + 0 * t, "hip_flexion_l": 0.3 * np.sin(4 * t), "knee_flexion_l": 0.5 + 0.3 * np.sin(4 * t)},
    )
    lab = np.stack([X[..., 0], -X[..., 2], X[..., 1]], axis=-1)  # model (Y up) -> lab (Z up)
    write_c3d(tmp_path / "own.c3d", list(MARKERS), lab, 128.0)
    lab_labels = [f"Anna:{'L_FCC' if m == 'LHEE' else m}" for m in MARKERS]
    write_c3d(tmp_path / "lab.c3d", lab_labels, lab, 128.0)
    (tmp_path / "map.tsv").write_text("label\tmarker\nL_FCC\tLHEE\n")
    assert (
        main(["ik", "--model", str(model), "--markers", str(tmp_path / "own.c3d"), "--out", str(tmp_path / "own.mot")])
        == 0
    )
    assert (
        main(
            [
                "ik",
                "--model",
                str(model),
                "--markers",
                str(tmp_path / "lab.c3d"),
                "--out",
                str(tmp_path / "lab.mot"),
                "--label-map",
                str(tmp_path / "map.tsv"),
            ]
        )
        == 0
    ), capsys.readouterr().err
    own, ours = read_mot(tmp_path / "own.mot"), read_mot(tmp_path / "lab.mot")
    pd.testing.assert_frame_equal(own, ours)
    np.testing.assert_allclose(
        ours["knee_flexion_l"], 0.5 + 0.3 * np.sin(4 * t), atol=1e-4
    )  # rad; float32 mm in the file
