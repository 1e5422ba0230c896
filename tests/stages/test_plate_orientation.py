"""Force plates whatever the order of their corners and the lab's up axis: the grf and events steps on files
written both ways, against the known load and against each other.

One physical set-up, written as three C3D files (``write_c3d`` with its ``ForcePlatform``):

* ``z-up``: a Z-up lab (Qualisys, Vicon), corners in the usual order (plate z axis down);
* ``z-up reversed``: the same lab, corners listed the other way round the plate (plate z axis up), the
  channels in the frame those corners define; ``ORIGIN`` written with either sign (ezc3d normalises it);
* ``y-up reversed``: a Y-up lab (BTS): every lab coordinate ``(x, y, z)`` becomes ``(x, z, -y)`` (the
  rotation ``(-90, 0, 0)``), corners the other way round.

The sensor origin of every plate lies 40 mm below the centre of its surface (and a few mm beside it), so
that a moment moved to the wrong side of the surface shows in the centre of pressure (80 mm x Fh / Fz).
Channels are the physics of a known load: force ``F`` on the body at the point ``P`` with a free moment
``T`` about the lab's up, on top of an unzeroed resting reading.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.grf import external_loads_columns, plate_vertical_loads
from loper_analysis.gait.grf_settings import GRFSettings
from loper_analysis.io.c3d_writer import ForcePlatform, write_c3d
from loper_analysis.io.force_platforms import read_force_platforms
from loper_analysis.motion.markers import lab_up
from loper_analysis.stages.events.step import EventSettings, events
from loper_analysis.stages.grf.step import grf
from tests.force_plate_channels import plate_frame, wrench_channels

RATE, RATIO = 100.0, 10
DURATION_S = 2.4
#: Z-up lab -> Y-up lab, (x, y, z) -> (x, z, -y): what rotate_markers does with (-90, 0, 0).
Q = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
Z_UP_ROTATION = (-90.0, 0.0, 0.0)
#: Plate centres (m, Z-up lab, surface at z = 0) and half sizes; plate 1 takes the left foot, plate 2 the right.
CENTRES = (np.array([0.3, 0.25, 0.0]), np.array([0.3, 0.75, 0.0]))
HALF = np.array([0.25, 0.2, 0.0])
#: Sensor origin -> surface centre (m, Z-up lab): the sensor lies 40 mm below the surface, a little aside.
CENTRE_FROM_SENSOR = np.array([-0.002, 0.003, 0.04])
REST_FORCE_N = np.array([1.5, -2.0, -30.0])  # an unloaded plate is not zeroed
REST_MOMENT_NM = np.array([0.4, -0.3, 0.1])
PEAK_N = 700.0
#: Contact (start, end) s of each plate, and the analytic load on it.
CONTACTS = ((0.5, 1.2), (1.0, 1.7))
ON_N, OFF_N = 50.0, 20.0


def _corners(centre: np.ndarray, reversed_order: bool) -> np.ndarray:
    """Corners (4, 3) m in C3D order (plate x = lab x, y = lab -y, z down), or listed the other way round."""
    quadrants = np.array([[1, 1, 0], [-1, 1, 0], [-1, -1, 0], [1, -1, 0]], dtype=float)
    corners = centre + (quadrants * HALF) @ np.diag([1.0, -1.0, -1.0]).T
    return corners[::-1] if reversed_order else corners


def _platform(corners: np.ndarray, channels: tuple, origin_sign: float = 1.0) -> ForcePlatform:
    """TYPE-2 plate with ``ORIGIN`` = +-(sensor origin -> surface centre) in the frame its corners define."""
    frame, _ = plate_frame(ForcePlatform(2, corners, (0.0, 0.0, 0.0), channels))
    return ForcePlatform(2, corners, tuple(origin_sign * (frame.T @ CENTRE_FROM_SENSOR)), channels)


def _load(k: int, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Force on the body (n, 3) N, its point (n, 3) m and free moment (n,) N·m about +z, plate k (Z-up lab)."""
    a, b = CONTACTS[k]
    s = np.clip((t - a) / (b - a), 0.0, 1.0)
    shape = np.where((t > a) & (t < b), np.sin(np.pi * s), 0.0)
    force = np.column_stack([60.0 * shape * np.cos(np.pi * s), -30.0 * shape, PEAK_N * shape])
    point = CENTRES[k] + np.column_stack([0.1 - 0.2 * s, 0.05 * np.ones_like(s), np.zeros_like(s)])
    return force, point, 3.0 * shape


