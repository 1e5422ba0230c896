"""The simulated lab's second device: a rod just above the ankle, attached in every trial with the device.

Its device is the thigh rod's (:func:`loper_analysis.device.controller.simulate_device`), driven by the forward
motion of its point on the shank and by its own pulses, with the thigh's onsets and duration; its desired and
measured force become the robot log's ``shank_force_desired_n`` and ``shank_force_measured_n``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from loper_analysis.constants import SIDE_SUFFIX
from loper_analysis.errors import LoperInputError
from loper_analysis.study_design import PERTURBED_SIDE
from loper_analysis.swing_leg.dynamics import segment_coordinates

__all__ = ["attach_shank_rod", "shank_rod_position_m", "with_shank_rod"]


def shank_rod_position_m(coordinates: pd.DataFrame, params, side: str = SIDE_SUFFIX[PERTURBED_SIDE]) -> np.ndarray:
    """Forward position (m) of a second rod's point on the shank, ``params.shank_attachment_m`` below the knee."""
    q = segment_coordinates(
        coordinates[[f"hip_flexion_{side}", f"knee_flexion_{side}", f"ankle_dorsiflexion_{side}"]].to_numpy(float),
        -coordinates["pelvis_tilt"].to_numpy(float),
        coordinates["pelvis_tx"].to_numpy(float),
    )
    return q[:, 0] - params.length_m[0] * np.sin(q[:, 1]) - params.shank_attachment_m * np.sin(q[:, 2])


def attach_shank_rod(robot, fine, params, shank_rod, perturbation, run):
    """The robot frame, the segment parameters and the second rod's (rod, point motion in m, seed) after
    attaching ``shank_rod`` (None: all unchanged, no rod); ``run``: the robot's sample times and their mocap
    times (s), the pulses' onsets on the robot clock (s), the device and the trial's seed sequence (spawned once
    more, after the trial's own four, so that a trial without a shank rod keeps its seeds)."""
    if perturbation is not None and perturbation.shank_force_n and shank_rod is None:
        raise LoperInputError(f"simulate_walking_trial: a {perturbation.shank_force_n:g} N shank pulse needs shank_rod")
    if shank_rod is None:
        return robot, params, None
    times, onsets_robot, device, ss = run
    (seed,) = ss.spawn(1)
    params = params.replace(shank_attachment_m=shank_rod.attachment_m(params.length_m[1]))
    pulse = (perturbation.shank_force_n, perturbation.duration_s) if perturbation else (0.0, 0.0)
    robot, brace = with_shank_rod(robot, fine, params, times, onsets_robot, pulse, device, seed)
    return robot, params, (shank_rod, brace, seed)


def with_shank_rod(robot, fine, params, times, onsets_robot, pulse, device, seed):
    """The robot frame with a second device's desired and measured force (N) at the shank rod's point of
    ``params``, driven by that point's motion in ``fine`` and ``pulse`` (force N, duration s) at ``onsets_robot``
    (s, robot clock; ``times``: the robot's sample times and the same on the mocap clock, s); and that point's
    motion (m, mean removed)."""
    from loper_analysis.device.controller import simulate_device
    from loper_analysis.synthetic.response import pulse_train

    t_robot, t_mocap = times
    brace = np.interp(t_mocap, fine["time_s"].to_numpy(), shank_rod_position_m(fine, params))
    brace -= brace.mean()
    force_n, duration_s = pulse
    desired = pulse_train(t_robot, onsets_robot, force_n, duration_s) if force_n else 0 * t_robot
    sim = simulate_device(desired, device, None, brace_position_m=brace, seed=seed)
    robot = robot.assign(
        shank_force_desired_n=sim["force_desired_n"].to_numpy(),
        shank_force_measured_n=sim["force_measured_n"].to_numpy(),
    )
    return robot, brace
