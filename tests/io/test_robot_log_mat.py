"""Robot logs exported from MATLAB (io/robot_log_mat.py): the .mat reader against the TSV format, and its refusals."""

import numpy as np
import pandas as pd
import pytest
from scipy.io import savemat

from loper_analysis.errors import LoperInputError
from loper_analysis.io.robot_log import (
    COLUMNS,
    FORMAT_NAME,
    read_robot_log,
    write_robot_log,
)
from loper_analysis.io.robot_log_mat import read_robot_log_mat
from tests.io.robot_log_frames import FS, N, make_frame, rounded

# ---------------------------------------------------------------------------
# round trips


def test_mat_round_trip_equals_tsv_content(tmp_path):
    tsv = tmp_path / "rec.loper.tsv"
    original = make_frame()
    original[["sync_v", "perturbation", "safety_state"]] = 0
    write_robot_log(tsv, original, FS, {"trial": "rec"})
    expected, _ = read_robot_log(tsv)

    mat = tmp_path / "rec.mat"
    savemat(
        mat,
        {
            "t": (1e3 * expected["time_s"].to_numpy())[np.newaxis, :],  # (1, n), milliseconds
            "Fd": expected["force_desired_n"].to_numpy()[:, np.newaxis],  # (n, 1)
            "Fm": expected["force_measured_n"].to_numpy()[np.newaxis, :],
            "theta": expected["motor_angle_rad"].to_numpy()[:, np.newaxis],
            "omega": expected["motor_velocity_rad_s"].to_numpy(),  # 1-D: savemat stores (1, n)
        },
    )
    cmap = {
        "time_s": "t",
        "force_desired_n": "Fd",
        "force_measured_n": "Fm",
        "motor_angle_rad": "theta",
        "motor_velocity_rad_s": "omega",
        "sync_v": None,
        "perturbation": None,
        "safety_state": None,
    }
    frame, meta = read_robot_log_mat(mat, cmap, FS, time_scale=0.001)
    assert meta == {"format": FORMAT_NAME, "sample_rate_hz": 1000.0, "source": str(mat)}
    assert list(frame.columns) == list(COLUMNS)
    assert frame["perturbation"].dtype == np.int64 and frame["safety_state"].dtype == np.int64
    pd.testing.assert_frame_equal(frame.drop(columns="time_s"), expected.drop(columns="time_s"), check_exact=True)
    np.testing.assert_allclose(frame["time_s"], expected["time_s"], rtol=1e-15, atol=0)
    # written back: byte for byte the TSV it came from
    back = tmp_path / "from_mat.loper.tsv"
    write_robot_log(back, frame, FS, {"trial": "rec"})
    assert back.read_bytes() == tsv.read_bytes()


def test_mat_without_time_and_with_optional_channels(tmp_path):
    frame = rounded(make_frame())
    frame["time_s"] = np.arange(N) / FS
    mat = tmp_path / "rec.mat"
    savemat(
        mat,
        {
            "Fd": frame["force_desired_n"].to_numpy(),
            "Fm": frame["force_measured_n"].to_numpy(),
            "theta": frame["motor_angle_rad"].to_numpy(),
            "omega": frame["motor_velocity_rad_s"].to_numpy(),
            "sync": frame["sync_v"].to_numpy(),
            "pert": frame["perturbation"].to_numpy().astype(np.uint8),
            "safety": frame["safety_state"].to_numpy().astype(np.int32)[:, np.newaxis],
        },
    )
    cmap = {
        "force_desired_n": "Fd",
        "force_measured_n": "Fm",
        "motor_angle_rad": "theta",
        "motor_velocity_rad_s": "omega",
        "sync_v": "sync",
        "perturbation": "pert",
        "safety_state": "safety",
    }
    got, _ = read_robot_log_mat(mat, cmap, FS)
    pd.testing.assert_frame_equal(got, frame, check_exact=True)


# ---------------------------------------------------------------------------
# refusals of the .mat reader