def _analogs(plates: list[ForcePlatform], t: np.ndarray) -> np.ndarray:
    """Channels (n, 12) of the two plates: the known load on top of the resting reading."""
    columns = []
    for k, plate in enumerate(plates):
        physical = _platform(np.asarray(plate.corners_m), plate.channels)  # ORIGIN as the physics has it
        force, point, free = _load(k, t)
        centre = np.mean(plate.corners_m, axis=0)
        up = np.array([0.0, 0.0, 1.0])
        moment = np.cross(point - centre, force) + free[:, None] * up
        columns.append(wrench_channels(physical, force + REST_FORCE_N, moment + REST_MOMENT_NM))
    return np.hstack(columns)


def _heels(tm: np.ndarray) -> np.ndarray:
    """Heel markers (n, 2, 3) m, left then right: on their plate (5 cm up) around its contact, 40 cm up otherwise."""
    heels = np.empty((tm.size, 2, 3))
    for k in range(2):
        a, b = CONTACTS[k]
        on = (tm >= a - 0.1) & (tm <= b + 0.1)
        heels[:, k] = CENTRES[k] + np.array([0.0, -0.1, 0.05])
        heels[~on, k, 2] = 0.4
    return heels


def write_trial(path, reversed_order: bool = False, y_up: bool = False, origin_sign: float = 1.0):
    """The trial as a C3D file: two TYPE-2 plates and the heel markers ``LHEE``, ``RHEE`` (module notes)."""
    n_frames = round(DURATION_S * RATE)
    tm = np.arange(n_frames) / RATE
    t = np.arange(n_frames * RATIO) / (RATE * RATIO)
    plates = [
        _platform(_corners(c, reversed_order), tuple(range(1 + 6 * k, 7 + 6 * k)), origin_sign)
        for k, c in enumerate(CENTRES)
    ]
    analogs = _analogs(plates, t)
    heels = _heels(tm)
    if y_up:  # the same plates and channels: only the lab's coordinates turn
        plates = [ForcePlatform(2, np.asarray(p.corners_m) @ Q.T, p.origin_m, p.channels) for p in plates]
        heels = heels @ Q.T
    labels = [f"{q}{k}" for k in (1, 2) for q in ("Fx", "Fy", "Fz", "Mx", "My", "Mz")]
    units = ["N", "N", "N", "Nmm", "Nmm", "Nmm"] * 2
    return write_c3d(path, ["LHEE", "RHEE"], heels, RATE, labels, analogs, units, RATE * RATIO, force_platforms=plates)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("plates")
    return {
        "z-up": write_trial(d / "zup.c3d"),
        "z-up reversed": write_trial(d / "zup_reversed.c3d", reversed_order=True),
        "z-up reversed, ORIGIN negated": write_trial(d / "zup_reversed_neg.c3d", reversed_order=True, origin_sign=-1.0),
        "y-up reversed": write_trial(d / "yup_reversed.c3d", reversed_order=True, y_up=True),
        "y-up": write_trial(d / "yup.c3d", y_up=True),
    }


def test_the_files_hold_what_the_module_notes_say(files):
    """The reversed plates' z axis points up (ezc3d's frame from the corners), the usual ones' down."""
    for name, path in files.items():
        up = lab_up((0.0, 0.0, 0.0) if name.startswith("y-up") else Z_UP_ROTATION)
        for p in read_force_platforms(path, up):
            x, y = p.corners_m[0] - p.corners_m[1], p.corners_m[0] - p.corners_m[3]
            assert np.sign(np.cross(x, y) @ up) == (1.0 if "reversed" in name else -1.0), name


