"""The robot (LOPER) log format ``loper-log 1`` (io/robot_log.py): writer, TSV reader and every refusal."""

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.robot_log import (
    COLUMNS,
    FORMAT_NAME,
    SAFETY_STATES,
    SHANK_COLUMNS,
    UNITS,
    read_robot_log,
    write_robot_log,
)
from tests.io.robot_log_frames import FS, N, make_frame, rounded

#: Data rows start after '# format', '# sample_rate_hz', '# trial' and the column row.
FIRST_LINE = 5


@pytest.fixture
def log_file(tmp_path):
    path = tmp_path / "good.loper.tsv"
    write_robot_log(path, make_frame(), FS, {"trial": "steps40"})
    return path


def with_cell(log_file, sample: int, column: str, text: str):
    """A copy of the log with one cell replaced (named bad.loper.tsv)."""
    lines = log_file.read_text().splitlines()
    cells = lines[FIRST_LINE - 1 + sample].split("\t")
    cells[COLUMNS.index(column)] = text
    lines[FIRST_LINE - 1 + sample] = "\t".join(cells)
    bad = log_file.with_name("bad.loper.tsv")
    bad.write_text("\n".join(lines) + "\n")
    return bad


def with_lines(log_file, lines):
    bad = log_file.with_name("bad.loper.tsv")
    bad.write_text("\n".join(lines) + "\n")
    return bad


def refusal(path, **kwargs) -> str:
    with pytest.raises(LoperInputError) as err:
        read_robot_log(path, **kwargs)
    return str(err.value)


# ---------------------------------------------------------------------------
# constants

#: What the refusals add about a second rod's load cell.
MISSING_TAIL = ", and a robot with a second rod at the shank also shank_force_desired_n and shank_force_measured_n"
UNKNOWN_TAIL = " (and, with a second rod at the shank, shank_force_desired_n and shank_force_measured_n)"


def test_constants():
    assert FORMAT_NAME == "loper-log 1"
    assert COLUMNS == (
        "time_s",
        "force_desired_n",
        "force_measured_n",
        "motor_angle_rad",
        "motor_velocity_rad_s",
        "sync_v",
        "perturbation",
        "safety_state",
    )
    assert UNITS == {
        "time_s": "s",
        "force_desired_n": "N",
        "force_measured_n": "N",
        "motor_angle_rad": "rad",
        "motor_velocity_rad_s": "rad/s",
        "sync_v": "V",
        "perturbation": "1",
        "safety_state": "1",
        "shank_force_desired_n": "N",
        "shank_force_measured_n": "N",
    }
    assert SHANK_COLUMNS == ("shank_force_desired_n", "shank_force_measured_n")
    assert SAFETY_STATES == {
        0: "ok",
        1: "limited",
        2: "motor_off_position",
        3: "motor_off_velocity",
        4: "motor_off_torque",
        5: "servo_off_position",
    }


# ---------------------------------------------------------------------------
# round trips


def test_round_trip_exact_to_written_precision_and_same_bytes(tmp_path, log_file):
    head = log_file.read_text().splitlines()[:6]
    assert head[:4] == ["# format: loper-log 1", "# sample_rate_hz: 1000", "# trial: steps40", "\t".join(COLUMNS)]
    assert head[4].split("\t")[0] == "12" and head[5].split("\t")[0] == "12.001"
    frame, meta = read_robot_log(log_file, FS)
    assert list(frame.columns) == list(COLUMNS)
    assert frame.dtypes.to_dict() == {
        **{c: np.dtype("float64") for c in COLUMNS[:6]},
        "perturbation": np.dtype("int64"),
        "safety_state": np.dtype("int64"),
    }
    assert frame.index.equals(pd.RangeIndex(N))
    pd.testing.assert_frame_equal(frame, rounded(make_frame()), check_exact=True)
    # values differ from the originals by at most the printed precision
    np.testing.assert_allclose(frame["force_measured_n"], make_frame()["force_measured_n"], rtol=5e-9, atol=0)
    # the same data give the same bytes, from the original frame and from what was read back
    again = tmp_path / "again.loper.tsv"
    write_robot_log(again, make_frame(), FS, {"trial": "steps40"})
    assert again.read_bytes() == log_file.read_bytes()
    write_robot_log(again, frame, FS, meta)
    assert again.read_bytes() == log_file.read_bytes()


