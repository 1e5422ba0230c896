"""Bad input to the processing stages (C3D -> markers -> model -> IK) is refused with one message naming the
file, the quantity and its value, and nothing is written; good input passes unchanged.

Every file is built here: the generated model, TRCs of its markers moved through known angles, C3D files
written by our writer (in a child process) and damaged byte by byte.
"""

from __future__ import annotations

import shutil
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.c3d_writer import write_c3d
from loper_analysis.io.opensim_tables import read_mot, write_trc
from loper_analysis.io.osim import read_model, write_model
from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.ik_settings import IKSettings
from loper_analysis.motion.model import MARKERS, build_lower_body_model
from loper_analysis.stages.ik.step import ik_chunk, ik_file
from loper_analysis.stages.markers.step import markers as markers_step
from loper_analysis.stages.model.step import ModelSettings, ScaleFiles, scale, scale_with_setup
from tests.gait2392_models import scaled_gait2392

ROOT = Path(__file__).resolve().parents[2]
GAIT2392 = ROOT / "examples" / "gait2392"
FS = 128.0
N = 32


@pytest.fixture(scope="module")
def trial(tmp_path_factory):
    """Generated model (.osim), its markers through known angles (m, model frame) and the full TRC."""
    d = tmp_path_factory.mktemp("guards")
    model = build_lower_body_model(1.73, 64.9)
    t = np.arange(N) / FS
    w = 2 * np.pi * 0.6
    truth = {
        "pelvis_tx": 0.02 * np.sin(2 * w * t),
        "pelvis_ty": 0.93 + 0.01 * np.sin(2 * w * t),
        "pelvis_tilt": 0.05 * np.sin(w * t),
        "hip_flexion_l": 0.1 + 0.3 * np.sin(w * t),
        "knee_flexion_l": 0.6 + 0.5 * np.sin(w * t + 1),
        "ankle_dorsiflexion_l": 0.1 * np.sin(w * t + 2),
        "hip_flexion_r": -0.1 + 0.2 * np.sin(w * t),
        "knee_flexion_r": 0.3 + 0.1 * np.sin(w * t),
    }
    X = marker_positions(model, truth)
    osim_path = write_model(model, d / "model.osim")
    return {
        "dir": d,
        "model": osim_path,
        "t": t,
        "X": X,
        "truth": truth,
        "trc": write_trc(d / "all.trc", t, X, list(MARKERS)),
    }


def subset_trc(trial, path, names):
    idx = [MARKERS.index(n) for n in names]
    return write_trc(path, trial["t"], trial["X"][:, idx], list(names))


# ---------------------------------------------------------------- 1. a mislabelled point unit


def test_c3d_in_mm_declared_as_m_is_refused_by_the_markers_step(trial, tmp_path):
    lab_X = trial["X"] @ np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], float).T  # model Y-up -> lab Z-up
    good = write_c3d(tmp_path / "good.c3d", list(MARKERS), lab_X, FS, point_unit="mm")
    bad = write_c3d(tmp_path / "bad.c3d", list(MARKERS), 1000.0 * lab_X, FS, point_unit="m")  # mm numbers, "m"
    gaps = markers_step(good, tmp_path / "good.trc")
    assert (tmp_path / "good.trc").is_file() and len(gaps) == 0
    with pytest.raises(LoperInputError) as err:
        markers_step(bad, tmp_path / "bad.trc")
    msg = str(err.value)
    assert str(bad) in msg and "marker extent" in msg and "POINT:UNITS" in msg
    extent = float(msg.split(" is ")[1].split(" m,")[0])
    assert 1000 < extent < 2000  # the lower body spans 1.0 .. 2.0 m, read 1000 times too large
    assert not (tmp_path / "bad.trc").exists()


def test_scaling_the_generated_model_with_a_static_trial_in_the_wrong_unit_is_refused(trial, tmp_path):
    static = write_trc(tmp_path / "static.trc", trial["t"][:4], 1000.0 * trial["X"][:4], list(MARKERS))
    out = tmp_path / "scaled.osim"
    with pytest.raises(LoperInputError) as err:
        # the motion check off: the numbers 1000 times too large move 1000 times as far
        scale(ScaleFiles(trial["model"], static, out), 64.9, ModelSettings(max_motion_rms_m=None))
    msg = str(err.value)
    assert str(static) in msg and "scale factor" in msg and "0.5 .. 2" in msg
    thigh = float(msg.split("thigh_r ")[1].split(",")[0])
    assert thigh == pytest.approx(1000.0, rel=0.05)
    assert not out.exists()


