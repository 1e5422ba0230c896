"""loper_analysis.device.loadcell: the robot log's forces and perturbation flag on the mocap frames, against
known clocks."""

import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.device.loadcell import (
    OUTPUT_COLUMNS,
    SHANK_OUTPUT_COLUMNS,
    SYNC_CHANNEL,
    LoadcellSettings,
    perturbation_onsets,
    robot_log_frames_and_native,
)
from loper_analysis.errors import LoperInputError
from loper_analysis.stages.settings import stage_settings
from loper_analysis.synthetic.sync import pulse_train_at, sync_pulse_starts
from tests.sync_records import ANALOG_HZ, ROBOT_HZ, mocap_view

CONFIG = yaml.safe_load((Path(__file__).resolve().parents[2] / "config" / "config.yaml").read_text())

FRAME_HZ = 128.0
FORCE_COMPONENTS = ((8.0, 0.7, 0.3), (5.0, 2.3, 1.1), (3.0, 6.1, 2.0))  # (N, Hz, rad), all < 10 Hz


def robot_log_on_mocap_frames(*records, **options) -> pd.DataFrame:
    """The frame table of :func:`robot_log_frames_and_native` (its forces on the mocap frames)."""
    return robot_log_frames_and_native(*records, **options)[0]


def force(t):
    return sum(a * np.sin(2 * np.pi * f * t + p) for a, f, p in FORCE_COMPONENTS)


def make_trial(offset_s, ppm, robot_t0_s, seed, robot_duration_s=60.0, mocap_duration_s=70.0):
    n = int(robot_duration_s * ROBOT_HZ)
    t = robot_t0_s + np.arange(n) / ROBOT_HZ
    flag = np.zeros(n, dtype=np.int64)
    onsets = []
    for t_on in (robot_t0_s + 10.0123, robot_t0_s + 23.4567, robot_t0_s + 41.0009):
        k = int(np.ceil((t_on - robot_t0_s) * ROBOT_HZ))
        flag[k : k + 100] = 1  # 100 ms pulse
        onsets.append(t[k])
    log = pd.DataFrame(
        {
            "time_s": t,
            "force_desired_n": 2.0 * np.sin(2 * np.pi * 100.0 * t),  # to be filtered away
            "force_measured_n": force(t),
            "motor_angle_rad": 0.0,
            "motor_velocity_rad_s": 0.0,
            "sync_v": pulse_train_at(
                np.arange(int(round(robot_duration_s * ROBOT_HZ))) / ROBOT_HZ, sync_pulse_starts(robot_duration_s, seed)
            ),
            "perturbation": flag,
            "safety_state": 0,
        }
    )
    starts = sync_pulse_starts(robot_duration_s, seed)
    sync = mocap_view(starts, offset_s, ppm, robot_t0_s, robot_duration_s, mocap_duration_s)
    frames = np.arange(int(mocap_duration_s * FRAME_HZ)) / FRAME_HZ
    return log, sync, frames, np.array(onsets)