def _mat_frame(tmp_path, **overrides):
    frame = rounded(make_frame())
    variables = {
        "t": frame["time_s"].to_numpy(),
        "Fd": frame["force_desired_n"].to_numpy(),
        "Fm": frame["force_measured_n"].to_numpy(),
        "theta": frame["motor_angle_rad"].to_numpy(),
        "omega": frame["motor_velocity_rad_s"].to_numpy(),
    }
    variables.update(overrides)
    mat = tmp_path / "rec.mat"
    savemat(mat, variables)
    return mat


CMAP = {
    "time_s": "t",
    "force_desired_n": "Fd",
    "force_measured_n": "Fm",
    "motor_angle_rad": "theta",
    "motor_velocity_rad_s": "omega",
    "sync_v": None,
    "perturbation": None,
    "safety_state": None,
}


def mat_refusal(mat, cmap=CMAP, **kwargs) -> str:
    with pytest.raises(LoperInputError) as err:
        read_robot_log_mat(mat, cmap, FS, **kwargs)
    return str(err.value)


def test_mat_missing_variable(tmp_path):
    mat = _mat_frame(tmp_path)
    cmap = {**CMAP, "force_measured_n": "F_load"}
    assert mat_refusal(mat, cmap) == (
        f"{mat}: variable 'F_load' (for column 'force_measured_n') not found; "
        f"variables in the file: Fd, Fm, omega, t, theta"
    )


def test_mat_unequal_lengths(tmp_path):
    mat = _mat_frame(tmp_path, Fm=np.zeros(N - 1), omega=np.zeros((N + 2, 1)))
    assert mat_refusal(mat) == f"{mat}: variables have unequal lengths: t 60, Fd 60, Fm 59, theta 60, omega 62"


def test_mat_validation_is_shared(tmp_path):
    fm = rounded(make_frame())["force_measured_n"].to_numpy().copy()
    fm[[13, 20]] = np.nan
    mat = _mat_frame(tmp_path, Fm=fm)
    assert mat_refusal(mat) == f"{mat}: column 'force_measured_n', sample 13 (t = 12.013 s): non-finite force nan"
    # time in ms read without time_scale: steps of 1000 "s"
    mat = _mat_frame(tmp_path, t=1e3 * np.arange(N) / FS)
    assert mat_refusal(mat) == (
        f"{mat}: column 'time_s', sample 1 (t = 1 s): time step 1000 ms since sample 0 "
        f"deviates +99900 % from 1/sample_rate_hz = 1 ms (tolerance 1 %)"
    )
    mat = _mat_frame(tmp_path, pert=np.full(N, 3.0))
    assert mat_refusal(mat, {**CMAP, "perturbation": "pert"}) == (
        f"{mat}: column 'perturbation', sample 0 (t = 12 s): value 3 is not 0 or 1"
    )


def test_mat_bad_map_and_bad_variables(tmp_path):
    mat = _mat_frame(tmp_path, M=np.ones((N, 3)), name="steps")
    assert mat_refusal(mat, {k: v for k, v in CMAP.items() if k != "force_desired_n"}) == (
        "column_map: column(s) force_desired_n not mapped to a .mat variable"
    )
    assert mat_refusal(mat, {**CMAP, "force_n": "Fd"}) == (
        "column_map: unknown column(s) force_n; columns are "
        + ", ".join((*COLUMNS, "shank_force_desired_n", "shank_force_measured_n"))
    )
    assert mat_refusal(mat, {**CMAP, "force_measured_n": None}) == (
        "column_map: column 'force_measured_n' must map to a .mat variable (only time_s, sync_v, perturbation, "
        "safety_state may be None)"
    )
    assert mat_refusal(mat, {**CMAP, "motor_angle_rad": "M"}) == (
        f"{mat}: variable 'M' (for column 'motor_angle_rad') has shape (60, 3); expected a vector (n,), (n, 1) "
        f"or (1, n)"
    )
    assert mat_refusal(mat, {**CMAP, "motor_angle_rad": "name"}) == (
        f"{mat}: variable 'name' (for column 'motor_angle_rad') is not real numeric (dtype <U5)"
    )
    with pytest.raises(LoperInputError, match=r"^time_scale must be a positive number, got 0$"):
        read_robot_log_mat(mat, CMAP, FS, time_scale=0)
    junk = tmp_path / "junk.mat"
    junk.write_bytes(b"not a mat file at all" * 10)
    assert mat_refusal(junk).startswith(f"{junk}: cannot read .mat file (")