@pytest.mark.parametrize("name", ["z-up reversed", "z-up reversed, ORIGIN negated"])
def test_reversed_corners_give_the_known_load_and_the_usual_reading(files, tmp_path, name):
    """Force, centre of pressure and free moment of the .mot (lab frame) are the known load, either corner order."""
    lab_frame = GRFSettings(rotation_deg=(0, 0, 0))
    usual = grf(files["z-up"], tmp_path / "usual.grf.mot", lab_frame)
    other = grf(files[name], tmp_path / "other.grf.mot", lab_frame)
    t = usual["time_s"].to_numpy()
    for k in range(2):
        cols = external_loads_columns(k + 1)
        np.testing.assert_allclose(other[cols].to_numpy(), usual[cols].to_numpy(), rtol=0, atol=1e-9)
        force, point, free = _load(k, t)
        loaded = force[:, 2] > 20.0
        got = other[cols].to_numpy()[loaded]
        np.testing.assert_allclose(got[:, 0:3], force[loaded], rtol=0, atol=2e-3)  # N (float32 channels)
        np.testing.assert_allclose(got[:, 3:6], point[loaded], rtol=0, atol=2e-5)  # m
        np.testing.assert_allclose(
            got[:, 6:9], np.column_stack([0 * free, 0 * free, free])[loaded], rtol=0, atol=2e-3
        )  # N·m, about +z
        np.testing.assert_array_equal(other[cols].to_numpy()[~loaded][:, [0, 1, 2, 6, 7, 8]], 0.0)
    vl_usual, vl_other = (
        plate_vertical_loads(read_force_platforms(files["z-up"]), (0, 0, 0)),
        plate_vertical_loads(read_force_platforms(files[name]), (0, 0, 0)),
    )
    np.testing.assert_allclose(vl_other.vertical_n, vl_usual.vertical_n, rtol=0, atol=1e-9)
    np.testing.assert_allclose(vl_other.rest_vertical_n, REST_FORCE_N[2], atol=1e-4)


def test_without_the_correction_ezc3d_puts_the_moment_below_the_sensor(files):
    """The reversed plate read as ezc3d reads it is 80 mm x Fh/Fz off: what read_force_platforms corrects."""
    import ezc3d

    raw = ezc3d.c3d(str(files["z-up reversed"]), extract_forceplat_data=True)["data"]["platform"][0]
    usual = read_force_platforms(files["z-up"])[0]
    i = int(np.argmax(usual.force_n[:, 2]))
    wrong = np.asarray(raw["moment"], float)[:, i] / 1000.0
    expected_error = -2.0 * np.cross(usual.force_n[i], CENTRE_FROM_SENSOR)  # moved 2 x 40 mm the wrong way
    np.testing.assert_allclose(wrong - usual.moment_nm[i], expected_error, atol=1e-4)
    np.testing.assert_allclose(
        read_force_platforms(files["z-up reversed"])[0].moment_nm[i], usual.moment_nm[i], atol=1e-9
    )


@pytest.mark.parametrize("name", ["y-up", "y-up reversed"])
def test_y_up_lab_without_rotation_gives_the_z_up_labs_mot(files, tmp_path, name):
    """A Y-up file with rotation (0, 0, 0) (up = lab_up of it = +Y) gives the .mot of the Z-up file with
    (-90, 0, 0): the same model-frame loads."""
    assert lab_up((0, 0, 0)).tolist() == [0.0, 1.0, 0.0] and lab_up(Z_UP_ROTATION).tolist() == [0.0, 0.0, 1.0]
    z_up = grf(files["z-up"], tmp_path / "z.grf.mot", GRFSettings(rotation_deg=Z_UP_ROTATION))
    y_up = grf(files[name], tmp_path / "y.grf.mot", GRFSettings(rotation_deg=(0, 0, 0)), up=lab_up((0, 0, 0)))
    assert list(y_up.columns) == list(z_up.columns)
    np.testing.assert_allclose(y_up.to_numpy(), z_up.to_numpy(), rtol=0, atol=1e-9)
    # and it is the known load, turned into the model frame: vertical along +Y, the free moment about +Y
    force, point, free = _load(0, z_up["time_s"].to_numpy())
    loaded = force[:, 2] > 20.0
    cols = external_loads_columns(1)
    np.testing.assert_allclose(y_up[cols[1]].to_numpy()[loaded], force[loaded, 2], atol=2e-3)
    np.testing.assert_allclose(y_up[cols[3:6]].to_numpy()[loaded], point[loaded] @ Q.T, atol=2e-5)
    np.testing.assert_allclose(y_up[cols[7]].to_numpy()[loaded], free[loaded], atol=2e-3)