@pytest.mark.parametrize("offset_s, ppm, robot_t0_s", [(3.217, 150.0, 0.0), (-1.5, -80.0, 5.0)])
def test_robot_log_on_mocap_frames_known_signals(offset_s, ppm, robot_t0_s):
    scale = 1 + ppm * 1e-6
    log, sync, frames, onsets_robot = make_trial(offset_s, ppm, robot_t0_s, seed=21)
    out = robot_log_on_mocap_frames(log, ROBOT_HZ, sync, ANALOG_HZ, frames, source="S01/walk")
    assert tuple(out.columns) == OUTPUT_COLUMNS
    np.testing.assert_array_equal(out["time_s"], frames)
    cm = out.attrs["clock_map"]
    assert abs(cm.offset_s - offset_s) < 0.2e-3 and abs(cm.scale - scale) < 10e-6

    # NaN exactly outside the log's span on the mocap clock
    t_first = offset_s + scale * robot_t0_s
    t_last = offset_s + scale * (robot_t0_s + (len(log) - 1) / ROBOT_HZ)
    inside = (frames >= t_first) & (frames <= t_last)
    for col in OUTPUT_COLUMNS[1:]:
        np.testing.assert_array_equal(out[col].notna().to_numpy(), inside)

    # forces: the analytic signal at the mapped times; tolerance = 0.2 ms clock error times the
    # largest slope, plus linear-interpolation and filter-pass-band error (< 0.01 N)
    robot_time = (frames[inside] - offset_s) / scale
    slope = sum(a * 2 * np.pi * f for a, f, _ in FORCE_COMPONENTS)
    tol = slope * 0.2e-3 + 0.01
    np.testing.assert_allclose(out["force_measured_n"][inside], force(robot_time), atol=tol)

    # the 100 Hz component (2 N) is attenuated to < 1 %, away from the filter's start-up transients
    interior = inside & (frames > t_first + 0.25) & (frames < t_last - 0.25)
    assert np.max(np.abs(out["force_desired_n"][interior])) < 0.02

    # flag stays 0/1 and each 100 ms onset lands within one frame of its mapped time
    assert set(np.unique(out["perturbation"][inside])) == {0.0, 1.0}
    onsets = perturbation_onsets(out["time_s"], out["perturbation"])
    expected = offset_s + scale * onsets_robot
    assert onsets.size == 3
    assert np.all(np.abs(onsets - expected) <= 1 / FRAME_HZ)
    widths = np.array([np.sum((frames >= o) & (out["perturbation"] == 1) & (frames < o + 0.2)) for o in onsets])
    assert np.all((widths >= 12) & (widths <= 14))  # 100 ms = 12.8 frames


def test_robot_log_at_its_own_rate_on_the_mocap_clock():
    """The robot-rate table: every robot sample at its mapped time (offset + scale x robot time, within the
    clock map's 0.2 ms), the filtered force there (the analytic signal within the same tolerance as the frames),
    the flag unchanged; the 128 Hz frames are its linear interpolation (the same table, bit for bit)."""
    offset_s, ppm, robot_t0_s = 3.217, 150.0, 0.0
    scale = 1 + ppm * 1e-6
    log, sync, frames, onsets_robot = make_trial(offset_s, ppm, robot_t0_s, seed=21)
    out, native = robot_log_frames_and_native(log, ROBOT_HZ, sync, ANALOG_HZ, frames, source="S01/walk")
    assert tuple(native.columns) == OUTPUT_COLUMNS and len(native) == len(log)
    t_robot = log["time_s"].to_numpy()
    assert np.abs(native["time_s"] - (offset_s + scale * t_robot)).max() < 0.2e-3
    slope = sum(a * 2 * np.pi * f for a, f, _ in FORCE_COMPONENTS)
    interior = (t_robot > 0.25) & (t_robot < t_robot[-1] - 0.25)
    np.testing.assert_allclose(
        native["force_measured_n"][interior], force(t_robot[interior]), atol=slope * 0.2e-3 + 0.01
    )
    np.testing.assert_array_equal(native["perturbation"], log["perturbation"].to_numpy(float))
    inside = out["force_measured_n"].notna().to_numpy()
    np.testing.assert_array_equal(
        out["force_measured_n"][inside], np.interp(frames[inside], native["time_s"], native["force_measured_n"])
    )
    pd.testing.assert_frame_equal(
        out, robot_log_on_mocap_frames(log, ROBOT_HZ, sync, ANALOG_HZ, frames, source="S01/walk")
    )


def test_robot_log_on_mocap_frames_bad_sync():
    log, sync, frames, _ = make_trial(3.217, 150.0, 0.0, seed=22)
    missing = log.assign(sync_v=np.nan)
    with pytest.raises(LoperInputError, match=r"S02/walk: robot log column 'sync_v': .*no finite sample"):
        robot_log_on_mocap_frames(missing, ROBOT_HZ, sync, ANALOG_HZ, frames, source="S02/walk")
    with pytest.raises(LoperInputError, match=r"S02/walk: mocap sync channel: .*flat"):
        robot_log_on_mocap_frames(log, ROBOT_HZ, np.zeros_like(sync), ANALOG_HZ, frames, source="S02/walk")
    flat = log.assign(sync_v=5.0)
    with pytest.raises(LoperInputError, match=r"S02/walk: robot log column 'sync_v': .*flat"):
        robot_log_on_mocap_frames(flat, ROBOT_HZ, sync, ANALOG_HZ, frames, source="S02/walk")
    with pytest.raises(LoperInputError, match="S02/walk: robot log lacks column.*perturbation"):
        robot_log_on_mocap_frames(
            log.drop(columns="perturbation"), ROBOT_HZ, sync, ANALOG_HZ, frames, source="S02/walk"
        )
    with pytest.raises(LoperInputError, match="S02/walk: column 'time_s'.*log_rate_hz"):
        robot_log_on_mocap_frames(log, 500.0, sync, ANALOG_HZ, frames, source="S02/walk")