def test_lab_setup_scaling_with_a_static_trial_in_the_wrong_unit_is_refused(tmp_path):
    shutil.copy(GAIT2392 / "scale_setup.xml", tmp_path / "scale_setup.xml")
    shutil.copy(GAIT2392 / "gait2392_Scale_MarkerSet.xml", tmp_path / "gait2392_Scale_MarkerSet.xml")
    model = scaled_gait2392({}, 75.1646, markers=True)
    ms = model.getMarkerSet()
    labels = [ms.get(i).getName() for i in range(ms.getSize())]
    X = np.repeat(marker_positions(model, {}, labels), 4, axis=0)
    static = write_trc(
        tmp_path / "static.trc", np.arange(4) / 100.0, 10.0 * X, labels
    )  # every number 10 times too large
    out = tmp_path / "scaled.osim"
    with pytest.raises(LoperInputError) as err:
        files = ScaleFiles(GAIT2392 / "gait2392_simbody.osim", static, out, setup_xml=tmp_path / "scale_setup.xml")
        scale_with_setup(files, 75.0)
    msg = str(err.value)
    assert str(static) in msg and "scale factor" in msg
    factors = [float(part.split()[-1]) for part in msg.split("model's): ")[1].split(";")[0].split(", ")]
    np.testing.assert_allclose(factors, 10.0, rtol=1e-6)  # every distance 10 times the model's
    assert not out.exists()


def test_ik_with_markers_1000_times_too_far_apart_fails_naming_the_rms_and_the_limit(trial, tmp_path):
    trc = write_trc(tmp_path / "huge.trc", trial["t"], 1000.0 * trial["X"], list(MARKERS))
    out = tmp_path / "huge.mot"
    with pytest.raises(LoperInputError) as err:  # the marker geometry says it first
        ik_chunk(trial["model"], trc, out, 0, 1)
    msg = str(err.value)
    assert str(trc) in msg and "ik.geometry_stop_change" in msg and "ratio 1000.000" in msg
    assert "1000 times the model's: markers in another length unit (the file's POINT:UNITS)" in msg
    assert not out.exists()
    with pytest.raises(LoperInputError) as err:  # and IK's marker error, without the geometry check
        ik_chunk(trial["model"], trc, out, 0, 1, IKSettings(geometry_stop_change=np.inf))
    msg = str(err.value)
    assert str(trc) in msg and "IK marker RMS error exceeds 60 mm" in msg and f"in {N} of {N} frames" in msg
    assert "ik.max_marker_rms_m" in msg
    mean_rms_mm = float(msg.split("mean RMS ")[1].split(" mm")[0])
    assert mean_rms_mm > 1e5  # hundreds of metres
    assert not out.exists()


def test_ik_on_a_model_without_markers_says_it_has_none_and_where_they_come_from(trial, tmp_path):
    """OpenSim's gait2392 as distributed keeps its markers in a file of its own."""
    generic = ROOT / "src/loper_analysis/templates/gait2392_simbody.osim"
    out = tmp_path / "x.mot"
    with pytest.raises(LoperInputError) as err:
        ik_file(generic, trial["trc"], out)
    msg = str(err.value)
    assert f"{generic} (model 3DGaitModel2392) has no markers (its MarkerSet is empty)" in msg
    assert "gait2392_Scale_MarkerSet.xml" in msg and "model.scale_setup" in msg and "--config-out" in msg
    assert not out.exists()


# ---------------------------------------------------------------- 2. ANALOG:RATE against the data layout


def test_analog_rate_half_of_the_recorded_one_is_refused(tmp_path):
    rng = np.random.default_rng(7)
    X = rng.normal(size=(10, 2, 3))
    analogs = np.arange(10 * 8 * 2, dtype=float).reshape(80, 2)
    path = write_c3d(tmp_path / "rates.c3d", ["A", "B"], X, FS, ["Fz1", "Fz2"], analogs, ["N", "N"], 1024.0)
    assert read_c3d(path).analogs.shape == (80, 2)
    data = bytearray(path.read_bytes())
    start = (data[0] - 1) * 512 + 512  # parameter section, after the header block
    hits = [i for i in range(512, start + 4096) if data[i : i + 4] == struct.pack("<f", 1024.0)]
    assert len(hits) == 1
    data[hits[0] : hits[0] + 4] = struct.pack("<f", 512.0)
    path.write_bytes(bytes(data))
    with pytest.raises(LoperInputError) as err:
        read_c3d(path)
    msg = str(err.value)
    assert str(path) in msg and "ANALOG:RATE = 512 Hz" in msg and "4 analog samples per frame" in msg
    assert "holds 8 per frame" in msg and "1024 Hz" in msg


