"""Robot-log frames shared by the robot-log tests: a valid frame and what the file holds of it."""

import numpy as np
import pandas as pd

from loper_analysis.io.robot_log import COLUMNS

FS = 1000.0
N = 60


def make_frame(n: int = N, seed: int = 0) -> pd.DataFrame:
    """A valid robot-log frame of ``n`` samples at 1000 Hz starting at 12 s."""
    rng = np.random.default_rng(seed)
    return pd.DataFrame(
        {
            "time_s": 12.0 + np.arange(n) / FS,
            "force_desired_n": 40.0 * rng.random(n),
            "force_measured_n": 40.0 * rng.random(n) + rng.normal(0.0, 1e-3, n),
            "motor_angle_rad": rng.normal(0.0, 0.1, n),
            "motor_velocity_rad_s": rng.normal(0.0, 2.0, n),
            "sync_v": np.where(np.arange(n) % 20 < 5, 5.0, 0.0),
            "perturbation": (np.arange(n) % 10 >= 5).astype(np.int64),
            "safety_state": np.arange(n) % 6,
        }
    )


def rounded(frame: pd.DataFrame) -> pd.DataFrame:
    """What the file holds: time to %.15g, other channels to %.9g."""
    out = frame.copy()
    for col in COLUMNS[:6]:
        fmt = "%.15g" if col == "time_s" else "%.9g"
        out[col] = np.array([fmt % v for v in frame[col]], dtype=np.float64)
    return out
