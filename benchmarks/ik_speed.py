"""IK throughput: a 4-minute trial at 128 Hz (30,720 frames) with the default model, one core.

Usage: python benchmarks/ik_speed.py [n_frames]
Markers come from known joint angles through the model (forward kinematics);
prints the IK wall time and the largest angle error.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from loper_analysis.kinematics import inverse_kinematics, marker_positions
from loper_analysis.model import MARKERS, build_lower_body_model


def main(n: int = 30720) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "model.osim"
        build_lower_body_model(1.73, 64.9, path)
        t = np.arange(n) / 128.0
        w = 2 * np.pi * 0.6
        truth = {
            "pelvis_tx": 0.02 * np.sin(2 * w * t), "pelvis_ty": 0.93 + 0.01 * np.sin(2 * w * t),
            "pelvis_tilt": 0.05 * np.sin(w * t),
            "hip_flexion_l": 0.1 + 0.3 * np.sin(w * t), "knee_flexion_l": 0.6 + 0.5 * np.sin(w * t + 1),
            "ankle_dorsiflexion_l": 0.1 * np.sin(w * t + 2),
            "hip_flexion_r": 0.1 - 0.3 * np.sin(w * t), "knee_flexion_r": 0.6 - 0.5 * np.sin(w * t + 1),
            "ankle_dorsiflexion_r": -0.1 * np.sin(w * t + 2),
        }
        X = marker_positions(path, truth)
        for accuracy in (1e-6, 1e-8):  # the pipeline's default (config opensim.accuracy), and tighter
            t0 = time.perf_counter()
            res = inverse_kinematics(path, t, X, list(MARKERS), accuracy=accuracy)
            dt = time.perf_counter() - t0
            err = max(np.abs(res.coordinates[:, i] - truth[c]).max() for i, c in enumerate(res.coordinate_names)
                      if not c.endswith(("_tx", "_ty")))
            print(f"IK of {n} frames ({n / 128 / 60:.1f} min at 128 Hz), {len(MARKERS)} markers, accuracy "
                  f"{accuracy:g}: {dt:.1f} s ({dt / n * 1e3:.2f} ms/frame; target 30 s for 30,720 frames); "
                  f"max angle error {np.rad2deg(err):.2e} deg")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 30720)
