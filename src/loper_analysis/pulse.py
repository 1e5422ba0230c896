"""The shape of a measured LOPER force pulse: rise time and overshoot of the controlled robot.

A commanded rectangle (``force_n`` for ``duration_s``) reaches the leg as the
robot's step response to its switching on, minus the same response to its
switching off. The step response is that of a second-order system whose
damping ratio gives the overshoot and whose natural frequency gives the 10-90 %
rise time, e.g. the study's 10 ms and 30.5 % (:data:`loper_analysis.reference.STUDY_DEVICE`).
The impulse of the pulse is ``force_n * duration_s`` (the two step responses
settle to the same level), however fast or slow its edges.
"""

from __future__ import annotations

import numpy as np

from .checks import positive
from .errors import LoperInputError

__all__ = ["second_order_parameters", "step_response", "pulse_force"]


def second_order_parameters(rise_time_s: float, overshoot_pct: float) -> tuple[float, float]:
    """Damping ratio (-) and natural frequency (rad/s) of a step response with this rise time (10-90 %, s) and overshoot (%).

    Raises
    ------
    LoperInputError
        A rise time that is not positive, an overshoot outside 0 < overshoot < 100 %.
    """
    tr = positive("rise_time_s", rise_time_s)
    if not 0.0 < overshoot_pct < 100.0:
        raise LoperInputError(f"overshoot_pct must lie in 0 .. 100 % (exclusive), got {overshoot_pct}")
    lo = np.log(overshoot_pct / 100.0)
    zeta = float(-lo / np.sqrt(np.pi**2 + lo**2))
    # rise time of the unit-frequency response: first crossings of 0.1 and 0.9 (it rises monotonically to its peak)
    tau = np.linspace(0.0, np.pi / np.sqrt(1.0 - zeta**2), 20001)
    y = _unit_step(tau, zeta)
    tr_unit = float(np.interp(0.9, y, tau) - np.interp(0.1, y, tau))
    return zeta, tr_unit / tr


def _unit_step(tau: np.ndarray, zeta: float) -> np.ndarray:
    wd = np.sqrt(1.0 - zeta**2)
    tau = np.maximum(tau, 0.0)
    return 1.0 - np.exp(-zeta * tau) * (np.cos(wd * tau) + zeta / wd * np.sin(wd * tau))


def step_response(time_s, rise_time_s: float, overshoot_pct: float) -> np.ndarray:
    """Unit step response (n,) at ``time_s`` (s after the step; 0 before it)."""
    zeta, wn = second_order_parameters(rise_time_s, overshoot_pct)
    t = np.asarray(time_s, dtype=float)
    return np.where(t > 0.0, _unit_step(wn * t, zeta), 0.0)


def pulse_force(time_s, onset_s: float, duration_s: float, force_n: float, rise_time_s: float,
                overshoot_pct: float) -> np.ndarray:
    """Force (n,) in N of a pulse commanded from ``onset_s`` for ``duration_s`` (s), as the robot delivers it.

    ``force_n * (y(t - onset_s) - y(t - onset_s - duration_s))`` with ``y`` the
    :func:`step_response` of ``rise_time_s`` (10-90 %, s) and ``overshoot_pct`` (%).
    """
    duration = positive("duration_s", duration_s)
    t = np.asarray(time_s, dtype=float)
    return force_n * (step_response(t - onset_s, rise_time_s, overshoot_pct)
                      - step_response(t - onset_s - duration, rise_time_s, overshoot_pct))
