"""io/osim.py: OpenSim files read against their own XML (counted here with ElementTree), written and read back,
and files that are not what they claim refused with messages naming them."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import (
    model_source,
    quiet_opensim,
    read_marker_set,
    read_model,
    read_scale_setup,
    write_model,
    write_osim_object,
)

ROOT = Path(__file__).resolve().parents[2]
GAIT2392 = ROOT / "examples" / "gait2392" / "gait2392_simbody.osim"
MARKER_SET = ROOT / "examples" / "gait2392" / "gait2392_Scale_MarkerSet.xml"
SCALE_SETUP = ROOT / "examples" / "gait2392" / "scale_setup.xml"


@pytest.fixture(scope="module")
def gait2392():
    return read_model(GAIT2392)


def test_a_model_holds_what_its_file_says(gait2392):
    root = ET.parse(GAIT2392).getroot()
    assert gait2392.getName() == root.find("Model").get("name") == "3DGaitModel2392"
    assert gait2392.getBodySet().getSize() == len(root.findall("./Model/BodySet/objects/Body")) == 12
    assert gait2392.getCoordinateSet().getSize() == len(root.findall(".//Coordinate")) == 23
    assert model_source(gait2392) == f"{GAIT2392} (model 3DGaitModel2392)"


def test_a_model_written_reads_back_and_an_unsaved_one_is_named_alone(gait2392, tmp_path):
    osim = quiet_opensim()
    copy = osim.Model(gait2392)
    copy.setName("copy_of_2392")
    assert model_source(copy) == f"{GAIT2392} (model copy_of_2392)"  # the copy keeps its file
    built = osim.Model()
    built.setName("built")
    assert model_source(built) == "model built"  # built in memory: no file, the name alone
    path = write_model(copy, tmp_path / "sub" / "copy.osim")
    assert path == tmp_path / "sub" / "copy.osim"
    again = read_model(path)
    assert again.getName() == "copy_of_2392" and model_source(again) == f"{path} (model copy_of_2392)"
    assert [again.getCoordinateSet().get(i).getName() for i in range(23)] == [
        gait2392.getCoordinateSet().get(i).getName() for i in range(23)
    ]
    assert sorted(p.name for p in (tmp_path / "sub").iterdir()) == ["copy.osim"]  # nothing staged left behind


def test_a_marker_set_and_a_scale_setup_hold_what_their_files_say(tmp_path):
    markers = read_marker_set(MARKER_SET)
    names = [m.get("name") for m in ET.parse(MARKER_SET).getroot().iter("Marker")]
    assert [markers.get(i).getName() for i in range(markers.getSize())] == names and len(names) == 39
    setup = read_scale_setup(SCALE_SETUP)
    tool = ET.parse(SCALE_SETUP).getroot().find("ScaleTool")
    assert setup.getName() == tool.get("name") == "gait2392_lab_scale"
    assert setup.getSubjectMass() == float(tool.find("mass").text) == 75.0
    path = write_osim_object(markers, tmp_path / "markers.xml", "marker set")
    assert read_marker_set(path).getSize() == 39


def test_files_that_are_no_model_or_setup_are_refused(tmp_path):
    def refused(message: str):
        return pytest.raises(LoperInputError, match="^" + re.escape(message))

    with refused(f"model file not found: {tmp_path / 'none.osim'}"):
        read_model(tmp_path / "none.osim")
    text = tmp_path / "text.osim"
    text.write_text("not xml")
    with refused(f"{text}: not an OpenSim model: not an XML file ("):
        read_model(text)
    with refused(f"{MARKER_SET}: not an OpenSim model (its <OpenSimDocument> element holds no <Model>)"):
        read_model(MARKER_SET)
    with refused(f"{GAIT2392}: not an OpenSim ScaleTool setup (its <OpenSimDocument> element holds no <ScaleTool>)"):
        read_scale_setup(GAIT2392)
    with refused(f"scale setup file not found: {tmp_path / 'none.xml'}"):
        read_scale_setup(tmp_path / "none.xml")
    with refused(f"marker set file not found: {tmp_path / 'none.xml'}"):
        read_marker_set(tmp_path / "none.xml")