# ---------------------------------------------------------------------------
# the .mat writer


MAT_NAMES = {
    "time_s": "t_ms",
    "force_desired_n": "F_des",
    "force_measured_n": "F_meas",
    "motor_angle_rad": "theta_m",
    "motor_velocity_rad_s": "omega_m",
    "sync_v": "sync",
    "perturbation": "pert",
    "safety_state": "safety",
}


def test_mat_writer_round_trip_and_fixed_bytes(tmp_path):
    from tests.io.robot_log_mat_files import MAT_HEADER_TEXT, write_robot_log_mat

    frame = make_frame()
    mat = write_robot_log_mat(tmp_path / "rec.loper.mat", frame, FS, MAT_NAMES, time_scale=0.001)
    back, meta = read_robot_log_mat(mat, MAT_NAMES, FS, time_scale=0.001)
    assert meta["sample_rate_hz"] == FS
    pd.testing.assert_frame_equal(
        back.drop(columns="time_s"), frame.drop(columns="time_s"), check_exact=True, check_dtype=False
    )
    np.testing.assert_allclose(back["time_s"], frame["time_s"], rtol=1e-15, atol=0)  # ms -> s
    assert mat.read_bytes()[: len(MAT_HEADER_TEXT)] == MAT_HEADER_TEXT.encode()
    again = write_robot_log_mat(tmp_path / "again.loper.mat", frame, FS, MAT_NAMES, time_scale=0.001)
    assert again.read_bytes() == mat.read_bytes()
    plain = write_robot_log_mat(tmp_path / "plain.mat", frame, FS)  # the column names as variable names
    got, _ = read_robot_log_mat(plain, {c: c for c in COLUMNS}, FS)
    pd.testing.assert_frame_equal(got, frame, check_exact=True, check_dtype=False)


@pytest.mark.parametrize(
    "names, match",
    [
        ({**MAT_NAMES, "sync_v": "2sync"}, "is not a MATLAB name"),
        ({k: v for k, v in MAT_NAMES.items() if k != "sync_v"}, "missing: sync_v"),
        ({**MAT_NAMES, "sync_v": "pert"}, "all different"),
    ],
)
def test_mat_writer_refuses_bad_names_and_leaves_nothing(tmp_path, names, match):
    from tests.io.robot_log_mat_files import write_robot_log_mat

    with pytest.raises(LoperInputError, match=match):
        write_robot_log_mat(tmp_path / "rec.mat", make_frame(), FS, names)
    assert list(tmp_path.iterdir()) == []


def test_mat_with_a_second_rods_load_cell(tmp_path):
    """The shank rod's two variables, mapped, come back as the log's last two columns with their values; one of
    them mapped alone is refused naming the other."""
    rng = np.random.default_rng(5)
    desired, measured = 30.0 * rng.random(N), rng.random(N)
    mat = _mat_frame(tmp_path, Fsd=desired, Fsm=measured)
    cmap = {**CMAP, "shank_force_desired_n": "Fsd", "shank_force_measured_n": "Fsm"}
    frame, _ = read_robot_log_mat(mat, cmap, FS)
    assert tuple(frame.columns[-2:]) == ("shank_force_desired_n", "shank_force_measured_n")
    np.testing.assert_array_equal(frame["shank_force_desired_n"], desired)
    np.testing.assert_array_equal(frame["shank_force_measured_n"], measured)
    plain, _ = read_robot_log_mat(mat, {**CMAP, "shank_force_desired_n": None}, FS)
    assert tuple(plain.columns) == COLUMNS
    assert mat_refusal(mat, {**CMAP, "shank_force_measured_n": "Fsm"}) == (
        "column_map: column 'shank_force_measured_n' is mapped but 'shank_force_desired_n' is not: a second rod's "
        "load cell needs both"
    )
