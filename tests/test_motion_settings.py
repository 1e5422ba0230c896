"""The settings of the model, IK and GRF steps: built from the config as the rules build them, and by the commands.

``ModelSettings``, ``IKSettings`` and ``GRFSettings`` default to the shipped configuration's values;
``loper-analysis grf|scale|segments|ik`` take their settings from the config of the working directory (and
``--configfile``), the options given on the command line winning.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.cli import main
from loper_analysis.gait.grf_settings import GRFSettings
from loper_analysis.io.opensim_tables import read_mot, write_trc
from loper_analysis.io.osim import read_model, write_model
from loper_analysis.io.segment_table import read_segments
from loper_analysis.motion.ik import DEFAULT_COORDINATE_MAP, marker_positions
from loper_analysis.motion.ik_settings import IKSettings
from loper_analysis.motion.model import MARKERS, build_lower_body_model
from loper_analysis.motion.segments import segments_from_model
from loper_analysis.stages.model.step import ModelSettings
from loper_analysis.stages.settings import stage_settings
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry
from tests.gait2392_models import GENERIC, scaled_gait2392

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "config.yaml"
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"
SCALE_SETUP = ROOT / "examples" / "gait2392" / "scale_setup.xml"
WALKING5 = ROOT / "tests" / "data" / "opensim-core" / "walking5.c3d"
SHIPPED = yaml.safe_load(CONFIG.read_text())


def _configure(project: Path, **sections: dict) -> None:
    """Change keys of config/config.yaml in ``project``: ``section={key: value}``."""
    path = project / "config" / "config.yaml"
    config = yaml.safe_load(path.read_text())
    for section, values in sections.items():
        config[section].update(values)
    path.write_text(yaml.safe_dump(config))


# --------------------------------------------------------------------------- defaults = the shipped config


def test_model_and_grf_settings_of_the_shipped_config_are_the_defaults():
    model = stage_settings(SHIPPED, "model")
    # the coordinate map written out in the config is the library's default map, for which None stands
    assert {k: (v["coordinate"], v["sign"]) for k, v in model.coordinate_map.items()} == DEFAULT_COORDINATE_MAP
    assert dataclasses.replace(model, coordinate_map=None) == ModelSettings()
    assert stage_settings(SHIPPED, "grf") == GRFSettings()


def test_ik_settings_of_the_shipped_config_are_the_defaults():
    settings = stage_settings(SHIPPED, "ik")
    # the config writes "none" as empty mappings and the coordinate map out; the library's None stands for them
    assert settings.marker_weights == {} and settings.coordinate_tasks == {}
    shipped_map = {k: (v["coordinate"], v["sign"]) for k, v in settings.coordinate_map.items()}
    assert shipped_map == DEFAULT_COORDINATE_MAP
    plain = dataclasses.replace(settings, marker_weights=None, coordinate_tasks=None, coordinate_map=None)
    assert plain == IKSettings()


def test_a_changed_config_key_changes_the_settings():
    config = yaml.safe_load(CONFIG.read_text())
    config["ik"]["tree_step_tolerance"] = 1e-8
    config["grf"]["loaded_threshold_n"] = 35.0
    config["model"]["static_duration_s"] = None
    assert stage_settings(config, "ik").tree_step_tolerance == 1e-8
    assert stage_settings(config, "grf").threshold_n == 35.0
    assert stage_settings(config, "model").static_duration_s is None


# --------------------------------------------------------------------------- segments


def test_segments_takes_the_config_and_an_option_wins(project, capsys):
    _configure(project, model={"brace_attachment_fraction": 0.6})
    assert main(["segments", "--height-m", "1.8", "--mass-kg", "70", "--out", "config.tsv"]) == 0
    assert "config: config/config.yaml" in capsys.readouterr().out
    np.testing.assert_allclose(
        read_segments("config.tsv").packed, segment_parameters_from_anthropometry(1.8, 70, 0.6).packed, rtol=1e-9
    )
    argv = ["segments", "--height-m", "1.8", "--mass-kg", "70", "--attachment-fraction", "0.7", "--out", "option.tsv"]
    assert main(argv) == 0
    np.testing.assert_allclose(
        read_segments("option.tsv").packed, segment_parameters_from_anthropometry(1.8, 70, 0.7).packed, rtol=1e-9
    )


def test_segments_of_a_model_take_the_configured_side(project):
    _configure(project, study={"perturbed_side": "right"})
    assert main(["segments", "--model", str(GENERIC), "--out", "right.tsv"]) == 0
    assert main(["segments", "--model", str(GENERIC), "--side", "left", "--out", "left.tsv"]) == 0
    model = read_model(GENERIC)
    for name, suffix in (("right.tsv", "r"), ("left.tsv", "l")):
        np.testing.assert_allclose(read_segments(name).packed, segments_from_model(model, suffix).packed, rtol=1e-9)


# --------------------------------------------------------------------------- grf


def test_grf_takes_the_config_threshold_and_rotation_and_options_win(project, capsys):
    def loaded(name: str) -> int:
        return int((read_mot(name)["1_ground_force_vz"] != 0.0).sum())  # lab frame: z up

    _configure(project, markers={"lab_to_model_rotation_deg": [0.0, 0.0, 0.0]})
    assert main(["grf", str(WALKING5), "--out", "lab.grf.mot"]) == 0
    assert "config: config/config.yaml" in capsys.readouterr().out
    assert main(["grf", str(WALKING5), "--out", "typed.grf.mot", "--rotate-deg", "0", "0", "0"]) == 0
    pd.testing.assert_frame_equal(read_mot("lab.grf.mot"), read_mot("typed.grf.mot"))  # the config's rotation
    _configure(project, grf={"loaded_threshold_n": 400.0})
    assert main(["grf", str(WALKING5), "--out", "high.grf.mot"]) == 0
    assert main(["grf", str(WALKING5), "--out", "low.grf.mot", "--threshold-n", "20"]) == 0
    assert 0 < loaded("high.grf.mot") < loaded("low.grf.mot") == loaded("lab.grf.mot")
    pd.testing.assert_frame_equal(read_mot("low.grf.mot"), read_mot("lab.grf.mot"))


# --------------------------------------------------------------------------- ik


def test_ik_takes_the_config_limits_and_options_win(project, capsys):
    generic = build_lower_body_model(1.73, 64.9)
    model = write_model(generic, project / "model.osim")
    t = np.arange(16) / 128.0
    X = marker_positions(generic, {"pelvis_ty": np.full(t.size, 0.93)})
    X = X + np.random.default_rng(1).normal(0, 0.002, X.shape)  # 2 mm marker noise
    write_trc(project / "trial.trc", t, X, list(MARKERS))
    argv = ["ik", "--model", str(model), "--markers", "trial.trc", "--out", "trial.mot"]
    _configure(project, ik={"max_marker_rms_m": 1e-4, "warn_marker_rms_m": 1e-5})
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert "config: config/config.yaml" in captured.out and "ik.max_marker_rms_m" in captured.err
    assert not (project / "trial.mot").exists()
    assert main([*argv, "--max-marker-rms-m", "0.06", "--warn-marker-rms-m", "0.02"]) == 0
    captured = capsys.readouterr()
    assert "16 frames" in captured.out and "warning" not in captured.err
    assert len(read_mot("trial.mot")) == 16


# --------------------------------------------------------------------------- scale


@pytest.fixture
def moving_static(project):
    """gait2392's markers scaled with known factors, standing for 0.1 s, then one knee marker 5 cm off (0.2 s)."""
    factors = {"pelvis": 1.05, "torso": 1.05, "femur": 1.10, "tibia": 0.95, "talus": 1.05, "calcn": 1.05, "toes": 1.05}
    model = scaled_gait2392(factors, 80.0, markers=True)
    markers = model.getMarkerSet()
    labels = [markers.get(i).getName() for i in range(markers.getSize())]
    X = np.repeat(marker_positions(model, {}, labels), 20, axis=0)
    X[10:, labels.index("R.Knee.Lat"), 0] += 0.05
    return write_trc(project / "static.trc", np.arange(20) / 100.0, X, labels)


