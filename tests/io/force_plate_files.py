"""Small C3D files with one force platform, built from a known point load.

The files are written by ezc3d in a child process (ezc3d writing and
OpenSim's wrapper must not share a process). The channel values come from
the physics, independently of any reader:

* plate frame (C3D corner convention): x = corner1 - corner2, y = corner1 -
  corner4, z = x cross y, here x = lab x, y = lab -y, z = lab -z (down);
* ``ORIGIN`` = sensor origin minus surface centre, plate frame (z > 0: the
  sensor lies below the surface);
* channels hold the force on the body and its moment about the sensor
  origin, plate frame (the sign of Vicon's walking5.c3d).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

__all__ = ["R_PLATE_TO_LAB", "channels_for_load", "plate_corners_mm", "type3_channels", "write_plate_c3d"]

#: Plate -> lab rotation of the files built here (columns: plate x, y, z in the lab).
R_PLATE_TO_LAB = np.diag([1.0, -1.0, -1.0])


def plate_corners_mm(centre_mm=(300.0, 200.0, 0.0), half_x_mm: float = 250.0, half_y_mm: float = 200.0) -> np.ndarray:
    """(4, 3) lab corners in C3D order (plate (+x,+y), (-x,+y), (-x,-y), (+x,-y)) of a level plate."""
    c = np.asarray(centre_mm, dtype=float)
    plate = np.array([[1, 1, 0], [-1, 1, 0], [-1, -1, 0], [1, -1, 0]], dtype=float) * [half_x_mm, half_y_mm, 0.0]
    return c + plate @ R_PLATE_TO_LAB.T


def channels_for_load(force_n, point_mm, free_moment_nmm: float, centre_mm, origin_mm) -> np.ndarray:
    """Six channels [F; M] (plate frame; N, N·mm about the sensor origin) of a load on the body.

    ``force_n`` (3,) lab, applied at ``point_mm`` (3,) lab on the surface, plus a
    free moment about lab +z; ``origin_mm`` is ``FORCE_PLATFORM:ORIGIN``.
    """
    F = np.asarray(force_n, dtype=float)
    sensor = np.asarray(centre_mm, dtype=float) + R_PLATE_TO_LAB @ np.asarray(origin_mm, dtype=float)
    M = np.cross(np.asarray(point_mm, dtype=float) - sensor, F) + np.array([0.0, 0.0, free_moment_nmm])
    return np.r_[R_PLATE_TO_LAB.T @ F, R_PLATE_TO_LAB.T @ M]


def type3_channels(
    force_n, point_mm, free_moment_nmm: float, centre_mm, a_mm: float, b_mm: float, depth_mm: float
) -> np.ndarray:
    """Eight Kistler channels (fx12, fx34, fy14, fy23, fz1..fz4) of a load; sensors at plate (+-a, +-b, depth).

    Sensors 1, 2 at plate y = +b, sensors 1, 4 at plate x = +a; the vertical
    forces are the least-norm split that reproduces the resultant.
    """
    F = R_PLATE_TO_LAB.T @ np.asarray(force_n, dtype=float)
    p = R_PLATE_TO_LAB.T @ (np.asarray(point_mm, dtype=float) - np.asarray(centre_mm, dtype=float))
    origin = np.array([0.0, 0.0, depth_mm])
    M = np.cross(p - origin, F) + R_PLATE_TO_LAB.T @ np.array([0.0, 0.0, free_moment_nmm])
    xs = np.array([a_mm, -a_mm, -a_mm, a_mm])
    ys = np.array([b_mm, b_mm, -b_mm, -b_mm])
    A = np.vstack([np.ones(4), ys, -xs])
    fz = np.linalg.lstsq(A, np.array([F[2], M[0], M[1]]), rcond=None)[0]
    fy14 = fy23 = F[1] / 2.0
    # Mz = b (fx34 - fx12) + a (fy14 - fy23), fx12 + fx34 = Fx
    diff = M[2] / b_mm
    fx34 = (F[0] + diff) / 2.0
    fx12 = F[0] - fx34
    return np.r_[fx12, fx34, fy14, fy23, fz]


_CHILD = r"""
import json, sys
import numpy as np
import ezc3d

