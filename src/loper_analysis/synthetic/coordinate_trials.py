"""Synthetic trials at the coordinate level: the response analysis' inputs without markers and inverse kinematics.

A simulated walking trial (:func:`loper_analysis.synthetic.trials.simulate_walking_trial`)
holds the model coordinates, the true gait events and the robot log. The
full chain writes markers and recovers the angles through OpenSim; for many
repeated experiments (e.g. checking the precision the planner predicts,
:mod:`loper_analysis.planning.precision`) that is far too slow. :func:`trial_inputs`
builds the same inputs directly:

* ``angles``: the coordinates at the motion-capture frames as the angle table
  (``pelvis_angle_rad = -pelvis_tilt``, ``pelvis_x_m = pelvis_tx``, the joint
  angles), plus optional white noise of ``angle_noise_sd_rad`` on every angle
  (standing in for what markers and IK add);
* ``force`` and ``force_native``: the robot log on the motion-capture frames
  and at its own 1000 Hz samples through the sync pulses, exactly as the
  load-cell step does (:func:`loper_analysis.device.loadcell.robot_log_frames_and_native`;
  the fit takes the pulse from the native rate);
* ``strides``: :func:`loper_analysis.gait.strides.stride_tables` from the true
  events and that force table;
* ``markers``: two brace markers along the (noisy) thigh, from which
  :func:`loper_analysis.impedance.responses.rod_directions.brace_force_direction` gives the rods'
  direction.

The result is a trial mapping for :func:`loper_analysis.impedance.identification.impedance.fit_onset`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, SIDES, angle_column
from loper_analysis.errors import LoperInputError
from loper_analysis.study_design import PERTURBED_SIDE, PULSE_DURATION_S, PULSE_FORCE_N
from loper_analysis.swing_leg.dynamics import segment_coordinates
from loper_analysis.synthetic.walking import AMPLITUDE_CV, TIMING_CV

__all__ = ["BRACE_LABELS", "trial_inputs", "perturbation_experiment"]

#: Brace marker labels written by :func:`trial_inputs` (the defaults of ``brace_force_direction``).
BRACE_LABELS: tuple[str, str] = ("LBRA_P", "LBRA_D")
_COORDINATE = {"hip": "hip_flexion", "knee": "knee_flexion", "ankle": "ankle_dorsiflexion"}


def trial_inputs(
    walk,
    lab,
    name: str,
    *,
    angle_noise_sd_rad: float = 0.0,
    seed=None,
    end_s: float | None = None,
    side: str = PERTURBED_SIDE,
) -> dict:
    """The inputs of the response analysis for one simulated trial with the device.

    Parameters
    ----------
    walk : loper_analysis.synthetic.trials.WalkingTrial
        A trial simulated with the device (``walk.robot`` not None).
    lab : loper_analysis.synthetic.trials.LabSettings
        Its rates and clocks.
    name : str
        Trial name.
    angle_noise_sd_rad : float
        SD (rad) of white noise added to every angle at every frame (0: none).
    seed : int or SeedSequence, optional
        Seed of that noise; drawn over the whole trial before any cut, so a
        cut trial's frames equal the uncut trial's.
    end_s : float, optional
        Keep only frames up to this time (s, motion-capture clock).
    side : {"left", "right"}
        The perturbed leg (its stride table).

    Returns
    -------
    dict
        ``name``, ``angles``, ``strides``, ``force`` (frames), ``force_native``
        (the robot samples on the motion-capture clock) and ``markers``
        ``(time_s, markers_m (n, 2, 3), labels)``.
    """
    from loper_analysis.device.loadcell import robot_log_frames_and_native
    from loper_analysis.gait.strides import stride_tables

    if walk.robot is None:
        raise LoperInputError(f"{name}: a trial without the device has no robot log")
    if side not in SIDES:
        raise LoperInputError(f"{name}: side must be one of {SIDES}, got {side!r}")
    coords = walk.mocap_coordinates(lab.marker_rate_hz)
    t = coords["time_s"].to_numpy(float)
    angles = pd.DataFrame(
        {
            "time_s": t,
            "pelvis_x_m": coords["pelvis_tx"].to_numpy(float),
            "pelvis_angle_rad": -coords["pelvis_tilt"].to_numpy(float),
        }
    )
    for s in SIDES:
        for joint in JOINTS:
            angles[angle_column(joint, s)] = coords[f"{_COORDINATE[joint]}_{s[0]}"].to_numpy(float)
    if angle_noise_sd_rad < 0 or not np.isfinite(angle_noise_sd_rad):
        raise LoperInputError(f"{name}: angle_noise_sd_rad must be finite and >= 0, got {angle_noise_sd_rad}")
    if angle_noise_sd_rad > 0:
        rng = np.random.default_rng(seed)
        columns = [c for c in angles.columns if c.endswith("_rad")]
        angles[columns] = angles[columns].to_numpy() + rng.normal(0.0, angle_noise_sd_rad, (len(t), len(columns)))
    ratio = int(round(lab.analog_rate_hz / lab.marker_rate_hz))
    sync_v = walk.sync_v(np.arange(len(t) * ratio) / lab.analog_rate_hz, lab)
    force, native = robot_log_frames_and_native(
        walk.robot, lab.robot_rate_hz, sync_v, lab.analog_rate_hz, t, source=name
    )
    events = walk.mocap_events()
    if end_s is not None:
        keep = t <= end_s + 1e-9
        angles, force = angles[keep].reset_index(drop=True), force[keep].reset_index(drop=True)
        native = native[native["time_s"].to_numpy(float) <= end_s + 1e-9].reset_index(drop=True)
        events = events[events["time_s"] <= end_s].reset_index(drop=True)
    force.attrs, native.attrs = {}, {}
    strides = stride_tables(angles, events, force, side=side).strides
    joints = angles[[angle_column(j, side) for j in JOINTS]].to_numpy(float)
    q = segment_coordinates(joints, angles["pelvis_angle_rad"].to_numpy(float), angles["pelvis_x_m"].to_numpy(float))
    markers = np.zeros((len(angles), 2, 3))
    markers[:, 0, 0], markers[:, 0, 1] = 0.1 * np.sin(q[:, 1]), 0.1 * np.cos(q[:, 1])  # proximal: up the thigh
    return {
        "name": name,
        "angles": angles,
        "strides": strides,
        "force": force,
        "force_native": native,
        "markers": (angles["time_s"].to_numpy(float), markers, list(BRACE_LABELS)),
    }


def perturbation_experiment(
    seed,
    params,
    height_m: float,
    onset_ms: float,
    impedance,
    n_strides,
    *,
    lab=None,
    device=None,
    timing_cv: float = TIMING_CV,
    amplitude_cv: float = AMPLITUDE_CV,
    force_n: float = PULSE_FORCE_N,
    duration_s: float = PULSE_DURATION_S,
    every_strides: tuple[int, int] = (3, 5),
    angle_noise_sd_rad: float = 0.0,
    variability=None,
    adaptation=None,
    minimal_impedance=None,
    shank_force_n: float = 0.0,
) -> tuple[dict, dict[int, dict]]:
    """One synthetic perturbation experiment: a trial long enough for ``max(n_strides)`` perturbed strides.

    One walking trial with the device (:func:`~loper_analysis.synthetic.trials.simulate_walking_trial`,
    seeded by ``seed``) is perturbed at ``onset_ms`` (a ``force_n`` N pulse of
    ``duration_s`` s every ``every_strides`` strides); the subject answers with
    ``impedance`` (6,). Returns the whole trial's inputs (:func:`trial_inputs`,
    named ``full``: its unperturbed strides are the null pairs) and, per count
    ``n`` in ``n_strides``, the trial cut 1 s after the swing of its ``n``-th
    perturbed stride (named ``first{n}``; the whole trial if it holds fewer).
    ``variability``, ``adaptation`` and ``minimal_impedance``: the lab's
    stride-to-stride variability, the subject's adaptation to the device and
    its minimal-impedance walking
    (:func:`loper_analysis.synthetic.variability.lab_variability`; None: the
    gentle lab of ``timing_cv`` and ``amplitude_cv`` alone). ``shank_force_n``
    (N): a second rod's pulse just above the ankle with the thigh's (the default
    :class:`~loper_analysis.swing_leg.rods.ShankRod`); its load cell is then in
    the force tables and the fit takes both rods.
    """
    from loper_analysis.device.controller import DeviceParameters
    from loper_analysis.swing_leg.rods import ShankRod
    from loper_analysis.synthetic.gait_curves import NominalGait
    from loper_analysis.synthetic.trials import LabSettings, PerturbationSettings, simulate_walking_trial

    lab = lab or LabSettings()
    counts = sorted({int(n) for n in np.atleast_1d(n_strides)})
    if not counts or counts[0] < 1:
        raise LoperInputError(f"n_strides must hold counts >= 1, got {n_strides!r}")
    mean_every = 0.5 * (every_strides[0] + every_strides[1])
    trial_s = (counts[-1] + 3) * mean_every * NominalGait().stride_s * 1.1 + 2.0
    sim_seed, noise_seed = np.random.SeedSequence(seed).spawn(2)
    perturbation = PerturbationSettings(
        onset_ms / 1e3, tuple(float(v) for v in impedance), force_n, duration_s, tuple(every_strides), shank_force_n
    )
    walk = simulate_walking_trial(
        trial_s,
        lab,
        sim_seed,
        height_m,
        params,
        timing_cv=timing_cv,
        amplitude_cv=amplitude_cv,
        device=device or DeviceParameters(),
        perturbation=perturbation,
        variability=variability,
        adaptation=adaptation,
        minimal_impedance=minimal_impedance,
        shank_rod=ShankRod() if shank_force_n else None,
    )
    full = trial_inputs(walk, lab, "full", angle_noise_sd_rad=angle_noise_sd_rad, seed=noise_seed)
    heel_strikes = walk.schedule["heel_strike_s"].to_numpy(float)
    cut = {}
    for n in counts:
        end = heel_strikes[n - 1] + 1.0 if n <= heel_strikes.size else None
        cut[n] = trial_inputs(walk, lab, f"first{n}", angle_noise_sd_rad=angle_noise_sd_rad, seed=noise_seed, end_s=end)
    return full, cut
