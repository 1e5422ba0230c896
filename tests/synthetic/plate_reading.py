"""The load a C3D reader reads from a force platform's six channels: the inverse of
:func:`loper_analysis.synthetic.force_plates.plate_channels`, which the tests check it against."""

from __future__ import annotations

import numpy as np

from loper_analysis.io.c3d import LENGTH_UNITS_PER_M
from loper_analysis.io.c3d_writer import ForcePlatform
from loper_analysis.synthetic.force_plates import plate_frame

__all__ = ["plate_load"]


def plate_load(plate: ForcePlatform, channels, point_unit: str = "mm") -> dict[str, np.ndarray]:
    """Force (n, 3) N, centre of pressure (n, 3) m and free moment (n,) N·m, lab frame, from the six channels
    (n, 6); the centre of pressure is NaN where the normal force is zero."""
    W = np.atleast_2d(np.asarray(channels, dtype=float))
    if plate.type == 4:
        W = W @ np.asarray(plate.cal_matrix).T
    f, m_sensor = W[:, :3], W[:, 3:] / LENGTH_UNITS_PER_M[point_unit]
    m_centre = m_sensor + np.cross(f, np.asarray(plate.origin_m, dtype=float))
    R, centre = plate_frame(plate)
    with np.errstate(divide="ignore", invalid="ignore"):
        cop_plate = np.column_stack([-m_centre[:, 1] / f[:, 2], m_centre[:, 0] / f[:, 2], np.zeros(len(f))])
    free = m_centre[:, 2] - (cop_plate[:, 0] * f[:, 1] - cop_plate[:, 1] * f[:, 0])
    sign = -1.0 if R[2, 2] < 0 else 1.0
    return {"force_n": f @ R.T, "cop_m": cop_plate @ R.T + centre, "free_moment_nm": sign * free}
