"""``loper-analysis inspect`` configuring a subject from a marker-set template (loper_analysis.stages.inspect), on every
lab file of the tests."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from loper_analysis.cli import main
from loper_analysis.errors import LoperInputError
from loper_analysis.schema import check_config
from loper_analysis.stages.inspect import inspect_subject

ROOT = Path(__file__).resolve().parents[2]
QCMAS = ROOT / "tests" / "data" / "c3d-parser" / "QCMAS"
#: Every C3D file of another lab (or written as one) the tests hold, with the template it must choose.
LAB_FILES = {
    "clinical Nexus pair": ([QCMAS / "static.c3d", QCMAS / "walk-nodevice.c3d"], "plugin_gait"),
    "OpenSim's walking5 (Nexus 1.8)": ([ROOT / "tests/data/opensim-core/walking5.c3d"], "isb"),
    "Rajagopal2016 as a Vicon lab": (
        [ROOT / "examples/rajagopal2016/raw/R11/static.c3d", ROOT / "examples/rajagopal2016/raw/R11/walk-nodevice.c3d"],
        "isb",
    ),
}


def _merged(base: dict, over: dict) -> dict:
    out = dict(base)
    for key, value in over.items():
        out[key] = _merged(base.get(key, {}), value) if isinstance(value, dict) and key in base else value
    return out


@pytest.mark.parametrize("lab", sorted(LAB_FILES))
def test_inspect_writes_a_schema_valid_config_for_every_lab_file(lab, tmp_path):
    files, template = LAB_FILES[lab]
    config_out = tmp_path / "lab" / "S1" / "config.yaml"
    result = inspect_subject(files, config_out)
    assert result.setup.template.name == template
    doc = yaml.safe_load(config_out.read_text())
    for key in ("generic_model", "scale_setup", "ik_tasks"):
        assert Path(doc["ik" if key == "ik_tasks" else "model"][key]).is_file(), key
    assert (config_out.parent / "marker_set.xml").is_file()
    base = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    check_config(_merged(base, doc), ROOT / "workflow" / "schemas" / "config.schema.yaml")
    assert result.written[-1] == config_out


def test_a_config_over_an_input_is_refused_and_nothing_is_written(tmp_path, capsys):
    static = tmp_path / "static.c3d"
    static.write_bytes((QCMAS / "static.c3d").read_bytes())
    before = static.read_bytes()
    assert main(["inspect", str(static), "--config-out", str(static)]) == 2
    assert f"--config-out would write over c3d {static}" in capsys.readouterr().err
    assert static.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["static.c3d"]
    with pytest.raises(LoperInputError, match="would overwrite an input file"):
        inspect_subject([static], tmp_path / "static.c3d")
