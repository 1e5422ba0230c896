"""The robot's sync train as the motion-capture analog input records it: shared by the clock tests."""

import numpy as np

from loper_analysis.synthetic.sync import pulse_train_at

ROBOT_HZ = 1000.0
ANALOG_HZ = 1024.0


def mocap_view(starts, offset_s, ppm, robot_t0_s, robot_duration_s, mocap_duration_s, pulse_s=0.01):
    """The robot's sync train as the mocap analog input records it (zero while the robot is not running).

    Robot clock: the log's sample 0 is at ``robot_t0_s``; pulses start at
    ``robot_t0_s + starts``. Mocap clock: analog sample 0 at t = 0;
    ``t_mocap = offset_s + (1 + ppm * 1e-6) * t_robot``.
    """
    scale = 1 + ppm * 1e-6
    t_analog = np.arange(round(mocap_duration_s * ANALOG_HZ)) / ANALOG_HZ
    rel = (t_analog - offset_s) / scale - robot_t0_s  # time since the robot log's sample 0
    running = (rel >= 0) & (rel < robot_duration_s)
    return np.where(running, pulse_train_at(rel, starts, pulse_s), 0.0)
