"""``loper-analysis markers`` and ``events`` take their settings from the workflow's configuration.

Run in a project folder, each command builds its stage's settings as the rule does
(:meth:`~loper_analysis.stages.markers.step.MarkerSettings.from_config`,
:meth:`~loper_analysis.stages.events.step.EventSettings.from_config`) from ``config/config.yaml`` and any
``--configfile``, says which files it read, and lets an option given on the command line win.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.cli import main
from loper_analysis.io.c3d_writer import write_c3d

ROOT = Path(__file__).resolve().parents[1]

RATE_HZ = 100.0
GAP_FRAMES = 5  # one interior gap of marker RASI
ANALOG_HZ = 1000.0
RAMP_N_PER_S = 6000.0  # the belt force rises from 0 to 600 N in 0.1 s at each heel strike
STRIKES_S = (0.5, 1.5, 2.5)


def _layer(project: Path, name: str, data: dict) -> str:
    path = project / "config" / name
    path.write_text(yaml.safe_dump(data))
    return str(path)


@pytest.fixture
def gappy(project) -> Path:
    """Three markers standing still about 1 m apart (a treadmill trial does not travel), RASI missing for
    GAP_FRAMES interior frames."""
    n = 100
    X = np.tile(np.array([[0.1, -0.1, 1.0], [0.1, 0.1, 1.0], [0.0, 0.1, 0.05]]), (n, 1, 1))
    X = X + 0.002 * np.sin(np.arange(n) / 10.0)[:, None, None]
    X[40 : 40 + GAP_FRAMES, 0] = np.nan
    return write_c3d(project / "gappy.c3d", ["RASI", "LASI", "LHEE"], X, RATE_HZ)


def _markers(path: Path, *options: str) -> pd.DataFrame:
    assert main(["markers", str(path), "--out", "m.trc", "--gaps", "m.gaps.tsv", *options]) == 0
    return pd.read_csv("m.gaps.tsv", sep="\t")


def test_markers_fills_gaps_up_to_the_configs_length_unless_told(gappy, project, capsys):
    config = yaml.safe_load((project / "config" / "config.yaml").read_text())
    assert config["markers"]["max_gap_frames"] >= GAP_FRAMES
    assert _markers(gappy)["n_frames"].tolist() == [GAP_FRAMES]
    assert "config: config/config.yaml" in capsys.readouterr().out
    shorter = _layer(project, "short.yaml", {"markers": {"max_gap_frames": GAP_FRAMES - 1}})
    assert len(_markers(gappy, "--configfile", shorter)) == 0  # the layered file's limit: the gap stays
    assert (
        "config: config/config.yaml, config/short.yaml (later files override earlier ones)" in capsys.readouterr().out
    )
    assert _markers(gappy, "--configfile", shorter, "--max-gap-frames", str(GAP_FRAMES))["n_frames"].tolist() == [
        GAP_FRAMES
    ]  # the option wins


def test_markers_without_a_config_uses_the_librarys_defaults_and_says_so(gappy, project, capsys):
    (project / "config" / "config.yaml").unlink()
    assert _markers(gappy)["n_frames"].tolist() == [GAP_FRAMES]  # the library's 10 frames, as the config's
    assert "config: none" in capsys.readouterr().out


@pytest.fixture
def belts(project) -> Path:
    """A treadmill trial without force platforms: each belt's vertical force on the config's channels
    (Fz_left, Fz_right) ramps at RAMP_N_PER_S from 0 N at each heel strike, holds 600 N, and drops at toe-off;
    heel markers keep the left heel the lower during left stances (and the right during right stances)."""
    t = np.arange(0.0, 4.0, 1.0 / ANALOG_HZ)
    forces = []
    for shift in (0.0, 0.5):
        f = np.zeros_like(t)
        for strike in STRIKES_S:
            s = strike + shift
            stance = (t >= s) & (t < s + 0.6)
            f[stance] = np.minimum(RAMP_N_PER_S * (t[stance] - s), 600.0)
        forces.append(f)
    frames = np.arange(0.0, 4.0, 1.0 / RATE_HZ)
    left_down = np.interp(frames, t, forces[0]) > 0
    heels = np.zeros((len(frames), 2, 3))
    heels[:, 0] = [0.2, 0.1, 0.0]
    heels[:, 1] = [0.2, -0.1, 0.0]
    heels[:, 0, 2] = np.where(left_down, 0.05, 0.15)
    heels[:, 1, 2] = np.where(left_down, 0.15, 0.05)
    return write_c3d(
        project / "belts.c3d",
        ["LHEE", "RHEE"],
        heels,
        RATE_HZ,
        ["Fz_left", "Fz_right"],
        np.column_stack(forces),
        ["N", "N"],
        ANALOG_HZ,
    )


def _heel_strikes(path: Path, *options: str) -> np.ndarray:
    assert main(["events", str(path), "--out", "e.tsv", *options]) == 0
    table = pd.read_csv("e.tsv", sep="\t")
    return table.loc[(table.side == "left") & (table.event == "heel_strike"), "time_s"].to_numpy()


def test_events_threshold_from_the_config_unless_told(belts, project, capsys):
    config = yaml.safe_load((project / "config" / "config.yaml").read_text())
    on_n = config["events"]["threshold_on_n"]
    default = _heel_strikes(belts)
    assert "config: config/config.yaml" in capsys.readouterr().out
    # the force crosses the threshold on_n / RAMP_N_PER_S after the strike (to one analog sample)
    np.testing.assert_allclose(default, np.array(STRIKES_S) + on_n / RAMP_N_PER_S, atol=1.0 / ANALOG_HZ)
    higher = _layer(project, "high.yaml", {"events": {"threshold_on_n": 300.0}})
    later = _heel_strikes(belts, "--configfile", higher)
    np.testing.assert_allclose(later - default, (300.0 - on_n) / RAMP_N_PER_S, atol=1.0 / ANALOG_HZ)
    told = _heel_strikes(belts, "--configfile", higher, "--threshold-on-n", str(on_n))
    np.testing.assert_array_equal(told, default)  # the option wins