def test_metadata_round_trip(tmp_path):
    path = tmp_path / "meta.loper.tsv"
    write_robot_log(
        path,
        make_frame(),
        1000,
        {"trial": "steps40", "clock": "robot", "operator": "A. B: lab 2", "n_steps": 40, "note": ""},
    )
    _, meta = read_robot_log(path)
    assert meta == {
        "format": "loper-log 1",
        "sample_rate_hz": 1000.0,
        "trial": "steps40",
        "clock": "robot",
        "operator": "A. B: lab 2",
        "n_steps": "40",
        "note": "",
    }
    assert list(meta) == ["format", "sample_rate_hz", "trial", "clock", "operator", "n_steps", "note"]
    assert isinstance(meta["sample_rate_hz"], float)


def test_missing_motor_samples_round_trip_as_nan(tmp_path):
    frame = make_frame()
    frame.loc[7, "motor_angle_rad"] = np.nan
    frame.loc[8, "sync_v"] = np.nan
    path = tmp_path / "gap.loper.tsv"
    write_robot_log(path, frame)
    back, _ = read_robot_log(path)
    assert np.isnan(back.loc[7, "motor_angle_rad"]) and np.isnan(back.loc[8, "sync_v"])
    assert np.isnan(back["motor_angle_rad"]).sum() == 1
    assert path.read_text().splitlines()[FIRST_LINE - 2 + 7].split("\t")[3] == "nan"


# ---------------------------------------------------------------------------
# refusals of the TSV reader


def test_not_a_loper_log(tmp_path):
    plain = tmp_path / "plain.tsv"
    make_frame().to_csv(plain, sep="\t", index=False)
    assert refusal(plain) == f"{plain}: not a loper log: no '# format: loper-log 1' header line"
    empty = tmp_path / "empty.loper.tsv"
    empty.write_text("")
    assert refusal(empty) == f"{empty}: not a loper log: no '# format: loper-log 1' header line"


def test_missing_format_line_and_other_format(log_file):
    lines = log_file.read_text().splitlines()
    bad = with_lines(log_file, lines[1:])
    assert refusal(bad) == f"{bad}: not a loper log: no '# format: loper-log 1' header line"
    bad = with_lines(log_file, ["# format: loper-log 2"] + lines[1:])
    assert refusal(bad) == f"{bad}: unsupported format 'loper-log 2'; this reader reads 'loper-log 1'"
    bad = with_lines(log_file, lines[:1] + lines[2:])
    assert refusal(bad) == f"{bad}: no '# sample_rate_hz: ...' header line"


def test_missing_columns_are_named(log_file):
    lines = [line.split("\t") for line in log_file.read_text().splitlines()]
    keep = [j for j, c in enumerate(COLUMNS) if c not in ("force_measured_n", "sync_v")]
    bad = with_lines(log_file, ["\t".join(r) if r[0].startswith("#") else "\t".join(r[j] for j in keep) for r in lines])
    assert refusal(bad) == (
        f"{bad}: missing column(s) force_measured_n, sync_v; a robot log has the columns "
        + ", ".join(COLUMNS)
        + MISSING_TAIL
    )


def test_unknown_columns_are_refused(log_file):
    lines = log_file.read_text().splitlines()
    lines[FIRST_LINE - 2] += "\ttemperature_c\tnote"
    for i in range(FIRST_LINE - 1, len(lines)):
        lines[i] += "\t21.5\tx"
    bad = with_lines(log_file, lines)
    assert refusal(bad) == (
        f"{bad}: unknown column(s) temperature_c, note; a robot log has exactly the columns "
        + ", ".join(COLUMNS)
        + UNKNOWN_TAIL
    )
    lines = log_file.read_text().splitlines()
    lines[FIRST_LINE - 2] += "\t"
    bad = with_lines(log_file, lines)
    assert (
        refusal(bad)
        == f"{bad}: unknown column(s) ''; a robot log has exactly the columns " + ", ".join(COLUMNS) + UNKNOWN_TAIL
    )


def test_reordered_columns_are_refused(log_file):
    lines = [line.split("\t") for line in log_file.read_text().splitlines()]
    bad = with_lines(
        log_file, ["\t".join(r) if r[0].startswith("#") else "\t".join([r[1], r[0], *r[2:]]) for r in lines]
    )
    assert refusal(bad) == (
        f"{bad}: line 4: columns in the order force_desired_n, time_s, "
        + ", ".join(COLUMNS[2:])
        + "; a robot log has them in the order "
        + ", ".join(COLUMNS)
    )


