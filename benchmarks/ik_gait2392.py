"""IK time per frame with the study's gait2392 beside the default generated model, on the same walking.

Usage: python benchmarks/ik_gait2392.py [duration_s]     (default 240 s: a 4-minute trial at 128 Hz)

One simulated walking trial (the synthetic lab's gait) drives both models: the generated sagittal model
with its 36 markers, and gait2392 (23 coordinates) with its 39 scale markers, its coordinates mapped
from ours (:data:`loper_analysis.synthetic.lab_export.GAIT2392_COORDINATES`). Markers get 0.5 mm noise;
IK runs at the pipeline's accuracy (``opensim.accuracy`` 1e-6) on one core, as the ``ik`` rule does.
Prints wall time, time per frame and the hip, knee and ankle errors against the simulated angles.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from loper_analysis.io.osim import read_marker_set, read_model
from loper_analysis.motion.ik import inverse_kinematics, marker_positions
from loper_analysis.motion.model import build_lower_body_model
from loper_analysis.synthetic.gait_curves import NominalGait
from loper_analysis.synthetic.lab_export import gait2392_coordinates
from loper_analysis.synthetic.walking import leg_length_from_height, walking_kinematics

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "gait2392"
RATE_HZ = 128.0
HEIGHT_M, MASS_KG = 1.80, 75.0


def _run(name: str, model, coordinates, angles: dict[str, tuple[str, float]], rng) -> None:
    markers = model.getMarkerSet()
    labels = [markers.get(i).getName() for i in range(markers.getSize())]
    values = {c: coordinates[c].to_numpy(float) for c in coordinates.columns if c != "time_s"}
    X = marker_positions(model, values, labels) + rng.normal(0.0, 0.5e-3, (len(coordinates), len(labels), 3))
    t = coordinates["time_s"].to_numpy(float)
    t0 = time.perf_counter()
    result = inverse_kinematics(model, t, X, labels, accuracy=1e-6)
    seconds = time.perf_counter() - t0
    solved = result.frame()
    errors = {ours: np.degrees(solved[c].to_numpy() - values[c]) for ours, (c, _) in angles.items()}
    text = ", ".join(f"{k} rms {np.sqrt(np.mean(e**2)):.2f} max {np.abs(e).max():.2f} deg" for k, e in errors.items())
    print(
        f"{name}: {len(t)} frames, {len(labels)} markers, {model.getCoordinateSet().getSize()} coordinates: "
        f"{seconds:.1f} s, {1e3 * seconds / len(t):.2f} ms/frame; {text}"
    )


def main(duration_s: float = 240.0) -> None:
    rng = np.random.default_rng(2024)
    coordinates, _ = walking_kinematics(
        duration_s,
        RATE_HZ,
        NominalGait(),
        rng,
        timing_cv=0.03,
        amplitude_cv=0.05,
        leg_length_m=leg_length_from_height(HEIGHT_M),
    )
    generated = build_lower_body_model(HEIGHT_M, MASS_KG)
    _run(
        "generated model",
        generated,
        coordinates,
        {"hip": ("hip_flexion_l", 1), "knee": ("knee_flexion_l", 1), "ankle": ("ankle_dorsiflexion_l", 1)},
        rng,
    )
    gait2392 = read_model(EXAMPLE / "gait2392_simbody.osim")
    gait2392.updateMarkerSet(read_marker_set(EXAMPLE / "gait2392_Scale_MarkerSet.xml"))
    gait2392.initSystem()
    _run(
        "gait2392",
        gait2392,
        gait2392_coordinates(coordinates, 0.05),
        {"hip": ("hip_flexion_l", 1), "knee": ("knee_angle_l", -1), "ankle": ("ankle_angle_l", 1)},
        rng,
    )


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 240.0)