def test_scale_takes_the_configs_window_and_motion_limit_and_options_win(project, moving_static, capsys):
    def argv(out: str, *options: str) -> list[str]:
        files = ["--model", str(GENERIC), "--setup", str(SCALE_SETUP), "--static", str(moving_static)]
        return ["scale", *files, "--mass-kg", "80", "--out", out, *options]

    # the whole trial (model.static_duration_s 1 s): the knee marker moves 25 mm RMS, over the config's 10 mm
    _configure(project, markers={"static_max_motion_rms_m": 0.01})
    assert main(argv("never.osim")) == 2
    assert "model.static_max_motion_rms_m 0.01 m" in capsys.readouterr().err
    # the limit given as 0 is no limit
    assert main(argv("unchecked.osim", "--max-motion-rms-m", "0")) == 0
    assert "config: config/config.yaml" in capsys.readouterr().out
    # the config's first 0.05 s: before the move, the known factors
    _configure(project, markers={"static_duration_s": 0.05, "static_max_motion_rms_m": 0.01})
    assert main(argv("still.osim")) == 0
    thigh = segments_from_model(read_model("still.osim"), "r").length_m[0]
    generic_thigh = segments_from_model(read_model(GENERIC), "r").length_m[0]
    np.testing.assert_allclose(thigh / generic_thigh, 1.10, rtol=1e-6)
    # a window given on the command line wins over the config's
    assert main(argv("window.osim", "--start", "0", "--end", "0.19")) == 2
    assert "model.static_max_motion_rms_m" in capsys.readouterr().err
    assert not (project / "never.osim").exists() and not (project / "window.osim").exists()