def test_non_numeric_cell_names_column_and_sample(log_file):
    bad = with_cell(log_file, 17, "force_measured_n", "12.3N")
    assert refusal(bad) == (
        f"{bad}: column 'force_measured_n', sample 17 (t = 12.017 s, line 22): non-numeric value '12.3N'"
    )
    bad = with_cell(log_file, 3, "safety_state", "")
    assert refusal(bad) == f"{bad}: column 'safety_state', sample 3 (t = 12.003 s, line 8): non-numeric value ''"
    bad = with_cell(log_file, 4, "time_s", "t4")
    assert refusal(bad) == f"{bad}: column 'time_s', sample 4 (line 9): non-numeric value 't4'"


def test_ragged_row(log_file):
    lines = log_file.read_text().splitlines()
    lines[FIRST_LINE - 1 + 9] = lines[FIRST_LINE - 1 + 9].rsplit("\t", 1)[0]
    bad = with_lines(log_file, lines)
    assert refusal(bad) == f"{bad}: sample 9 (line 14): 7 field(s), expected 8 (one per column)"


def test_blank_line_inside_the_data(log_file):
    lines = log_file.read_text().splitlines()
    bad = with_lines(log_file, lines[: FIRST_LINE - 1 + 6] + [""] + lines[FIRST_LINE - 1 + 6 :])
    assert refusal(bad) == f"{bad}: sample 6 (line 11): 1 field(s), expected 8 (one per column)"


def test_non_finite_time(log_file):
    bad = with_cell(log_file, 2, "time_s", "nan")
    assert refusal(bad) == f"{bad}: column 'time_s', sample 2 (t = nan s, line 7): non-finite time nan"


def test_non_monotonic_time_names_the_sample(log_file):
    bad = with_cell(log_file, 30, "time_s", "12.029")
    assert refusal(bad) == (
        f"{bad}: column 'time_s', sample 30 (t = 12.029 s, line 35): time not strictly "
        f"increasing (sample 29 is at t = 12.029 s)"
    )
    bad = with_cell(log_file, 30, "time_s", "12.01")
    assert refusal(bad) == (
        f"{bad}: column 'time_s', sample 30 (t = 12.01 s, line 35): time not strictly "
        f"increasing (sample 29 is at t = 12.029 s)"
    )


def test_sample_rate_differs_from_declared(log_file):
    assert refusal(log_file, sample_rate_hz=500) == (
        f"{log_file}: sample_rate_hz in the file is 1000 Hz but 500 Hz was declared"
    )
    assert read_robot_log(log_file, sample_rate_hz=1000)[1]["sample_rate_hz"] == 1000.0


def test_time_steps_inconsistent_with_header_rate(log_file):
    bad = with_cell(log_file, 12, "time_s", "12.0122")  # 1.2 ms after sample 11
    assert refusal(bad) == (
        f"{bad}: column 'time_s', sample 12 (t = 12.0122 s, line 17): time step 1.2 ms since "
        f"sample 11 deviates +20 % from 1/sample_rate_hz = 1 ms (tolerance 1 %)"
    )
    # 0.9 % is within the tolerance
    ok = with_cell(log_file, 12, "time_s", "12.012009")
    assert read_robot_log(ok)[0].loc[12, "time_s"] == 12.012009
    # a whole file at 500 Hz declared as 1000 Hz: the first step is named
    lines = log_file.read_text().splitlines()
    lines[1] = "# sample_rate_hz: 500"
    bad = with_lines(log_file, lines)
    assert refusal(bad) == (
        f"{bad}: column 'time_s', sample 1 (t = 12.001 s, line 6): time step 1 ms since "
        f"sample 0 deviates -50 % from 1/sample_rate_hz = 2 ms (tolerance 1 %)"
    )


@pytest.mark.parametrize(
    "column, sample, text",
    [
        ("force_desired_n", 0, "nan"),
        ("force_measured_n", 41, "inf"),
        ("force_measured_n", 5, "-inf"),
    ],
)
def test_non_finite_force_names_column_and_first_bad_sample(log_file, column, sample, text):
    bad = with_cell(log_file, sample, column, text)
    lines = bad.read_text().splitlines()
    later = lines[FIRST_LINE + sample].split("\t")  # a second bad sample after the first
    later[COLUMNS.index(column)] = "nan"
    lines[FIRST_LINE + sample] = "\t".join(later)
    bad.write_text("\n".join(lines) + "\n")
    t = f"{12 + sample / 1000:.9g}"
    assert refusal(bad) == (
        f"{bad}: column '{column}', sample {sample} (t = {t} s, line {FIRST_LINE + sample}): "
        f"non-finite force {float(text)}"
    )


