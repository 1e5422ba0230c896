"""Split-belt treadmill ground reaction forces of the synthetic subjects, from their gait events.

Treadmill forces
----------------
:func:`treadmill_grf` gives each belt (left foot on the left belt) a vertical
force that is zero in swing and, in stance, a step of ``edge_n`` at heel
strike followed by a smooth double hump (peaks about 1.1 body weight at the
end of the loading double support and at the start of push-off, valley about
0.8 body weight at mid-stance), back to ``edge_n`` just before toe-off and
zero from toe-off on. The step is the "rise time": it happens between two
analog samples (0 -> ``edge_n`` in less than one sample period), so a
threshold below ``edge_n`` minus a few noise SDs finds heel strike at the
first sample at or after the true event and toe-off at the first sample at or
after the true toe-off, i.e. always within one sample period. The shape is
scaled so that both belts together average body weight over the strides of
the events. Belt coordinates: x forward, y to the left, z up (right-handed,
Z-up like the motion-capture lab); each belt's origin is under the centre of
pressure at mid-stance.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.interpolate import PchipInterpolator

from loper_analysis.checks import generator
from loper_analysis.constants import GRAVITY_M_PER_S2, SIDES
from loper_analysis.errors import LoperInputError
from loper_analysis.synthetic.walking import TRUE_EVENT_COLUMNS

__all__ = ["GRF_COLUMNS", "treadmill_grf"]

#: Columns of the treadmill force frame (N, N·m, m; belt frame x forward, y left, z up).
GRF_COLUMNS: tuple[str, ...] = (
    "time_s",
    "fz_left_n",
    "fz_right_n",
    "fx_left_n",
    "fx_right_n",
    "mx_left_nm",
    "mx_right_nm",
    "my_left_nm",
    "my_right_nm",
    "mz_left_nm",
    "mz_right_nm",
    "cop_x_left_m",
    "cop_x_right_m",
    "cop_y_left_m",
    "cop_y_right_m",
)


def _stances(events: pd.DataFrame) -> tuple[dict[str, list[tuple[float, float]]], float, float]:
    """Stance intervals per side (start, end) in s, the typical stance duration and the mean stance fraction.

    A leading toe-off (foot already in stance at the start) starts one typical
    stance earlier; a trailing heel strike ends one typical stance later.
    """
    complete, strides = [], []
    pending: dict[str, tuple[list, list]] = {}
    for side in SIDES:
        ev = events[events["side"] == side].sort_values("time_s", kind="stable")
        kinds, times = ev["event"].tolist(), ev["time_s"].to_numpy(float)
        for i in range(1, len(kinds)):
            if kinds[i] == kinds[i - 1]:
                raise LoperInputError(
                    f"events: {side} {kinds[i]} at {times[i]:.4f} s follows another {kinds[i]} "
                    f"(at {times[i - 1]:.4f} s); heel strikes and toe-offs must alternate per side"
                )
        intervals, open_ends = [], []
        for i, (kind, tt) in enumerate(zip(kinds, times)):
            if kind == "heel_strike":
                if i + 1 < len(kinds):
                    intervals.append((tt, times[i + 1]))
                    complete.append(times[i + 1] - tt)
                else:
                    open_ends.append(("end", tt))
            elif i == 0:
                open_ends.append(("start", tt))
            if i >= 2:
                strides.append(tt - times[i - 2])
        pending[side] = (intervals, open_ends)
    if not complete or not strides:
        raise LoperInputError("events: need at least one complete stance (heel strike -> toe-off) and one stride")
    stance = float(np.median(complete))
    fraction = float(np.mean(complete) / np.mean(strides))
    out = {}
    for side, (intervals, open_ends) in pending.items():
        for where, tt in open_ends:
            intervals.append((tt - stance, tt) if where == "start" else (tt, tt + stance))
        out[side] = sorted(intervals)
    return out, stance, fraction


#: Normalised vertical-force shape over stance (fraction of stance, body weights), without the edge step.
_FZ_KNOTS = (
    (0.0, 0.0),
    (0.1, 0.35),
    (0.22, 1.1),
    (0.36, 0.85),
    (0.5, 0.72),
    (0.64, 0.85),
    (0.78, 1.1),
    (0.9, 0.35),
    (1.0, 0.0),
)


def treadmill_grf(
    events: pd.DataFrame,
    duration_s: float,
    analog_rate_hz: float,
    body_mass_kg: float,
    *,
    rng: np.random.Generator | None = None,
    noise_sd_n: float = 2.0,
    edge_n: float = 100.0,
    belt_speed_m_per_s: float = 0.5,
    foot_length_m: float = 0.26,
    ap_peak_fraction: float = 0.1,
) -> pd.DataFrame:
    """Split-belt treadmill forces and moments (left foot on the left belt) from gait events.

    Vertical force in stance: ``edge_n + c·BW·Q(u)``, ``u`` = fraction of the
    stance, ``Q`` the monotone cubic (PCHIP) through the knots (0, 0),
    (0.1, 0.35), (0.22, 1.1), (0.36, 0.85), (0.5, 0.72) and their mirror images
    (body weights), ``c`` set so that both belts together average body weight
    (``BW = m·g``) given the mean stance fraction of the events (70 kg,
    ``edge_n`` = 100 N, stance fraction 0.65: ``c`` = 0.88, peaks 1.11 BW at
    22 % and 78 % of stance, valley 0.78 BW). Zero in swing; the force steps
    from 0 to ``edge_n`` at heel strike and back to 0 at toe-off (stance is
    ``heel strike <= t < toe-off``), see the module docstring for the rise time.

    Fore-aft force ``-ap_peak_fraction·BW·sin(2πu)``: braking (negative) in the
    first half of stance, propulsion in the second; zero net impulse.

    Centre of pressure in the belt frame (x forward, y left, origin under the
    COP at mid-stance): it rolls from the heel 0.8 foot lengths forward while
    the belt carries the foot backward, ``x = 0.8·L_foot·(u - 0.5) -
    v_belt·(t - t_mid)``; ``y`` runs from 1 cm lateral to 1 cm medial. Moments
    about the belt origin for a force applied on the belt surface (z = 0,
    mediolateral force 0): ``mx = y·fz``, ``my = -x·fz``, ``mz = -y·fx`` plus a
    free moment of 0.

    Gaussian noise (SD ``noise_sd_n``) is added to every force sample, and
    ``noise_sd_n × 0.05 m`` to every moment sample, in swing too; the COP
    columns are noise-free and NaN in swing (undefined).

    Parameters
    ----------
    events : pandas.DataFrame
        ``side``, ``event``, ``time_s`` as from :func:`walking_kinematics`;
        heel strikes and toe-offs must alternate per side. A first toe-off
        without a heel strike before it (foot in stance at the start) starts
        one typical (median) stance earlier; a last heel strike without a
        toe-off ends one typical stance later.
    duration_s : float
        Trial duration (s); ``round(duration_s * analog_rate_hz)`` samples from 0.
    analog_rate_hz : float
        Analog sample rate (Hz), e.g. 1024.
    body_mass_kg : float
        Body mass (kg), 0 .. 300.
    rng : numpy.random.Generator or None
        Noise source; None = a fixed seed (0), still reproducible.
    noise_sd_n : float
        SD of the force noise (N), >= 0.
    edge_n : float
        Force step at heel strike and toe-off (N); keep it above the event
        threshold plus a few noise SDs, and below half body weight.
    belt_speed_m_per_s : float
        Belt speed (m/s), moves the COP backward during stance.
    foot_length_m : float
        Foot length (m) for the COP roll.
    ap_peak_fraction : float
        Peak fore-aft force as a fraction of body weight (0 .. 0.5).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`GRF_COLUMNS`: ``time_s``; ``fz_*_n``, ``fx_*_n`` (N);
        ``mx_*_nm``, ``my_*_nm``, ``mz_*_nm`` (N·m); ``cop_x_*_m``,
        ``cop_y_*_m`` (m, NaN in swing).

    Raises
    ------
    LoperInputError
        Missing columns, unknown side or event names, non-finite times,
        events that do not alternate per side, no complete stance or stride,
        out-of-range arguments.
    """
    if not isinstance(events, pd.DataFrame) or not set(TRUE_EVENT_COLUMNS) <= set(events.columns):
        raise LoperInputError(f"events must be a DataFrame with columns {list(TRUE_EVENT_COLUMNS)}")
    bad_side = sorted(set(events["side"]) - set(SIDES))
    bad_event = sorted(set(events["event"]) - {"heel_strike", "toe_off"})
    if bad_side or bad_event:
        raise LoperInputError(f"events: unknown side(s) {bad_side} or event(s) {bad_event}")
    if not np.all(np.isfinite(events["time_s"].to_numpy(float))):
        raise LoperInputError("events: time_s must be finite")
    if not (np.isfinite(duration_s) and duration_s > 0):
        raise LoperInputError(f"duration_s must be > 0, got {duration_s}")
    if not (np.isfinite(analog_rate_hz) and analog_rate_hz > 0):
        raise LoperInputError(f"analog_rate_hz must be > 0, got {analog_rate_hz}")
    if not 0 < body_mass_kg <= 300:
        raise LoperInputError(f"body_mass_kg must lie in 0 .. 300 kg, got {body_mass_kg}")
    if not noise_sd_n >= 0:
        raise LoperInputError(f"noise_sd_n must be >= 0, got {noise_sd_n}")
    bw = body_mass_kg * GRAVITY_M_PER_S2
    if not 0 < edge_n < 0.5 * bw:
        raise LoperInputError(f"edge_n must lie in 0 .. {0.5 * bw:.1f} N (half body weight), got {edge_n}")
    if not 0 <= belt_speed_m_per_s <= 5:
        raise LoperInputError(f"belt_speed_m_per_s must lie in 0 .. 5 m/s, got {belt_speed_m_per_s}")
    if not 0 < foot_length_m <= 0.5:
        raise LoperInputError(f"foot_length_m must lie in 0 .. 0.5 m, got {foot_length_m}")
    if not 0 <= ap_peak_fraction <= 0.5:
        raise LoperInputError(f"ap_peak_fraction must lie in 0 .. 0.5, got {ap_peak_fraction}")
    rng = np.random.default_rng(0) if rng is None else generator(rng)
    n = int(round(duration_s * analog_rate_hz))
    if n < 2:
        raise LoperInputError(f"duration_s * analog_rate_hz must give >= 2 samples, got {n}")

    stances, _, fraction = _stances(events)
    shape = PchipInterpolator(*np.array(_FZ_KNOTS).T)
    q_mean = float(shape.integrate(0.0, 1.0))
    scale = (bw / (2.0 * fraction) - edge_n) / (bw * q_mean)
    if scale <= 0:
        raise LoperInputError(
            f"edge_n = {edge_n} N is too large for body weight {bw:.0f} N at stance fraction {fraction:.2f}"
        )

    t = np.arange(n) / analog_rate_hz
    cols = {"time_s": t}
    for side in SIDES:
        fz, fx = np.zeros(n), np.zeros(n)
        cx, cy = np.full(n, np.nan), np.full(n, np.nan)
        lateral = 1.0 if side == "left" else -1.0  # +y is left
        for t_on, t_off in stances[side]:
            idx = slice(int(np.searchsorted(t, t_on, "left")), int(np.searchsorted(t, t_off, "left")))
            ts = t[idx]  # t_on <= ts < t_off
            if ts.size == 0:
                continue
            dur = t_off - t_on
            u = (ts - t_on) / dur
            fz[idx] = edge_n + scale * bw * shape(u)
            fx[idx] = -ap_peak_fraction * bw * np.sin(2.0 * np.pi * u)
            cx[idx] = 0.8 * foot_length_m * (u - 0.5) - belt_speed_m_per_s * (ts - t_on - 0.5 * dur)
            cy[idx] = lateral * 0.01 * (1.0 - 2.0 * u)
        x0, y0 = np.nan_to_num(cx), np.nan_to_num(cy)
        cols[f"fz_{side}_n"] = fz
        cols[f"fx_{side}_n"] = fx
        cols[f"mx_{side}_nm"] = y0 * fz
        cols[f"my_{side}_nm"] = -x0 * fz
        cols[f"mz_{side}_nm"] = -y0 * fx
        cols[f"cop_x_{side}_m"] = cx
        cols[f"cop_y_{side}_m"] = cy
    if noise_sd_n > 0:
        for name in GRF_COLUMNS[1:11]:
            sd = noise_sd_n if name.endswith("_n") else noise_sd_n * 0.05
            cols[name] = cols[name] + rng.normal(0.0, sd, n)
    return pd.DataFrame({c: cols[c] for c in GRF_COLUMNS})