def test_robot_log_on_mocap_frames_tolerates_missing_sync_samples():
    log, sync, frames, _ = make_trial(-1.5, -80.0, 0.0, seed=23)
    v = log["sync_v"].to_numpy().copy()
    v[20000:23000] = np.nan  # 3 s of missing sync samples in the robot log
    out = robot_log_on_mocap_frames(log.assign(sync_v=v), ROBOT_HZ, sync, ANALOG_HZ, frames, source="S03")
    cm = out.attrs["clock_map"]
    assert abs(cm.offset_s + 1.5) < 0.3e-3 and abs(cm.drift_ppm + 80.0) < 10.0


def test_perturbation_onsets():
    t = np.arange(10) * 0.1
    f = np.array([np.nan, 1, 0, 1, 1, 0, 0, 1, np.nan, 1])
    np.testing.assert_allclose(perturbation_onsets(t, f), [0.3, 0.7])
    with pytest.raises(LoperInputError, match="sample 2"):
        perturbation_onsets(t, np.array([0, 1, 2, 0, 0, 0, 0, 0, 0, 0]))


# --------------------------------------------------------------------------- settings


def test_settings_of_a_config():
    """The sync channel is events.sync_channel; the low-pass the walking trials' markers.filter.cutoff_hz and order."""
    config = copy.deepcopy(CONFIG)
    config["events"]["sync_channel"] = "trigger"
    config["markers"]["filter"].update(cutoff_hz=12.0, order=2)
    assert stage_settings(config, "events").loadcell == LoadcellSettings("trigger", 12.0, 2)
    assert stage_settings(CONFIG, "events").loadcell == LoadcellSettings() == LoadcellSettings(SYNC_CHANNEL, 40.0, 4)
    assert SYNC_CHANNEL == "sync"


@pytest.mark.parametrize("path", [("events", "sync_channel"), ("markers", "filter", "order")])
def test_settings_name_a_missing_key(path):
    config = copy.deepcopy(CONFIG)
    node = config
    for name in path[:-1]:
        node = node[name]
    del node[path[-1]]
    with pytest.raises(LoperInputError, match=f"^config: key '{'.'.join(path)}' missing: "):
        _ = stage_settings(config, "events").loadcell


def _with_shank_rod(log: pd.DataFrame, pulse_n: float = 30.0) -> pd.DataFrame:
    """``log`` with a second rod's load cell: its desired force a ``pulse_n`` N pulse wherever the flag is set, its
    measured force the analytic signal at half the thigh's size."""
    flag = log["perturbation"].to_numpy()
    t = log["time_s"].to_numpy()
    return log.assign(shank_force_desired_n=pulse_n * flag, shank_force_measured_n=0.5 * force(t) + pulse_n * flag)


def test_a_second_rods_load_cell_is_filtered_and_mapped_as_the_thigh_rods():
    """With the shank rod's columns both tables gain them; on the mocap frames the shank's measured force is its
    analytic signal (half the thigh's plus the pulses) within the thigh's own tolerance, and the thigh rod's
    columns are the same as without a second rod, bit for bit."""
    offset_s, ppm, robot_t0_s = 3.217, 150.0, 0.0
    log, sync, frames, _ = make_trial(offset_s, ppm, robot_t0_s, seed=21)
    one = robot_log_frames_and_native(log, ROBOT_HZ, sync, ANALOG_HZ, frames, source="S01/walk")
    two = robot_log_frames_and_native(
        _with_shank_rod(log), ROBOT_HZ, sync, ANALOG_HZ, frames, source="S01/walk", shank_pulse_force_n=30.0
    )
    for a, b in zip(one, two):
        assert tuple(b.columns) == (*OUTPUT_COLUMNS, *SHANK_OUTPUT_COLUMNS)
        pd.testing.assert_frame_equal(b[list(OUTPUT_COLUMNS)], a)
    native = two[1]
    t_robot = log["time_s"].to_numpy()
    interior = (t_robot > 0.25) & (t_robot < t_robot[-1] - 0.25)
    far = interior & (np.convolve(log["perturbation"].to_numpy(), np.ones(201), "same") == 0)  # 100 ms from pulses
    slope = sum(a * 2 * np.pi * f for a, f, _ in FORCE_COMPONENTS)
    np.testing.assert_allclose(
        native["shank_force_measured_n"][far], 0.5 * force(t_robot[far]), atol=0.5 * slope * 0.2e-3 + 0.01
    )