# ---------------------------------------------------------------- 3. a partial marker set


def test_coordinates_no_marker_determines_are_nan_never_zero(trial, tmp_path):
    six = ["RASI", "LASI", "RPSI", "LPSI", "RGTR", "LGTR"]
    trc = subset_trc(trial, tmp_path / "six.trc", six)
    res = ik_file(trial["model"], trc, tmp_path / "six.mot")
    nan = sorted(c for c, n in res.undetermined.items() if n == N)
    assert nan == sorted(["knee_flexion_r", "ankle_dorsiflexion_r", "knee_flexion_l", "ankle_dorsiflexion_l"])
    mot = read_mot(tmp_path / "six.mot")
    assert mot[nan].isna().all().all()
    # the pelvis and the hips are determined: their known values come back
    np.testing.assert_allclose(mot["hip_flexion_l"], trial["truth"]["hip_flexion_l"], atol=5e-3)  # GTR: 2 cm lever
    np.testing.assert_allclose(mot["pelvis_ty"], trial["truth"]["pelvis_ty"], atol=1e-4)


def test_thirty_markers_leave_only_the_left_foot_undetermined(trial, tmp_path):
    trc = subset_trc(trial, tmp_path / "thirty.trc", MARKERS[:30])  # left: no LANM, LHEE, LMT1, LMT5, braces
    res = ik_file(trial["model"], trc, tmp_path / "thirty.mot")
    assert res.undetermined == {"ankle_dorsiflexion_l": N}  # LANK sits on the shank: no left foot marker remains
    frame = read_mot(tmp_path / "thirty.mot")
    assert frame["ankle_dorsiflexion_l"].isna().all()
    np.testing.assert_allclose(frame["knee_flexion_l"], trial["truth"]["knee_flexion_l"], atol=1e-3)
    np.testing.assert_allclose(frame["ankle_dorsiflexion_r"], 0.0, atol=1e-3)  # the right foot is there: truth 0


def test_full_marker_set_output_is_unchanged(trial, tmp_path):
    res = ik_file(trial["model"], trial["trc"], tmp_path / "all.mot", IKSettings(tree_step_tolerance=1e-8))
    assert res.undetermined == {} and np.isfinite(res.coordinates).all()
    np.testing.assert_allclose(res.frame()["knee_flexion_l"], trial["truth"]["knee_flexion_l"], atol=1e-4)


# ---------------------------------------------------------------- 4. crashes of OpenSim's solver


def run_cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "loper_analysis.cli", *map(str, args)], capture_output=True, text=True, timeout=300
    )


def test_pelvis_only_markers_exit_2_with_one_line_instead_of_a_segfault(trial, tmp_path):
    trc = subset_trc(trial, tmp_path / "pelvis3.trc", ["RASI", "LASI", "RPSI"])
    out = tmp_path / "pelvis3.mot"
    proc = run_cli("ik", "--model", trial["model"], "--markers", trc, "--out", out)
    assert proc.returncode == 2, proc.stderr[-2000:]
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and str(trc) in lines[0] and "RASI, LASI, RPSI" in lines[0] and "pelvis" in lines[0]
    assert not out.exists()


def test_one_marker_is_refused_before_solving(trial, tmp_path):
    trc = subset_trc(trial, tmp_path / "one.trc", ["RASI"])
    with pytest.raises(LoperInputError, match=rf"one\.trc.*{N} frame\(s\) hold fewer than 3"):
        ik_file(trial["model"], trc, tmp_path / "one.mot")
    assert not (tmp_path / "one.mot").exists()


@pytest.mark.parametrize(
    "name, content, field",
    [
        ("model.txt", b"pelvis 1.0\n", "not an XML file"),
        ("binary.osim", bytes(range(256)) * 8, "not an XML file"),
        ("setup.osim", b'<?xml version="1.0"?><OpenSimDocument><ScaleTool/></OpenSimDocument>', "holds no <Model>"),
    ],
)
def test_a_model_file_that_is_no_osim_model_is_refused(trial, tmp_path, name, content, field):
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(LoperInputError) as err:
        read_model(path)
    assert str(path) in str(err.value) and field in str(err.value)
    with pytest.raises(LoperInputError, match="not an OpenSim model"):
        ik_file(path, trial["trc"], tmp_path / "x.mot")
    assert not (tmp_path / "x.mot").exists()
