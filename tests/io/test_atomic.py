"""The atomic writer: every kind of output is complete or absent, never half-written.

Each writer is made to fail halfway through a real write (a figure that
cannot render, a table cell that cannot be formatted, a library writer that
raises after writing part of its file); afterwards the target must hold its
old bytes (or not exist) and no staging file or directory may remain.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import (
    staged,
    write_bytes,
    write_figure,
    write_text,
    write_tsv,
    write_yaml,
)
from loper_analysis.io.c3d_writer import write_c3d
from loper_analysis.io.opensim_tables import write_mot, write_trc
from loper_analysis.io.osim import write_model
from loper_analysis.io.robot_log import write_robot_log
from loper_analysis.report.figures import pyplot


def _entries(directory):
    return sorted(p.name for p in directory.iterdir())


class _Unprintable:
    """A table cell whose text cannot be made: formatting it raises, as a broken object would."""

    def __str__(self):
        raise RuntimeError("cell cannot be formatted")

    __repr__ = __format__ = __str__


def test_staged_moves_the_finished_file_and_leaves_nothing_else(tmp_path):
    target = tmp_path / "out" / "table.tsv"  # the directory is created
    with staged(target) as tmp:
        assert tmp.name == "table.tsv" and tmp.parent != target.parent
        tmp.write_text("a\n1\n")
    assert target.read_text() == "a\n1\n"
    assert _entries(target.parent) == ["table.tsv"]


def test_staging_left_by_a_killed_writer_is_removed_when_the_target_is_written_again(tmp_path):
    target, other = tmp_path / "strides.tsv", tmp_path / "cycles.tsv"
    stale = tmp_path / ".strides.tsv.k3x9_q2a.partial"  # what a writer killed halfway leaves
    stale.mkdir()
    (stale / "strides.tsv").write_text("stride\n0\n1\n")
    busy = tmp_path / ".cycles.tsv.a1b2c3d4.partial"  # another target's: not touched
    busy.mkdir()
    write_text(target, "stride\n0\n1\n2\n")
    assert target.read_text() == "stride\n0\n1\n2\n"
    assert _entries(tmp_path) == [".cycles.tsv.a1b2c3d4.partial", "strides.tsv"]
    write_text(other, "x\n")
    assert _entries(tmp_path) == ["cycles.tsv", "strides.tsv"]


def test_staged_keeps_the_old_file_when_the_writer_fails_halfway(tmp_path):
    target = tmp_path / "data.bin"
    target.write_bytes(b"old")
    with pytest.raises(OSError, match="disk interrupted"):
        with staged(target) as tmp:
            with tmp.open("wb") as fh:
                fh.write(b"first half")
                raise OSError("disk interrupted")
    assert target.read_bytes() == b"old"
    assert _entries(tmp_path) == ["data.bin"]


def test_staged_refuses_a_writer_that_wrote_nothing(tmp_path):
    with pytest.raises(LoperInputError, match="produced no file"):
        with staged(tmp_path / "x.tsv"):
            pass
    assert _entries(tmp_path) == []


def test_staged_names_the_path_when_the_directory_cannot_be_made(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    with pytest.raises(LoperInputError, match=f"{blocker}/sub/x.tsv: cannot write"):
        write_text(blocker / "sub" / "x.tsv", "x")


def test_tsv_writer_leaves_no_partial_table_when_a_cell_fails(tmp_path):
    target = tmp_path / "strides.tsv"
    write_tsv(pd.DataFrame({"a": [1.0, 2.0]}), target)
    old = target.read_bytes()
    rows = 10_000  # the failing cell comes after thousands of rows were formatted
    frame = pd.DataFrame({"a": np.arange(rows, dtype=float), "b": ["x"] * (rows - 1) + [_Unprintable()]})
    with pytest.raises(RuntimeError, match="cannot be formatted"):
        write_tsv(frame, target)
    assert target.read_bytes() == old
    assert _entries(tmp_path) == ["strides.tsv"]


def test_tsv_writer_gives_the_same_bytes_for_the_same_frame(tmp_path):
    frame = pd.DataFrame({"time_s": [0.0, 1 / 3], "flag": [True, False], "x": [np.nan, 2.5e-7]})
    write_tsv(frame, tmp_path / "a.tsv")
    write_tsv(frame, tmp_path / "b.tsv")
    assert (tmp_path / "a.tsv").read_bytes() == (tmp_path / "b.tsv").read_bytes()
    assert (tmp_path / "a.tsv").read_text() == "time_s\tflag\tx\n0\tTrue\t\n0.333333333\tFalse\t2.5e-07\n"


def _pandas_tsv(frame: pd.DataFrame, float_format: str) -> bytes:
    return frame.to_csv(sep="\t", index=False, float_format=float_format, na_rep="", lineterminator="\n").encode()


@pytest.mark.parametrize("float_format", ["%.9g", "%.12g", "%.4f"])
def test_tsv_writer_of_numeric_tables_writes_pandas_own_bytes(tmp_path, float_format, rng):
    """Tables of float64 and int64 columns are formatted by the writer itself: the bytes must stay pandas'."""
    n = 2_000
    frame = pd.DataFrame(
        {
            "time_s": np.arange(n) / 1024,
            "force_N": rng.normal(0, 100, n),
            "frame": np.arange(n, dtype=np.int64) - 7,
            "tiny": rng.normal(0, 1e-9, n),
        }
    )
    frame.loc[[3, 9], "force_N"] = np.nan
    frame.loc[4, "tiny"], frame.loc[5, "tiny"], frame.loc[6, "tiny"] = -0.0, np.inf, -np.inf
    frame.loc[7, "force_N"], frame.loc[8, "force_N"] = 1e-300, 1e300
    cases = {
        "numeric": frame,
        "numbered columns": frame.set_axis(range(frame.shape[1]), axis=1),
        "a lone column": frame[["force_N"]],  # pandas quotes its empty cells
        "a text column": frame.assign(side="left"),
        "a float32 column": frame.astype({"tiny": np.float32}),
        "a quoted name": frame.rename(columns={"tiny": 'a "b"'}),
        "no rows": frame.iloc[:0],
    }
    for name, table in cases.items():
        write_tsv(table, tmp_path / "t.tsv", float_format)
        assert (tmp_path / "t.tsv").read_bytes() == _pandas_tsv(table, float_format), name