def test_infinite_motor_channel(log_file):
    bad = with_cell(log_file, 2, "motor_velocity_rad_s", "inf")
    assert refusal(bad) == (
        f"{bad}: column 'motor_velocity_rad_s', sample 2 (t = 12.002 s, line 7): infinite value "
        f"inf (missing samples are nan)"
    )


def test_fewer_than_two_samples(log_file):
    lines = log_file.read_text().splitlines()
    bad = with_lines(log_file, lines[:FIRST_LINE])
    assert refusal(bad) == f"{bad}: 1 sample(s); a robot log needs at least 2"
    bad = with_lines(log_file, lines[: FIRST_LINE - 1])
    assert refusal(bad) == f"{bad}: 0 sample(s); a robot log needs at least 2"
    bad = with_lines(log_file, lines[: FIRST_LINE - 2])
    assert refusal(bad) == f"{bad}: no column header row after the '#' header lines"


@pytest.mark.parametrize("text, shown", [("2", "2"), ("0.5", "0.5"), ("-1", "-1"), ("nan", "nan")])
def test_perturbation_not_0_or_1(log_file, text, shown):
    bad = with_cell(log_file, 23, "perturbation", text)
    assert refusal(bad) == (
        f"{bad}: column 'perturbation', sample 23 (t = 12.023 s, line 28): value {shown} is not 0 or 1"
    )


def test_unknown_safety_state(log_file):
    bad = with_cell(log_file, 8, "safety_state", "6")
    assert refusal(bad) == (
        f"{bad}: column 'safety_state', sample 8 (t = 12.008 s, line 13): unknown safety state 6 "
        f"(codes: 0 ok, 1 limited, 2 motor_off_position, 3 motor_off_velocity, "
        f"4 motor_off_torque, 5 servo_off_position)"
    )


def test_unreadable_file(tmp_path):
    missing = tmp_path / "none.loper.tsv"
    assert refusal(missing).startswith(f"{missing}: cannot read robot log (")
    latin = tmp_path / "latin.loper.tsv"
    latin.write_bytes(b"# format: loper-log 1\n# caf\xe9\n")
    assert refusal(latin).startswith(f"{latin}: not a loper log: not UTF-8 text (")


def test_malformed_and_repeated_header_lines(log_file):
    lines = log_file.read_text().splitlines()
    bad = with_lines(log_file, lines[:2] + ["# just a remark"] + lines[2:])
    assert refusal(bad) == f"{bad}: line 3: header line must be '# key: value', found '# just a remark'"
    bad = with_lines(log_file, lines[:2] + ["# trial: again"] + lines[2:])
    assert refusal(bad) == f"{bad}: line 4: header key 'trial' repeated"
    bad = with_lines(log_file, [lines[0], "# sample_rate_hz: fast"] + lines[2:])
    assert refusal(bad) == f"{bad}: header sample_rate_hz must be a positive number, got 'fast'"


# ---------------------------------------------------------------------------
# the writer


def test_failed_write_leaves_no_file(tmp_path):
    frame = make_frame()
    frame.loc[4, "force_measured_n"] = np.nan
    path = tmp_path / "S01" / "steps40.loper.tsv"
    path.parent.mkdir()
    with pytest.raises(LoperInputError) as err:
        write_robot_log(path, frame)
    assert str(err.value) == (
        f"refusing to write {path}: column 'force_measured_n', sample 4 (t = 12.004 s): non-finite force nan"
    )
    assert list(path.parent.iterdir()) == []


def test_failed_overwrite_keeps_the_old_file(tmp_path, log_file):
    before = log_file.read_bytes()
    frame = make_frame()
    frame.loc[10, "time_s"] = frame.loc[9, "time_s"]
    with pytest.raises(LoperInputError, match=r"column 'time_s', sample 10 \(t = 12\.009 s\): time not strictly"):
        write_robot_log(log_file, frame)
    assert log_file.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["good.loper.tsv"]


def test_failed_io_leaves_no_temporary_file(tmp_path):
    target = tmp_path / "dir.loper.tsv"
    target.mkdir()  # os.replace of a file onto a directory fails
    with pytest.raises(LoperInputError, match="cannot write robot log") as err:  # the OSError, wrapped
        write_robot_log(target, make_frame())
    assert str(err.value).startswith(f"{target}: ")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dir.loper.tsv"]
    assert list(target.iterdir()) == []


def test_writer_creates_a_missing_directory(tmp_path, log_file):
    path = tmp_path / "S01" / "steps40.loper.tsv"
    write_robot_log(path, make_frame(), FS, {"trial": "steps40"})
    assert path.read_bytes() == log_file.read_bytes()
    assert [p.name for p in path.parent.iterdir()] == ["steps40.loper.tsv"]  # no staging file left