def test_a_second_rod_configured_without_its_columns_is_refused_naming_the_key():
    log, sync, frames, _ = make_trial(3.217, 150.0, 0.0, seed=21)
    with pytest.raises(LoperInputError) as err:
        robot_log_frames_and_native(log, ROBOT_HZ, sync, ANALOG_HZ, frames, source="S01/walk", shank_pulse_force_n=30.0)
    assert str(err.value) == (
        "S01/walk: planning.shank_pulse_force_n = 30 N plans a second rod at the shank, but the robot log holds no "
        "shank_force_desired_n and shank_force_measured_n columns (its load cell); record them, or set "
        "planning.shank_pulse_force_n to 0 for the thigh rod alone"
    )


def test_shank_pulses_in_a_design_without_a_second_rod_are_refused_naming_the_key():
    log, sync, frames, _ = make_trial(3.217, 150.0, 0.0, seed=21)
    with pytest.raises(LoperInputError, match=r"shank_force_desired_n' pulses to 30 N, but planning\.shank_pulse"):
        robot_log_frames_and_native(
            _with_shank_rod(log), ROBOT_HZ, sync, ANALOG_HZ, frames, source="S01/walk", shank_pulse_force_n=0.0
        )
    # a rod attached but never pushed (its desired force 0) is a design without shank pulses: accepted
    quiet = _with_shank_rod(log).assign(shank_force_desired_n=0.0)
    out, _ = robot_log_frames_and_native(quiet, ROBOT_HZ, sync, ANALOG_HZ, frames, shank_pulse_force_n=0.0)
    assert "shank_force_measured_n" in out.columns


def test_a_shank_rods_pulses_in_kn_are_refused_naming_its_column_and_key():
    log, sync, frames, _ = make_trial(3.217, 150.0, 0.0, seed=21)
    kn = _with_shank_rod(log, pulse_n=0.03)
    with pytest.raises(LoperInputError, match=r"column 'shank_force_desired_n'.*planning\.shank_pulse_force_n.*kN"):
        robot_log_frames_and_native(kn, ROBOT_HZ, sync, ANALOG_HZ, frames, shank_pulse_force_n=30.0)


def test_one_shank_column_without_its_pair_is_refused():
    log, sync, frames, _ = make_trial(3.217, 150.0, 0.0, seed=21)
    half = _with_shank_rod(log).drop(columns=["shank_force_desired_n"])
    with pytest.raises(LoperInputError, match="shank_force_measured_n without its pair"):
        robot_log_frames_and_native(half, ROBOT_HZ, sync, ANALOG_HZ, frames, shank_pulse_force_n=30.0)


def test_a_shank_load_cell_logged_with_the_wrong_sign_is_refused_naming_its_columns():
    """Measured force of the opposite sign to the desired pulses (a load cell mounted the other way): the median
    ratio is about -1, outside the accepted 0.5 .. 2, and the message names the shank rod's columns."""
    log, sync, frames, _ = make_trial(3.217, 150.0, 0.0, seed=21)
    two = _with_shank_rod(log)
    flipped = two.assign(shank_force_measured_n=-two["shank_force_measured_n"])
    with pytest.raises(
        LoperInputError, match=r"column 'shank_force_measured_n' is -1\.\d+ times column 'shank_force_desired_n'"
    ):
        robot_log_frames_and_native(flipped, ROBOT_HZ, sync, ANALOG_HZ, frames, shank_pulse_force_n=30.0)
