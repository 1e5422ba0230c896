"""The swing leg's response to a LOPER force pulse, with a known impedance (the synthetic truth).

The perturbed swing follows the swing-leg model (``docs/swing_leg_model.md``; the
same equations the identification fits, :mod:`loper_analysis.swing_leg.dynamics`):
the unperturbed stride is the reference, its inverse dynamics with the
minimal-impedance force ``F_u`` is the feedforward, and the perturbed leg
is driven by ``u_ff + u_fb + Ja(q)^T F_p - Ja(q_u)^T F_u`` with
``T = -K dtheta - D dtheta'`` per joint. It is integrated with RK4
(:func:`loper_analysis.impedance.identification.simulate_response`) on the analog
grid (1024 Hz), much finer than the 128 Hz the pipeline later sees.

Force direction: the rods push on the brace perpendicular to the thigh, in
the sagittal plane, forward positive: ``(cos q_thigh, -sin q_thigh)`` for a
thigh segment angle ``q_thigh``. ``F_p`` follows the perturbed thigh (a
fixed-point iteration: simulate, turn the force with the new thigh angle,
simulate again), ``F_u`` the unperturbed one. The pipeline reads the same
direction from the two brace markers. A second rod just above the ankle
(:class:`~loper_analysis.swing_leg.rods.ShankRod`) pushes along the shank's
normal turned by the rod's angle, following the perturbed shank the same way.

The cart (pelvis translation) deviates freely in the model; its deviation
is not written to the markers (the stance leg holds the pelvis on the
treadmill), which does not change the joint-angle response the model
predicts. After the next heel strike the remaining deviation fades out
with a raised cosine over ``fade_s``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.study_design import PERTURBED_SIDE, PULSE_DURATION_S, PULSE_FORCE_N
from loper_analysis.swing_leg.dynamics import SegmentParameters, segment_coordinates
from loper_analysis.swing_leg.rods import ShankRod, segment_normal, shank_rod_direction

__all__ = ["perturbation_schedule", "pulse_train", "thigh_normal", "swing_response", "swing_responses", "swing_spans"]


def perturbation_schedule(
    events: pd.DataFrame,
    onset_s: float,
    rng: np.random.Generator,
    start_s: float,
    end_s: float,
    side: str = PERTURBED_SIDE,
    every_strides: tuple[int, int] = (3, 5),
) -> pd.DataFrame:
    """Perturbed strides: every 3-5 strides at random (uniform), ``onset_s`` after toe-off.

    Returns ``toe_off_s``, ``onset_s``, ``heel_strike_s`` (the next heel
    strike, end of the swing) for swings with ``start_s <= toe-off`` and
    ``heel strike <= end_s``.
    """
    ev = events[events["side"] == side]
    to = ev.loc[ev["event"] == "toe_off", "time_s"].to_numpy(float)
    hs = ev.loc[ev["event"] == "heel_strike", "time_s"].to_numpy(float)
    swings = []
    for t in to:
        nxt = hs[hs > t]
        if nxt.size and t >= start_s and nxt[0] <= end_s:
            swings.append((t, nxt[0]))
    lo, hi = every_strides
    rows, i = [], int(rng.integers(1, hi + 1))
    while i < len(swings):
        t_to, t_hs = swings[i]
        rows.append({"toe_off_s": t_to, "onset_s": t_to + onset_s, "heel_strike_s": t_hs})
        i += int(rng.integers(lo, hi + 1))
    return pd.DataFrame(rows, columns=["toe_off_s", "onset_s", "heel_strike_s"])


def pulse_train(time_s, onsets_s, force_n: float = PULSE_FORCE_N, duration_s: float = PULSE_DURATION_S) -> np.ndarray:
    """Desired force (N): ``force_n`` for ``onset <= t < onset + duration_s``, else 0."""
    t = np.asarray(time_s, float)
    out = np.zeros_like(t)
    for t0 in np.atleast_1d(onsets_s):
        out[(t >= t0 - 1e-9) & (t < t0 + duration_s - 1e-9)] = force_n  # tolerant of rounded sample times
    return out


def thigh_normal(q_thigh_rad) -> np.ndarray:
    """Unit vectors (n, 2) perpendicular to the thigh, pointing forward, world x/y."""
    return segment_normal(q_thigh_rad)


def swing_response(
    time_s,
    joint_angles_rad,
    pelvis_angle_rad,
    pelvis_x_m,
    params: SegmentParameters,
    impedance,
    force_perturbed_n,
    force_unperturbed_n,
    onset_s: float,
    heel_strike_s: float,
    *,
    before_s: float = 0.05,
    fade_s: float = 0.2,
    n_substeps: int = 2,
    iterations: int = 3,
    shank_force_n: tuple | None = None,
    shank_rod: ShankRod | None = None,
) -> np.ndarray:
    """Joint-angle deviations (n, 3) rad (hip, knee, ankle) caused by one pulse.

    ``time_s`` (n,) uniform; ``joint_angles_rad`` (n, 3) the unperturbed
    stride; ``force_*_n`` (n,) the load-cell force along the rods with and
    without the pulse (N); ``impedance`` the 6 true values in the order of
    :data:`loper_analysis.constants.PARAMETERS`. Zero before
    ``onset_s - before_s``; simulated to ``heel_strike_s``; faded out after.
    ``shank_force_n``: a second rod's load-cell force with and without the pulse, ((n,), (n,)) in N, pushing
    where ``shank_rod`` places it (``params.shank_attachment_m`` must be that point); None: the thigh rod alone.
    """
    from loper_analysis.impedance.identification import prepare_window, simulate_response
    from loper_analysis.impedance.responses.response_window import ResponseWindow

    t = np.asarray(time_s, float)
    th = np.asarray(joint_angles_rad, float)
    pel = np.asarray(pelvis_angle_rad, float)
    qu = segment_coordinates(th, pel, np.asarray(pelvis_x_m, float))
    fp_mag, fu_mag = np.asarray(force_perturbed_n, float), np.asarray(force_unperturbed_n, float)
    if not (t[0] <= onset_s - before_s - 0.04 and heel_strike_s <= t[-1]):
        raise LoperInputError(f"swing_response: data {t[0]:.3f} .. {t[-1]:.3f} s do not cover the swing")
    fu = fu_mag[:, None] * thigh_normal(qu[:, 1])
    shank = {}
    shank_rod = ShankRod() if shank_rod is None else shank_rod
    if shank_force_n is not None:
        sp_mag, su_mag = (np.asarray(f, float) for f in shank_force_n)
        shank["shank_force_unperturbed_n"] = su_mag[:, None] * shank_rod_direction(qu[:, 2], shank_rod)
    dth = np.zeros_like(th)
    for _ in range(iterations):
        q_thigh = qu[:, 1] - dth[:, 0]  # the pelvis is an input: d(theta_hip) = -d(q_thigh)
        fp = fp_mag[:, None] * thigh_normal(q_thigh)
        if shank_force_n is not None:  # d(q_shank) = d(q_thigh) + d(theta_knee)
            q_shank = q_thigh + qu[:, 2] - qu[:, 1] + dth[:, 1]
            shank["shank_force_perturbed_n"] = sp_mag[:, None] * shank_rod_direction(q_shank, shank_rod)
        window = prepare_window(
            t,
            qu,
            qu,
            params,
            onset_s,
            force_unperturbed_n=fu,
            force_perturbed_n=fp,
            pelvis_angle_unperturbed_rad=pel,
            pelvis_angle_perturbed_rad=pel,
            window=ResponseWindow(before_s=before_s, after_s=heel_strike_s - onset_s, initial_state_span_s=0.04),
            n_substeps=n_substeps,
            **shank,
        )
        response = simulate_response(window, np.asarray(impedance, float))
        i0 = int(np.searchsorted(t, window.time_s[0] - 1e-9))
        new = np.zeros_like(th)
        new[i0 : i0 + len(response)] = response
        tail = slice(i0 + len(response), None)
        after = t[tail] - window.time_s[-1]
        ramp = np.where(after < fade_s, 0.5 * (1 + np.cos(np.pi * after / fade_s)), 0.0)
        new[tail] = response[-1] * ramp[:, None]
        converged = np.max(np.abs(new - dth)) < 1e-9
        dth = new
        if converged:
            break
    return dth


def swing_responses(
    time_s,
    joint_angles_rad,
    pelvis_angle_rad,
    pelvis_x_m,
    params: SegmentParameters,
    impedance,
    force_n,
    swings,
    *,
    n_substeps: int = 2,
    shank_force_n=None,
    shank_rod: ShankRod | None = None,
) -> np.ndarray:
    """Joint-angle deviations (n, 3) rad of every swing driven by the measured force, against walking without it.

    Each swing (rows ``toe_off_s``, ``heel_strike_s`` of ``swings``) is
    simulated from toe-off to heel strike by :func:`swing_response` with the
    load-cell force ``force_n`` (n,) (N, along the rods) as the perturbing
    force and zero as the unperturbed one: the leg feels the device's force
    (its minimal-impedance force, and the pulses where there are any) through
    the swing-leg dynamics with ``impedance`` (the 6 values of
    :data:`loper_analysis.constants.PARAMETERS`). Swings whose span
    (toe-off - 0.3 s .. heel strike + 0.35 s) leaves ``time_s`` are skipped. ``shank_force_n`` (n,): a
    second rod's load-cell force (N) where ``shank_rod`` places it, felt the same way; None: no second rod.
    """
    t = np.asarray(time_s, float)
    th = np.asarray(joint_angles_rad, float)
    before = 0.05
    delta = np.zeros_like(th)
    zero = np.zeros_like(t)
    for toe_off, heel_strike in zip(swings["toe_off_s"], swings["heel_strike_s"]):
        if toe_off - 0.3 < t[0] or heel_strike + 0.35 > t[-1]:
            continue
        sl = slice(int(np.searchsorted(t, toe_off - 0.3)), int(np.searchsorted(t, heel_strike + 0.35)))
        delta[sl] += swing_response(
            t[sl],
            th[sl],
            np.asarray(pelvis_angle_rad)[sl],
            np.asarray(pelvis_x_m)[sl],
            params,
            impedance,
            np.asarray(force_n)[sl],
            zero[sl],
            toe_off + before,
            heel_strike,
            before_s=before,
            n_substeps=n_substeps,
            shank_force_n=None if shank_force_n is None else (np.asarray(shank_force_n)[sl], zero[sl]),
            shank_rod=shank_rod,
        )
    return delta


def swing_spans(events: pd.DataFrame, side: str = PERTURBED_SIDE) -> pd.DataFrame:
    """Every swing of ``side``: ``toe_off_s`` and the next ``heel_strike_s`` (true events, sorted)."""
    ev = events[events["side"] == side]
    to = np.sort(ev.loc[ev["event"] == "toe_off", "time_s"].to_numpy(float))
    hs = np.sort(ev.loc[ev["event"] == "heel_strike", "time_s"].to_numpy(float))
    i = np.searchsorted(hs, to, side="right")
    keep = i < hs.size
    return pd.DataFrame({"toe_off_s": to[keep], "heel_strike_s": hs[i[keep]]})
