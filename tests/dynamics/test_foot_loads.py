"""Each foot's load from the plates and the contacts: against OpenSim's InverseDynamicsTool on a recorded lab's
plates, a load split over two plates, the valid times of known contact sequences."""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest

from loper_analysis.dynamics.foot_loads import (
    combine_plate_loads,
    counted_contacts,
    foot_loads,
    valid_intervals,
    valid_mask,
)
from loper_analysis.dynamics.inverse_dynamics import FootLoad, generalized_forces
from loper_analysis.errors import LoperInputError
from loper_analysis.io.opensim_tables import read_mot
from loper_analysis.io.osim import read_model
from loper_analysis.io.readers import read_tsv
from loper_analysis.motion.markers import lab_up
from loper_analysis.stages.grf.step import grf
from loper_analysis.stages.settings import stage_settings
from tests.opensim_inverse_dynamics import opensim_inverse_dynamics
from tests.stages.dynamics.test_step import LABS, ROOT, recorded_trial

CUTOFF_HZ = 6.0
SAGITTAL = {"hip": "hip_flexion", "knee": "knee_angle", "ankle": "ankle_angle"}
SUFFIX = {"left": "l", "right": "r"}
GAIT2392 = ROOT / "src/loper_analysis/templates/gait2392_simbody.osim"


# ---------------------------------------------------------------- against OpenSim's tool on RCH's five plates


@pytest.fixture(scope="module")
def rch(tmp_path_factory):
    """RCH's walk through the workflow's rules; the ground reactions written again by the grf step with an
    ExternalLoads file giving each plate to the foot of its ok contact; OpenSim's tool and ours on them."""
    trial = recorded_trial(tmp_path_factory.mktemp("foot_loads"))
    files, out = trial["files"], trial["work"] / "opensim"
    out.mkdir()
    contacts = read_tsv(files["contacts"])
    ok = contacts[contacts["flag"] == "ok"]
    assert ok.groupby("plate")["side"].nunique().max() == 1  # every ok contact's plate touched by one foot
    bodies = {int(p): f"calcn_{SUFFIX[s]}" for p, s in zip(ok["plate"], ok["side"], strict=True)}
    # the grf rule's trial_grf, with the ExternalLoads file: the trial's rotation from its markers summary
    settings = stage_settings(trial["config"], "grf")
    rotation = tuple(float(read_tsv(files["markers_summary"])[f"rotation_{a}_deg"].iloc[0]) for a in "xyz")
    up = lab_up(settings.rotation_deg)
    table = grf(
        LABS / "RCH/walk-nodevice.c3d",
        out / "walk.grf.mot",
        dataclasses.replace(settings, rotation_deg=rotation),
        xml_out=out / "walk.loads.xml",
        bodies=bodies,
        up=up,
    )
    ground = read_mot(out / "walk.grf.mot")
    pd.testing.assert_frame_equal(ground, read_mot(files["grf"]))  # the workflow's ground reactions
    ik = read_mot(files["ik"])
    ik = ik[(ik["time_s"] >= table["time_s"].iloc[0]) & (ik["time_s"] <= table["time_s"].iloc[-1])]
    t = ik["time_s"].to_numpy()
    reference = opensim_inverse_dynamics(files["model"], files["ik"], out / "walk.loads.xml", out, t, CUTOFF_HZ)
    loads = foot_loads(ground, contacts)
    model = read_model(files["model"])
    ours = generalized_forces(model, t, ik.drop(columns="time_s"), list(loads.values()), cutoff_hz=CUTOFF_HZ)
    return ours, reference, contacts


@pytest.mark.slow  # the workflow's rules on RCH, then OpenSim's tool and ours (about 20 s)
@pytest.mark.parametrize("side", ["left", "right"])
@pytest.mark.parametrize("joint", ["hip", "knee", "ankle"])
def test_per_foot_loads_give_opensims_moments_in_the_valid_times(rch, side, joint):
    ours, reference, contacts = rch
    assert len(ours) == len(reference)
    np.testing.assert_allclose(ours["time_s"], reference["time_s"], atol=1e-9)
    valid = valid_mask(ours["time_s"].to_numpy(), valid_intervals(contacts, side))
    assert valid.sum() > 150  # RCH: 297 frames of the left leg, 190 of the right
    coordinate = f"{SAGITTAL[joint]}_{SUFFIX[side]}"
    a = ours[f"{coordinate}_moment_nm"].to_numpy()[valid]
    b = reference[f"{coordinate}_moment"].to_numpy()[valid]
    tolerance = max(0.01 * np.abs(b).max(), 1.0)
    assert np.abs(b).max() > 20.0  # a walking moment, N·m
    np.testing.assert_allclose(a, b, rtol=0, atol=tolerance)
    assert np.abs(a - b).max() < 1e-6  # measured: 1e-8 N·m, the rounding of the tool's .sto


# ---------------------------------------------------------------- a load split over two plates