spec = json.loads(open(sys.argv[1]).read())
arrays = np.load(sys.argv[2])

def int_param(c, group, name, values):
    values = np.asarray(values, dtype=int)
    c.add_parameter(group, name, values.astype(float))
    c["parameters"][group][name]["value"] = values
    c["parameters"][group][name]["type"] = ezc3d.ezc3d.INT

analogs = arrays["analogs"]  # (n_channels, n_samples)
ratio = spec["ratio"]
n_frames = analogs.shape[1] // ratio
c = ezc3d.c3d()
c["parameters"]["POINT"]["RATE"]["value"] = [spec["point_rate"]]
c["parameters"]["POINT"]["LABELS"]["value"] = ["M1"]
c.add_parameter("POINT", "UNITS", [spec["point_units"]])
c["data"]["points"] = np.ones((4, 1, n_frames))
c["parameters"]["ANALOG"]["RATE"]["value"] = [spec["point_rate"] * ratio]
c["parameters"]["ANALOG"]["LABELS"]["value"] = spec["labels"]
c["parameters"]["ANALOG"]["UNITS"]["value"] = spec["units"]
c["data"]["analogs"] = analogs[np.newaxis]
if spec["group"]:
    int_param(c, "FORCE_PLATFORM", "USED", [spec["used"]])
    int_param(c, "FORCE_PLATFORM", "TYPE", [spec["type"]])
    int_param(c, "FORCE_PLATFORM", "CHANNEL", np.asarray(spec["channel"])[:, None])
    c.add_parameter("FORCE_PLATFORM", "CORNERS", arrays["corners"].T[:, :, None])
    c.add_parameter("FORCE_PLATFORM", "ORIGIN", np.asarray(spec["origin"], float)[:, None])
    if "cal" in arrays:
        c.add_parameter("FORCE_PLATFORM", "CAL_MATRIX", arrays["cal"][:, :, None])
c.write(spec["out"])
"""


def write_plate_c3d(
    path,
    analogs,
    *,
    plate_type: int = 2,
    channel=None,
    corners_mm=None,
    origin_mm=(0.0, 0.0, 40.0),
    cal=None,
    used: int = 1,
    group: bool = True,
    labels=None,
    units=None,
    point_rate: float = 100.0,
    ratio: int = 10,
    point_units: str = "mm",
) -> Path:
    """Write a C3D with one force platform; ``analogs`` is (n_samples, n_channels), n_samples a multiple of
    ``ratio``."""
    path = Path(path)
    A = np.asarray(analogs, dtype=float)
    n_channels = A.shape[1]
    spec = {
        "out": str(path),
        "ratio": int(ratio),
        "point_rate": float(point_rate),
        "point_units": point_units,
        "labels": list(labels or [f"ch{i + 1}" for i in range(n_channels)]),
        "units": list(units or ["N"] * n_channels),
        "group": bool(group),
        "used": int(used),
        "type": int(plate_type),
        "channel": list(channel or range(1, (8 if plate_type == 3 else 6) + 1)),
        "origin": list(map(float, origin_mm)),
    }
    arrays = {"analogs": A.T, "corners": plate_corners_mm() if corners_mm is None else np.asarray(corners_mm, float)}
    if cal is not None:
        arrays["cal"] = np.asarray(cal, dtype=float)
    spec_path = path.with_suffix(".json")
    arrays_path = path.with_suffix(".npz")
    spec_path.write_text(json.dumps(spec))
    np.savez(arrays_path, **arrays)
    proc = subprocess.run(
        [sys.executable, "-c", _CHILD, str(spec_path), str(arrays_path)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    if proc.returncode != 0:
        raise RuntimeError(f"writing {path} failed:\n{proc.stderr}")
    spec_path.unlink()
    arrays_path.unlink()
    return path
