"""IK throughput: a 4-minute trial at 128 Hz (30,720 frames) with the default model, one core.

Usage: python benchmarks/ik_speed.py [n_frames]
Markers come from known joint angles through the model (forward kinematics);
prints the IK wall time and the angle errors per step tolerance of the tree solver (the default),
and for scale the error that 0.5 mm marker noise causes.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from loper_analysis.motion.ik import inverse_kinematics, marker_positions
from loper_analysis.motion.model import MARKERS, build_lower_body_model


def main(n: int = 30720) -> None:
    model = build_lower_body_model(1.73, 64.9)
    t = np.arange(n) / 128.0
    w = 2 * np.pi * 0.6
    truth = {
        "pelvis_tx": 0.02 * np.sin(2 * w * t),
        "pelvis_ty": 0.93 + 0.01 * np.sin(2 * w * t),
        "pelvis_tilt": 0.05 * np.sin(w * t),
        "hip_flexion_l": 0.1 + 0.3 * np.sin(w * t),
        "knee_flexion_l": 0.6 + 0.5 * np.sin(w * t + 1),
        "ankle_dorsiflexion_l": 0.1 * np.sin(w * t + 2),
        "hip_flexion_r": 0.1 - 0.3 * np.sin(w * t),
        "knee_flexion_r": 0.6 - 0.5 * np.sin(w * t + 1),
        "ankle_dorsiflexion_r": -0.1 * np.sin(w * t + 2),
    }
    X = marker_positions(model, truth)

    def angle_errors(res):  # (n_frames, n_angles) rad, translations left out
        return np.column_stack(
            [
                res.coordinates[:, i] - truth[c]
                for i, c in enumerate(res.coordinate_names)
                if not c.endswith(("_tx", "_ty"))
            ]
        )

    # the pipeline's default (config ik.tree_step_tolerance) is 1e-6; looser ones show what speed would cost
    for tolerance in (1e-4, 1e-5, 1e-6, 1e-8):
        t0 = time.perf_counter()
        res = inverse_kinematics(model, t, X, list(MARKERS), tree_step_tolerance=tolerance)
        dt = time.perf_counter() - t0
        err = angle_errors(res)
        print(
            f"IK of {n} frames ({n / 128 / 60:.1f} min at 128 Hz), {len(MARKERS)} markers, step tolerance "
            f"{tolerance:g}: {dt:.1f} s ({dt / n * 1e3:.2f} ms/frame; target 30 s for 30,720 frames); "
            f"angle error max {np.rad2deg(np.abs(err).max()):.2e} deg, "
            f"rms {np.rad2deg(np.sqrt(np.mean(err**2))):.2e} deg"
        )
    # for scale: what the synthetic lab's marker noise (config synthetic.marker_noise_sd_m) does at 1e-8
    noisy = X + np.random.default_rng(0).normal(0.0, 0.5e-3, X.shape)
    res = inverse_kinematics(model, t, noisy, list(MARKERS), tree_step_tolerance=1e-8)
    err = angle_errors(res)
    print(
        f"0.5 mm marker noise, step tolerance 1e-8: angle error max {np.rad2deg(np.abs(err).max()):.2e} deg, "
        f"rms {np.rad2deg(np.sqrt(np.mean(err**2))):.2e} deg"
    )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 30720)