def _one_load(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Time (n,) and a walking-like force (N), centre of pressure (m) and free torque (N·m), (n, 3), Y up."""
    t = np.linspace(0.0, 0.6, n)
    s = np.sin(np.pi * t / 0.6)
    force = np.column_stack([80 * np.sin(2 * np.pi * t / 0.6), 700 * s + 50 * s**3, 20 * s * np.cos(3 * t)])
    point = np.column_stack([0.1 + 0.25 * t / 0.6, np.full(n, 0.002), 0.09 + 0.01 * t])
    torque = np.column_stack([np.zeros(n), 4 * np.sin(5 * t), np.zeros(n)])
    return t, force, point, torque


def _split(force, point, torque, fraction, point_a):
    """Two plates' loads whose sum is the load (force, point, torque): plate A takes ``fraction`` of the force at
    ``point_a``, plate B the rest at the point that keeps the vertical-force weighted COP at ``point``, each
    plate's free torque the share that keeps the moment."""
    fa, fb = fraction[:, None] * force, (1 - fraction)[:, None] * force
    point_b = (point - fraction[:, None] * point_a) / (1 - fraction)[:, None]
    ta = fraction[:, None] * torque + np.cross(point - point_a, fa)
    tb = (1 - fraction)[:, None] * torque + np.cross(point - point_b, fb)
    return (fa, point_a, ta), (fb, point_b, tb)


def _grf_table(t, plates) -> pd.DataFrame:
    """A ground-reaction table (the grf .mot's columns) of the given plates' (force, point, torque)."""
    out = {"time_s": t}
    for n, (f, p, tq) in enumerate(plates, start=1):
        for kind, values in (("force_v", f), ("force_p", p), ("torque_", tq)):
            for j, axis in enumerate("xyz"):
                out[f"{n}_ground_{kind}{axis}"] = values[:, j]
    return pd.DataFrame(out)


@pytest.mark.parametrize("fraction_kind", ["constant", "rolling", "nearly_all_on_b"])
def test_a_load_split_over_two_plates_is_the_single_plate_load(fraction_kind):
    t, force, point, torque = _one_load(61)
    fraction = {
        "constant": np.full(t.size, 0.3),
        "rolling": 0.05 + 0.9 * t / t[-1],  # the foot rolls from plate B onto plate A
        "nearly_all_on_b": np.full(t.size, 1e-3),
    }[fraction_kind]
    point_a = point + np.array([0.12, 0.0, -0.03])
    a, b = _split(force, point, torque, fraction, point_a)
    f, p, tq = combine_plate_loads(np.array([a[0], b[0]]), np.array([a[1], b[1]]), np.array([a[2], b[2]]))
    np.testing.assert_allclose(f, force, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(p[1:-1], point[1:-1], rtol=0, atol=1e-12)  # the end samples bear no force
    np.testing.assert_allclose(tq, torque, rtol=0, atol=1e-9)
    # through foot_loads: one foot on both plates (one foot contact), and the same load on one plate
    contacts = pd.DataFrame(
        {"plate": [1, 2], "side": ["right", "right"], "flag": ["ok", "ok"], "start_s": [0.0, 0.0], "end_s": [0.6, 0.6]}
    )
    split = foot_loads(_grf_table(t, [a, b]), contacts.assign(foot_contact=[0, 0]), {"right": "calcn_r"})["right"]
    single = FootLoad("calcn_r", t, force, point, torque)
    # the moments of gait2392 in stance under each (knee flexed, ankle moving): the same to 1e-9 relative
    model = read_model(GAIT2392)
    frames = t[5:-5]
    coords = pd.DataFrame(
        {
            "pelvis_ty": np.full(frames.size, 0.95),
            "hip_flexion_r": 0.3 - 0.6 * frames,
            "knee_angle_r": -0.2 - 0.1 * np.sin(6 * frames),
            "ankle_angle_r": -0.1 + 0.3 * frames,
        }
    )
    ours = generalized_forces(model, frames, coords, [split], cutoff_hz=None)
    reference = generalized_forces(model, frames, coords, [single], cutoff_hz=None)
    for c in ("hip_flexion_r", "knee_angle_r", "ankle_angle_r"):
        r = reference[f"{c}_moment_nm"].to_numpy()
        assert np.abs(r).max() > 20.0
        np.testing.assert_allclose(ours[f"{c}_moment_nm"], r, rtol=0, atol=1e-9 * np.abs(r).max())


def test_a_foot_load_is_its_plates_over_its_ok_contacts_only():
    t, force, point, torque = _one_load(61)
    tt = np.linspace(0.0, 1.8, 181)
    f, p, tq = (np.zeros((tt.size, 3)) for _ in range(3))
    p[:] = point[0]
    for k0 in (0, 120):  # two loaded runs on plate 1: the left foot's (ok), then a flagged one
        f[k0 : k0 + 61], p[k0 : k0 + 61], tq[k0 : k0 + 61] = force, point, torque
        f[k0], f[k0 + 60] = 0.0, 0.0
    contacts = pd.DataFrame(
        {
            "plate": [1, 1],
            "side": ["left", "left"],
            "flag": ["ok", "two_feet"],
            "start_s": [0.01, 1.21],
            "end_s": [0.59, 1.79],
        }
    )
    loads = foot_loads(_grf_table(tt, [(f, p, tq)]), contacts)
    left, right = loads["left"], loads["right"]
    assert (left.body, right.body) == ("calcn_l", "calcn_r")
    np.testing.assert_array_equal(left.force_n[:61], f[:61])  # the ok contact's whole loaded run
    assert not left.force_n[61:].any() and not left.torque_nm[61:].any()  # nothing of the flagged contact
    np.testing.assert_array_equal(left.point_m[61:], np.repeat(left.point_m[59:60], tt.size - 61, axis=0))
    assert not right.force_n.any()
    with pytest.raises(LoperInputError, match="plate 3"):
        foot_loads(_grf_table(tt, [(f, p, tq)]), contacts.assign(plate=[3, 1]))


# ---------------------------------------------------------------- valid times


def _contacts(rows) -> pd.DataFrame:
    """A contact table of (plate, side, flag, start_s, end_s[, foot_contact]) rows."""
    columns = ["plate", "side", "flag", "start_s", "end_s", "foot_contact"]
    return pd.DataFrame([r if len(r) == 6 else (*r, i) for i, r in enumerate(rows)], columns=columns)


def test_valid_times_of_walking_over_plates():
    # L R L R on four plates, then the left foot's next contact flagged (two feet on plate 5)
    contacts = _contacts(
        [
            (1, "left", "ok", 0.0, 0.6),
            (2, "right", "ok", 0.5, 1.1),
            (3, "left", "ok", 1.0, 1.6),
            (4, "right", "ok", 1.5, 2.1),
            (5, "left", "two_feet", 2.0, 2.6),
        ]
    )
    # left: stance, swing 0.6 .. 1.0 (next heel strike 1.0 before the right's toe-off 1.1), stance; its swing
    # from 1.6 ends at a flagged contact: the landing's load is not known, so not valid
    np.testing.assert_array_equal(valid_intervals(contacts, "left"), [[0.0, 1.6]])
    # right: stance, swing 1.1 .. 1.5, stance; after 2.1 no heel strike is known
    np.testing.assert_array_equal(valid_intervals(contacts, "right"), [[0.5, 2.1]])
    mask = valid_mask(np.array([-0.1, 0.0, 0.8, 1.6, 1.7]), valid_intervals(contacts, "left"))
    np.testing.assert_array_equal(mask, [False, True, True, True, False])


def test_a_landing_off_the_plates_ends_the_valid_swing():
    # the left foot lands off the plates near 1.0 and again near 2.0 (the right's toe-offs at 1.1 and 2.1
    # show it), then on plate 3 at 3.0
    contacts = _contacts(
        [
            (1, "left", "ok", 0.0, 0.6),
            (2, "right", "ok", 0.5, 1.1),
            (4, "right", "ok", 1.5, 2.1),
            (3, "left", "ok", 3.0, 3.6),
        ]
    )
    np.testing.assert_array_equal(valid_intervals(contacts, "left"), [[0.0, 0.6], [3.0, 3.6]])
    # the right's swing 1.1 .. 1.5 holds no left event: valid
    np.testing.assert_array_equal(valid_intervals(contacts, "right"), [[0.5, 2.1]])


def test_a_foot_across_two_plates_counts_only_when_both_are_ok():
    both_ok = _contacts(
        [
            (1, "left", "ok", 0.0, 0.6, 0),
            (2, "right", "ok", 0.5, 1.1, 1),
            (3, "left", "ok", 1.0, 1.5, 2),
            (4, "left", "ok", 1.1, 1.6, 2),  # the same foot on plates 3 and 4
        ]
    )
    np.testing.assert_array_equal(valid_intervals(both_ok, "left"), [[0.0, 1.6]])
    one_flagged = both_ok.assign(flag=["ok", "ok", "ok", "off_plate"])
    assert list(counted_contacts(one_flagged, "left")["plate"]) == [1]
    np.testing.assert_array_equal(valid_intervals(one_flagged, "left"), [[0.0, 0.6]])
    # a contact of no known foot (loaded at the start of the recording) before the heel strike: the left foot
    # may have landed there
    unknown = _contacts([(1, "left", "ok", 0.0, 0.6), (5, "", "incomplete", 0.9, 1.2), (3, "left", "ok", 1.0, 1.6)])
    np.testing.assert_array_equal(valid_intervals(unknown, "left"), [[0.0, 0.6], [1.0, 1.6]])
    assert valid_intervals(_contacts([(1, "right", "edge", 0.0, 0.6)]), "right").shape == (0, 2)
    assert valid_intervals(_contacts([]), "right").shape == (0, 2) and counted_contacts(_contacts([]), "left").empty