def test_a_y_up_file_read_as_z_up_is_refused_naming_plate_up_and_setting(files, tmp_path):
    out = tmp_path / "refused.grf.mot"
    with pytest.raises(LoperInputError) as caught:
        grf(files["y-up reversed"], out, GRFSettings(rotation_deg=Z_UP_ROTATION))
    message = str(caught.value)
    assert message.startswith(f"{files['y-up reversed']} (force platform 1): the plate does not face up")
    assert "surface normal [0.0, 1.0, 0.0] is 90.0 deg from the up direction [0.0, 0.0, 1.0]" in message
    assert "markers.lab_to_model_rotation_deg" in message
    assert not out.exists()
    with pytest.raises(LoperInputError, match=r"yup\.c3d \(force platform 1\): the plate does not face up"):
        events(
            files["y-up"],
            tmp_path / "refused.events.tsv",
            EventSettings(foot_markers={"left": "LHEE", "right": "RHEE"}, rotation_deg=Z_UP_ROTATION),
        )


def _events(path, rotation_deg, tmp_path, name):
    table = events(
        path,
        tmp_path / f"{name}.events.tsv",
        EventSettings(
            foot_markers={"left": "LHEE", "right": "RHEE"},
            plate_sides={"left": 1, "right": 2},
            threshold_on_n=ON_N,
            threshold_off_n=OFF_N,
            rotation_deg=rotation_deg,
        ),
        contacts_out=tmp_path / f"{name}.contacts.tsv",
    )
    return table, pd.read_csv(tmp_path / f"{name}.contacts.tsv", sep="\t")


@pytest.mark.parametrize("name", ["z-up reversed", "y-up reversed", "y-up"])
def test_events_from_reversed_and_y_up_plates_equal_the_usual_ones(files, tmp_path, name):
    """Heel strikes and toe-offs on the analytic threshold crossings, the same from every file."""
    usual, usual_contacts = _events(files["z-up"], Z_UP_ROTATION, tmp_path, "usual")
    rotation = (0.0, 0.0, 0.0) if name.startswith("y-up") else Z_UP_ROTATION
    other, other_contacts = _events(files[name], rotation, tmp_path, "other")
    assert usual[["side", "event"]].values.tolist() == [
        ["left", "heel_strike"],
        ["right", "heel_strike"],
        ["left", "toe_off"],
        ["right", "toe_off"],
    ]
    pd.testing.assert_frame_equal(other, usual)
    assert other_contacts["flag"].tolist() == ["ok", "ok"] and other_contacts["side"].tolist() == ["left", "right"]
    heel = [c for c in other_contacts.columns if c.endswith("_m")]
    np.testing.assert_allclose(other_contacts[heel].to_numpy(float), usual_contacts[heel].to_numpy(float), atol=1e-9)
    # the load crosses 50 N on the way up and 20 N on the way down here (first analog sample at or past it)
    dt = 1.0 / (RATE * RATIO)
    for side, (a, b) in zip(("left", "right"), CONTACTS):
        on = a + (b - a) / math.pi * math.asin(ON_N / PEAK_N)
        off = b - (b - a) / math.pi * math.asin(OFF_N / PEAK_N)
        mine = other[other["side"] == side].set_index("event")["time_s"]
        assert 0.0 <= mine["heel_strike"] - on < dt + 1e-9 and 0.0 <= mine["toe_off"] - off < dt + 1e-9


def test_the_events_step_reads_its_c3d_once_and_gets_the_same_plates(files, tmp_path, monkeypatch):
    """One reading of the file gives the markers and the force platforms: ezc3d opens it once, and the platforms
    equal those read on their own."""
    from loper_analysis.io import c3d as c3d_module
    from loper_analysis.io import force_platforms as platforms_module

    alone = read_force_platforms(files["z-up"], lab_up(Z_UP_ROTATION))
    opened = []

    def counting(real):
        def open_file(path, *args, **kwargs):
            opened.append(str(path))
            return real(path, *args, **kwargs)

        return open_file

    # every opening of a C3D by the library goes through one of these two
    monkeypatch.setattr(c3d_module, "_open_c3d", counting(c3d_module._open_c3d))
    monkeypatch.setattr(platforms_module, "_open", counting(platforms_module._open))
    rec, plates = platforms_module.read_c3d_with_platforms(files["z-up"], lab_up(Z_UP_ROTATION))
    assert opened == [str(files["z-up"])] and rec.n_force_platforms == len(plates) == 2
    for a, b in zip(plates, alone):
        np.testing.assert_array_equal(a.force_n, b.force_n)
        np.testing.assert_array_equal(a.moment_nm, b.moment_nm)
    opened.clear()
    _events(files["z-up"], Z_UP_ROTATION, tmp_path, "once")
    assert opened == [str(files["z-up"])]