def test_figure_writer_leaves_no_partial_png_when_rendering_fails(tmp_path):
    target = tmp_path / "fit.png"
    figure = pyplot().figure()
    figure.gca().set_title(r"$\frac{1}{$")  # invalid mathtext: fails only when the figure is drawn
    with pytest.raises(ValueError):
        write_figure(figure, target)
    assert _entries(tmp_path) == []
    assert not pyplot().fignum_exists(figure.number)  # closed although it failed


def test_figure_writer_gives_the_same_bytes_for_the_same_figure(tmp_path):
    for name in ("a.png", "b.png"):
        figure = pyplot().figure(figsize=(2, 2))
        figure.gca().plot([0, 1], [1, 0])
        write_figure(figure, tmp_path / name)
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_yaml_writer_writes_nothing_for_a_document_it_cannot_represent(tmp_path):
    target = tmp_path / "truth.yaml"
    target.write_text("old: 1\n")
    with pytest.raises(Exception, match="cannot represent"):
        write_yaml(target, {"subject": "S01", "bad": object()})
    assert target.read_text() == "old: 1\n"
    assert _entries(tmp_path) == ["truth.yaml"]


def test_text_and_bytes_writers_replace_the_whole_file(tmp_path):
    target = tmp_path / "notes.md"
    write_text(target, "a much longer first version\n")
    write_bytes(target, b"short\n")
    assert target.read_bytes() == b"short\n"


def test_trc_writer_refuses_before_writing_and_leaves_no_file(tmp_path):
    target = tmp_path / "walk.trc"
    with pytest.raises(LoperInputError, match="walk.trc: .*infinite"):
        write_trc(target, [0.0, 0.01], np.array([[[0.0, 0.0, np.inf]], [[0.0, 0.0, 0.0]]]), ["LASI"])
    assert _entries(tmp_path) == []


def test_mot_writer_keeps_the_old_file_when_a_column_is_not_numeric(tmp_path):
    target = tmp_path / "walk.mot"
    write_mot(target, pd.DataFrame({"time_s": [0.0, 0.01], "hip_flexion_l": [0.1, 0.2]}))
    old = target.read_bytes()
    with pytest.raises(LoperInputError, match="walk.mot: column 'hip_flexion_l' is not numeric"):
        write_mot(target, pd.DataFrame({"time_s": [0.0, 0.01], "hip_flexion_l": ["a", "b"]}))
    assert target.read_bytes() == old
    assert _entries(tmp_path) == ["walk.mot"]


def test_c3d_writer_refuses_a_label_ezc3d_cannot_read_back_and_leaves_no_file(tmp_path):
    target = tmp_path / "static.c3d"
    # ezc3d writes a label of 256 characters into a file it cannot read back, so the writer refuses it up front
    with pytest.raises(LoperInputError, match="static.c3d: marker_labels"):
        write_c3d(target, ["x" * 256], np.zeros((2, 1, 3)), 128.0)
    assert _entries(tmp_path) == []


class _HalfWrittenModel:
    """An object that prints half a model file and then fails, as OpenSim does when the disk fills."""

    def printToXML(self, path):
        with open(path, "w") as fh:
            fh.write("<OpenSimDocument>")
        raise RuntimeError("disk full")


def test_model_writer_leaves_no_partial_osim(tmp_path):
    target = tmp_path / "scaled.osim"
    with pytest.raises(RuntimeError, match="disk full"):
        write_model(_HalfWrittenModel(), target)
    assert _entries(tmp_path) == []


def test_robot_log_writer_refuses_bad_data_before_writing(tmp_path):
    target = tmp_path / "trial.loper.tsv"
    frame = pd.DataFrame(
        {
            "time_s": [0.0, 0.001],
            "force_desired_n": [0.0, np.nan],
            "force_measured_n": [0.0, 0.0],
            "motor_angle_rad": 0.0,
            "motor_velocity_rad_s": 0.0,
            "sync_v": 0.0,
            "perturbation": 0,
            "safety_state": 0,
        }
    )
    with pytest.raises(LoperInputError, match="force_desired_n"):
        write_robot_log(target, frame, 1000.0)
    assert _entries(tmp_path) == []
