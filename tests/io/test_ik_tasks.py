"""io/ik_tasks.py: IK task sets written with OpenSim (a bare IKTaskSet, or inside an InverseKinematicsTool setup)
and as TSV tables, read back into known marker weights and coordinate tasks."""

from __future__ import annotations

import re

import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.ik_tasks import read_ik_tasks, task_set_tasks
from loper_analysis.io.osim import quiet_opensim

WEIGHTS = {"RASI": 10.0, "LASI": 2.5, "RHEE": 0.0}


def _task_set(osim, value_type=None):
    """Marker tasks of :data:`WEIGHTS` plus one not applied; two coordinate tasks (manual 0.05, default)."""
    tasks = osim.IKTaskSet()
    for name, weight in [*WEIGHTS.items(), ("C7", 99.0)]:
        task = osim.IKMarkerTask()
        task.setName(name)
        task.setWeight(weight)
        task.setApply(name != "C7")
        tasks.cloneAndAppend(task)
    manual = osim.IKCoordinateTask()
    manual.setName("knee_angle_r")
    manual.setWeight(5.0)
    manual.setValueType(osim.IKCoordinateTask.ManualValue if value_type is None else value_type)
    manual.setValue(0.05)
    tasks.cloneAndAppend(manual)
    default = osim.IKCoordinateTask()
    default.setName("ankle_angle_r")
    default.setWeight(1.5)
    default.setValueType(osim.IKCoordinateTask.DefaultValue)
    tasks.cloneAndAppend(default)
    return tasks


@pytest.fixture(scope="module")
def osim():
    return quiet_opensim()


def test_a_task_set_file_reads_back(osim, tmp_path):
    path = tmp_path / "tasks.xml"
    _task_set(osim).printToXML(str(path))
    markers, coordinates = read_ik_tasks(path)
    assert markers == WEIGHTS  # C7, not applied, is left out
    assert coordinates == {"knee_angle_r": (5.0, 0.05), "ankle_angle_r": (1.5, None)}


def test_the_task_set_of_an_ik_setup_reads_back_without_its_model(osim, tmp_path):
    tool = osim.InverseKinematicsTool()
    tool.set_IKTaskSet(_task_set(osim))
    tool.set_model_file("no_such_model.osim")
    path = tmp_path / "ik_setup.xml"
    tool.printToXML(str(path))
    assert read_ik_tasks(path) == (WEIGHTS, {"knee_angle_r": (5.0, 0.05), "ankle_angle_r": (1.5, None)})


def test_a_value_from_a_file_and_an_empty_set_are_refused(osim):
    with pytest.raises(
        LoperInputError, match=r"^setup\.xml: coordinate task knee_angle_r takes its value from a file; not supported$"
    ):
        task_set_tasks(_task_set(osim, osim.IKCoordinateTask.FromFile), "setup.xml")
    with pytest.raises(LoperInputError, match=r"^setup\.xml: the IK task set holds no task$"):
        task_set_tasks(osim.IKTaskSet(), "setup.xml")


def test_a_tsv_reads_into_the_same_tasks(tmp_path):
    path = tmp_path / "tasks.tsv"
    path.write_text(
        "name\tkind\tweight\tvalue\nRASI\tmarker\t10\t\nLASI\tmarker\t2.5\t\nRHEE\tmarker\t0\t\n"
        "knee_angle_r\tcoordinate\t5\t0.05\nankle_angle_r\tcoordinate\t1.5\t\n"
    )
    assert read_ik_tasks(path) == (WEIGHTS, {"knee_angle_r": (5.0, 0.05), "ankle_angle_r": (1.5, None)})
    path.write_text("name\tkind\tweight\nRASI\tmarker\t10\nknee_angle_r\tcoordinate\t5\n")
    assert read_ik_tasks(path) == ({"RASI": 10.0}, {"knee_angle_r": (5.0, None)})


@pytest.mark.parametrize(
    "text, message",
    [
        ("name\tweight\nRASI\t1\n", "missing column(s) ['kind']"),
        ("name\tkind\tweight\nRASI\tmarker\t-1\n", "row 1, column weight: -1 is not a weight >= 0"),
        ("name\tkind\tweight\nRASI\tmarker\t1\nLASI\tmarker\theavy\n", "row 2, column weight: 'heavy' is not a"),
        ("name\tkind\tweight\nRASI\tsegment\t1\n", "row 1, column kind: 'segment' is not 'marker' or 'coordinate'"),
    ],
)
def test_bad_tsv_rows_are_named(tmp_path, text, message):
    path = tmp_path / "tasks.tsv"
    path.write_text(text)
    with pytest.raises(LoperInputError, match="^" + re.escape(f"{path}: {message}")):
        read_ik_tasks(path)


def test_missing_and_foreign_files_are_refused(tmp_path):
    with pytest.raises(LoperInputError, match="^" + re.escape(f"IK task file not found: {tmp_path / 'no.xml'}")):
        read_ik_tasks(tmp_path / "no.xml")
    (tmp_path / "bad.xml").write_text("<OpenSimDocument><Model/></OpenSimDocument>")  # no Version attribute
    with pytest.raises(LoperInputError, match="^" + re.escape(f"{tmp_path / 'bad.xml'}: not an OpenSim IK task set (")):
        read_ik_tasks(tmp_path / "bad.xml")
    (tmp_path / "text.xml").write_text("this is not XML")  # OpenSim reads no task from it
    with pytest.raises(LoperInputError, match="^" + re.escape(f"{tmp_path / 'text.xml'}: the IK task set holds no")):
        read_ik_tasks(tmp_path / "text.xml")
