"""Where the rods push, read from a trial's data: the thigh rod's direction from its brace markers, a second
rod's at the shank from the joint angles.

The responses' trials carry these directions as ``force_direction`` (:mod:`.inputs`): (n, 2) for the thigh rod,
(n, 4) with the shank rod's after it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from loper_analysis.checks import require_columns
from loper_analysis.constants import angle_column
from loper_analysis.errors import LoperInputError
from loper_analysis.study_design import PERTURBED_SIDE
from loper_analysis.swing_leg.rods import ShankRod, shank_rod_direction

__all__ = ["brace_force_direction", "shank_force_direction"]


def brace_force_direction(
    markers_m: np.ndarray, labels: Sequence[str], brace=("LBRA_P", "LBRA_D"), source: str = ""
) -> np.ndarray:
    """Unit vectors (n, 2), world x/y of the model frame, along which the rods push.

    The two brace markers lie on the thigh, proximal and distal; the rods push
    perpendicular to their line, forward: the proximal-minus-distal direction
    turned by -90 degrees in the sagittal (x, y) plane. ``markers_m`` is
    (n, n_markers, 3) in the model frame (X forward, Y up), e.g. a TRC of the
    pipeline.
    """
    labels = list(labels)
    missing = [b for b in brace if b not in labels]
    if missing:
        raise LoperInputError(f"{source}: brace marker(s) {missing} not in the marker data")
    p = markers_m[:, labels.index(brace[0]), :2]
    d = markers_m[:, labels.index(brace[1]), :2]
    up = p - d
    norm = np.linalg.norm(up, axis=1)
    if not np.all(np.isfinite(norm)) or np.any(norm < 1e-3):
        bad = int(np.argmax(~np.isfinite(norm) | (norm < 1e-3)))
        raise LoperInputError(f"{source}: brace markers {brace} missing or coincident at frame {bad}")
    up /= norm[:, None]
    return np.stack([up[:, 1], -up[:, 0]], axis=-1)


def shank_force_direction(angles: pd.DataFrame, rod: ShankRod, source: str = "", side: str = PERTURBED_SIDE):
    """Unit vectors (n, 2), world x/y, along which ``rod`` pushes the shank of ``side``: the shank's forward
    normal turned by the rod's angle, the shank's angle from the joint-angle table (``pelvis_angle_rad``, the
    hip and knee angles, rad: pelvis - hip + knee, as :func:`loper_analysis.swing_leg.dynamics.segment_coordinates`
    has it; a frame without angles gives NaN)."""
    columns = ["pelvis_angle_rad", angle_column("hip", side), angle_column("knee", side)]
    table = require_columns(angles, columns, source)
    pelvis, hip, knee = (table[c].to_numpy(float) for c in columns)
    return shank_rod_direction(pelvis - hip + knee, rod)