def test_writer_refuses_what_the_reader_refuses(tmp_path):
    path = tmp_path / "w.loper.tsv"
    src = f"refusing to write {path}"

    def message(frame, rate=FS, metadata=None):
        with pytest.raises(LoperInputError) as err:
            write_robot_log(path, frame, rate, metadata)
        assert not path.exists()
        return str(err.value)

    frame = make_frame()
    assert message(frame.drop(columns=["sync_v"])) == (
        f"{src}: missing column(s) sync_v; a robot log has the columns " + ", ".join(COLUMNS) + MISSING_TAIL
    )
    assert message(frame.assign(extra=1.0)) == (
        f"{src}: unknown column(s) extra; a robot log has exactly the columns " + ", ".join(COLUMNS) + UNKNOWN_TAIL
    )
    assert message(frame.iloc[:1]) == f"{src}: 1 sample(s); a robot log needs at least 2"
    assert message(frame, rate=500) == (
        f"{src}: column 'time_s', sample 1 (t = 12.001 s): time step 1 ms since sample 0 deviates -50 % from "
        f"1/sample_rate_hz = 2 ms (tolerance 1 %)"
    )
    assert message(frame, rate=-1) == f"{src}: sample_rate_hz must be a positive number, got -1"
    assert message(frame.assign(perturbation=2)) == (
        f"{src}: column 'perturbation', sample 0 (t = 12 s): value 2 is not 0 or 1"
    )
    assert message(frame.assign(sync_v=["5V"] * N)) == (
        f"{src}: column 'sync_v', sample 0 (t = 12 s): non-numeric value '5V'"
    )
    assert message(frame, metadata={"bad key": "x"}) == (
        f"{src}: metadata key 'bad key' must match [A-Za-z_][A-Za-z0-9_.-]*"
    )
    assert message(frame, metadata={"note": "two\nlines"}) == (
        f"{src}: metadata value of 'note' must be one line without leading or trailing whitespace, got 'two\\nlines'"
    )
    assert message(frame, metadata={"sample_rate_hz": 500.0}) == (
        f"{src}: metadata sample_rate_hz 500.0 disagrees with sample_rate_hz 1000"
    )
    assert message(frame, metadata={"format": "loper-log 2"}) == (
        f"{src}: metadata format 'loper-log 2' is not 'loper-log 1'"
    )


def test_writer_accepts_any_column_order_and_index(tmp_path, log_file):
    frame = make_frame()
    shuffled = frame[list(reversed(COLUMNS))].set_axis(np.arange(N) * 3 + 7)
    shuffled["perturbation"] = shuffled["perturbation"].astype(bool)
    path = tmp_path / "shuffled.loper.tsv"
    write_robot_log(path, shuffled, FS, {"trial": "steps40"})
    assert path.read_bytes() == log_file.read_bytes()


def test_reader_accepts_crlf_and_trailing_blank_lines(tmp_path, log_file):
    crlf = tmp_path / "crlf.loper.tsv"
    crlf.write_bytes(log_file.read_bytes().replace(b"\n", b"\r\n") + b"\r\n\r\n")
    a, meta_a = read_robot_log(crlf)
    b, meta_b = read_robot_log(log_file)
    pd.testing.assert_frame_equal(a, b, check_exact=True)
    assert meta_a == meta_b


def test_a_second_rods_load_cell_round_trips_after_the_columns(tmp_path):
    """A log with the shank rod's two columns is written with them after :data:`COLUMNS` and read back to the
    values the file holds; one of them alone is refused naming the other."""
    frame = make_frame()
    rng = np.random.default_rng(3)
    frame = frame.assign(
        shank_force_desired_n=30.0 * rng.random(len(frame)), shank_force_measured_n=rng.random(len(frame))
    )
    path = tmp_path / "two.loper.tsv"
    write_robot_log(path, frame, FS)
    header = [line for line in path.read_text().splitlines() if not line.startswith("#")][0]
    assert tuple(header.split("\t")) == (*COLUMNS, *SHANK_COLUMNS)
    back, _ = read_robot_log(path)
    expected = rounded(frame[list(COLUMNS)]).assign(
        **{c: np.array([float(f"{v:.9g}") for v in frame[c]]) for c in SHANK_COLUMNS}
    )
    pd.testing.assert_frame_equal(back, expected)
    with pytest.raises(LoperInputError, match="missing column.s. shank_force_measured_n"):
        write_robot_log(tmp_path / "half.loper.tsv", frame.drop(columns=["shank_force_measured_n"]), FS)
