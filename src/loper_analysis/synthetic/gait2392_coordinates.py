"""Our model's coordinates as gait2392's, the OpenSim model the lab examples and the gait2392 benchmark use.

:data:`GAIT2392_COORDINATES` maps each gait2392 coordinate the simulation moves to ours, with the sign between
them (checked against OpenSim's body positions in the tests); :func:`gait2392_coordinates` turns a table of our
coordinates into gait2392's. The tests' lab export (``tests/qtm_export.py``) puts simulated trials on gait2392
through it.
"""

from __future__ import annotations

import pandas as pd

from loper_analysis.errors import LoperInputError

__all__ = ["GAIT2392_COORDINATES", "gait2392_coordinates"]

#: gait2392 coordinate <- (our coordinate, sign); the others stay at their defaults (0).
GAIT2392_COORDINATES: dict[str, tuple[str, float]] = {
    "pelvis_tilt": ("pelvis_tilt", 1.0),
    "pelvis_tx": ("pelvis_tx", 1.0),
    "pelvis_ty": ("pelvis_ty", 1.0),
    **{f"hip_flexion_{s}": (f"hip_flexion_{s}", 1.0) for s in "rl"},
    **{f"knee_angle_{s}": (f"knee_flexion_{s}", -1.0) for s in "rl"},
    **{f"ankle_angle_{s}": (f"ankle_dorsiflexion_{s}", 1.0) for s in "rl"},
}


def gait2392_coordinates(coordinates: pd.DataFrame, pelvis_ty_offset_m: float = 0.0) -> pd.DataFrame:
    """gait2392 coordinates (rad, m) from ours (:data:`loper_analysis.motion.model.COORDINATES`), ``time_s`` kept.

    ``knee_angle`` is minus our ``knee_flexion``; ``pelvis_ty`` is raised by ``pelvis_ty_offset_m``.
    """
    missing = [ours for ours, _ in GAIT2392_COORDINATES.values() if ours not in coordinates.columns]
    if missing:
        raise LoperInputError(f"coordinates lack column(s) {missing}")
    out = {c: sign * coordinates[ours].to_numpy(float) for c, (ours, sign) in GAIT2392_COORDINATES.items()}
    out["pelvis_ty"] = out["pelvis_ty"] + float(pelvis_ty_offset_m)
    frame = pd.DataFrame(out)
    if "time_s" in coordinates.columns:
        frame.insert(0, "time_s", coordinates["time_s"].to_numpy(float))
    return frame
