"""gait/trial_events.py: heel strikes and toe-offs of a treadmill recording built in memory, one vertical-force
channel per belt with known stances, and the heel markers that confirm (or refute) each belt's foot."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.trial_events import EventSettings, trial_events
from loper_analysis.io.c3d import C3DRecording
from loper_analysis.stages.settings import stage_settings

RATE_HZ, ANALOG_HZ, DURATION_S = 100.0, 1000.0, 6.0
#: Each belt's stances [heel strike, toe-off) in s: 0.7 s stances, 1.2 s strides, 0.1 s double support.
STANCES = {
    "left": [(0.5, 1.2), (1.7, 2.4), (2.9, 3.6), (4.1, 4.8)],
    "right": [(1.1, 1.8), (2.3, 3.0), (3.5, 4.2), (4.7, 5.4)],
}
LOW_M, HIGH_M = 0.03, 0.15  # heel height standing, swinging


def _recording(labels=("LHEE", "RHEE", "LASI"), units="N") -> C3DRecording:
    """Z-up lab; each belt carries 600 N over its stances; a heel is low while its foot stands."""
    n = int(DURATION_S * RATE_HZ)
    t, ta = np.arange(n) / RATE_HZ, np.arange(n * 10) / ANALOG_HZ
    forces, heels = [], []
    for side in ("left", "right"):
        k = np.arange(n * 10)
        on = np.zeros(n * 10, dtype=bool)
        for a, b in STANCES[side]:
            on |= (k >= round(a * ANALOG_HZ)) & (k < round(b * ANALOG_HZ))
        forces.append(np.where(on, 600.0, 0.0))
        standing = np.interp(t, ta, on.astype(float)) > 0.5
        heels.append(np.column_stack([0.1 * t, np.full(n, 0.1), np.where(standing, LOW_M, HIGH_M)]))
    X = np.stack(heels + [np.column_stack([0.1 * t, np.zeros(n), np.full(n, 0.95)])], axis=1)
    names = {"LHEE": 0, "RHEE": 1, "LASI": 2}
    return C3DRecording(
        "walk.c3d",
        list(labels),
        X[:, [names[lab] for lab in labels]],
        RATE_HZ,
        analog_labels=["Fz_left", "Fz_right"],
        analog_units=[units, units],
        analogs=np.column_stack(forces),
        analog_rate_hz=ANALOG_HZ,
    )


def test_belt_channels_give_the_known_events():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # both belts' feet are confirmed: no warning
        table, contacts = trial_events(_recording(), [], EventSettings())
    expected = sorted(
        [(a, side, "heel_strike") for side in STANCES for a, _ in STANCES[side]]
        + [(b, side, "toe_off") for side in STANCES for _, b in STANCES[side]]
    )
    assert list(zip(table.time_s.round(9), table.side, table.event)) == expected
    np.testing.assert_array_equal(table["sample"], np.round(table.time_s * ANALOG_HZ).astype(int))
    assert table.attrs["n_contacts_flagged"] == 0
    assert contacts.empty and list(contacts.columns) == ["plate", "contact", "side", "flag"]


def test_swapped_belt_channels_are_refused():
    swapped = EventSettings(grf_channels={"left": "Fz_right", "right": "Fz_left"})
    message = (
        "walk.c3d: events.grf_channels.left: channel Fz_right does not carry the left foot: in 4 of its 4 stances "
        "the right heel (RHEE) was the lower at mid-stance (by 120 mm, median); are the belts' channels swapped "
        "(events.grf_channels: {left: Fz_right, right: Fz_left})?"
    )
    with pytest.raises(LoperInputError, match="^" + re.escape(message) + "$"):
        trial_events(_recording(), [], swapped)


def test_without_heel_markers_the_feet_are_not_confirmed_but_events_come():
    with pytest.warns(UserWarning, match=re.escape("heel marker(s) LHEE, RHEE (events.foot_markers) not in the file")):
        table, _ = trial_events(_recording(labels=("LASI",)), [], EventSettings())
    assert len(table) == 16
    named = EventSettings(foot_markers={"left": "L.Heel", "right": "R.Heel"})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        table, _ = trial_events(_recording(), [], named, label_map={"LHEE": "L.Heel", "RHEE": "R.Heel"})
    assert len(table) == 16


def test_missing_channels_or_settings_are_named():
    with pytest.raises(
        LoperInputError,
        match="^"
        + re.escape(
            "walk.c3d: no analog channel 'Fz_belt2' (events.grf_channels.right), and no force platforms "
            "(FORCE_PLATFORM:USED is 0 or absent); channels present: Fz_left, Fz_right"
        ),
    ):
        trial_events(_recording(), [], EventSettings(grf_channels={"left": "Fz_left", "right": "Fz_belt2"}))
    with pytest.raises(LoperInputError, match=r"^walk\.c3d: no force platforms .* and no GRF channel configured"):
        trial_events(_recording(), [], EventSettings(grf_channels=None))
    with pytest.raises(LoperInputError, match=r"analog channel 'Fz_left' \(events\.grf_channels\.left\) is in 'V'"):
        trial_events(_recording(units="V"), [], EventSettings())


def test_settings_from_the_config_file(repo_root):
    config = yaml.safe_load((repo_root / "config" / "config.yaml").read_text())
    s = stage_settings(config, "events").events
    e = config["events"]
    assert (s.threshold_on_n, s.threshold_off_n, s.min_stance_s, s.min_swing_s) == (
        e["threshold_on_n"],
        e["threshold_off_n"],
        e["min_stance_s"],
        e["min_swing_s"],
    )
    assert s.rotation_deg == tuple(config["markers"]["lab_to_model_rotation_deg"])
    assert (s.band_n, s.max_rest_n, s.order) == (
        config["grf"]["resting_band_n"],
        config["grf"]["max_resting_n"],
        config["markers"]["filter"]["order"],
    )
