"""Device-performance analysis of the LOPER force controller (``docs/device.md``).

* Frequency response ``H = S_{Fm,Fd} / S_{Fd,Fd}`` (Welch averaging, Hann
  window), coherence and the -3 dB bandwidth relative to the low-frequency gain.
* Step responses: rising edges of the desired force, averaging over
  repetitions, 10-90 % rise time, overshoot relative to the steady state.

Signals are 1-D arrays of force in N sampled at ``sample_rate_hz``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.signal import coherence, csd, welch

from loper_analysis.checks import finite_vector, integer, number, positive
from loper_analysis.errors import LoperInputError
from loper_analysis.reference import STUDY_DEVICE
from loper_analysis.study_design import PULSE_FORCE_N

__all__ = [
    "FRFSettings",
    "StepSettings",
    "DeviceAnalysisSettings",
    "frequency_response",
    "bandwidth_hz",
    "step_onsets",
    "average_step",
    "step_metrics",
    "step_averages",
    "step_table",
    "device_summary",
    "WELCH_WINDOW_SAMPLES",
    "WELCH_OVERLAP_SAMPLES",
    "BANDWIDTH_REFERENCE_BAND_HZ",
    "STEP_BEFORE_S",
    "STEP_AFTER_S",
    "STEADY_WINDOW_S",
    "STEP_AMPLITUDES_N",
]

# Defaults of the device tests' analysis (config ``device.analysis.*``, the same values).
#: Samples of the Hann window of Welch's method (``welch_window_samples``) ...
WELCH_WINDOW_SAMPLES: int = 5000
#: ... and of the windows' overlap (``welch_overlap_samples``).
WELCH_OVERLAP_SAMPLES: int = 50
#: Band (Hz) whose mean gain is the reference of the -3 dB bandwidth (``bandwidth_reference_band_hz``).
BANDWIDTH_REFERENCE_BAND_HZ: tuple[float, float] = (0.5, 2.0)
#: A step's average runs from this long before its onset (s; ``step_before_s``) ...
STEP_BEFORE_S: float = 0.05
#: ... to this long after it (s; ``step_after_s``).
STEP_AFTER_S: float = 0.45
#: Span after the onset (s) whose mean is the step's steady state (``steady_window_s``).
STEADY_WINDOW_S: tuple[float, float] = (0.15, 0.3)
#: Heights (N) of the device tests' steps (config ``device.tests.step_amplitudes_n``): the step trial's profile
#: (:class:`~loper_analysis.device.trials.DeviceTestSettings`) and the heights its analysis sorts steps by.
STEP_AMPLITUDES_N: tuple[float, ...] = (20.0, 40.0, 60.0)


def _pair(key: str, value) -> tuple[float, float]:
    """Two finite numbers >= 0 in increasing order (``key``: the config key the message names)."""
    if isinstance(value, str | bytes) or not hasattr(value, "__len__") or len(value) != 2:
        raise LoperInputError(f"{key} must be two numbers [low, high], got {value!r}")
    low, high = (number(key, v, minimum=0.0) for v in value)
    if not low < high:
        raise LoperInputError(f"{key} must be [low, high] with low < high, got {list(value)!r}")
    return low, high


@dataclass(frozen=True)
class FRFSettings:
    """Welch's method of the frequency response (:func:`frequency_response`).

    ``window_samples``: samples of each Hann-windowed segment (>= 16; ``device.analysis.welch_window_samples``);
    ``overlap_samples``: samples two segments share (0 .. ``window_samples - 1``;
    ``device.analysis.welch_overlap_samples``).

    Raises
    ------
    LoperInputError
        A count that is no integer or out of its range, naming its config key and value.
    """

    window_samples: int = WELCH_WINDOW_SAMPLES
    overlap_samples: int = WELCH_OVERLAP_SAMPLES

    def __post_init__(self) -> None:
        window = integer("device.analysis.welch_window_samples", self.window_samples, minimum=16)
        overlap = integer("device.analysis.welch_overlap_samples", self.overlap_samples, minimum=0)
        if overlap >= window:
            raise LoperInputError(
                f"device.analysis.welch_overlap_samples must be below device.analysis.welch_window_samples "
                f"({window}), got {overlap}"
            )


@dataclass(frozen=True)
class StepSettings:
    """How the step trial's steps are averaged and measured (:func:`step_averages`, :func:`step_table`).

    ``before_s``, ``after_s``: each step's average runs from this long before to this long after its onset
    (s, > 0; ``device.analysis.step_before_s``, ``step_after_s``); ``steady_window_s``: the span after the onset
    (s, [low, high]) whose mean is the steady state (``device.analysis.steady_window_s``).

    Raises
    ------
    LoperInputError
        A value out of its range, naming its config key and value.
    """

    before_s: float = STEP_BEFORE_S
    after_s: float = STEP_AFTER_S
    steady_window_s: tuple[float, float] = STEADY_WINDOW_S

    def __post_init__(self) -> None:
        positive("device.analysis.step_before_s", self.before_s)
        positive("device.analysis.step_after_s", self.after_s)
        _pair("device.analysis.steady_window_s", self.steady_window_s)


@dataclass(frozen=True)
class DeviceAnalysisSettings:
    """The device tests' analysis (config ``device.analysis``): ``frf`` (:class:`FRFSettings`), ``steps``
    (:class:`StepSettings`) and ``reference_band_hz``, the band (Hz, [low, high]) whose mean gain is the
    reference of the -3 dB bandwidth (``device.analysis.bandwidth_reference_band_hz``; :func:`device_summary`).

    Raises
    ------
    LoperInputError
        A value out of its range, naming its config key and value.
    """

    frf: FRFSettings = field(default_factory=FRFSettings)
    steps: StepSettings = field(default_factory=StepSettings)
    reference_band_hz: tuple[float, float] = BANDWIDTH_REFERENCE_BAND_HZ

    def __post_init__(self) -> None:
        _pair("device.analysis.bandwidth_reference_band_hz", self.reference_band_hz)


def frequency_response(
    desired_n,
    measured_n,
    sample_rate_hz: float,
    window_samples: int = WELCH_WINDOW_SAMPLES,
    overlap_samples: int = WELCH_OVERLAP_SAMPLES,
) -> pd.DataFrame:
    """FRF from desired to measured force: columns frequency_hz, gain (N/N), phase_deg, coherence."""
    fs = positive("sample_rate_hz", sample_rate_hz)
    if int(window_samples) != window_samples or window_samples < 8:
        raise LoperInputError(f"window_samples must be an integer >= 8, got {window_samples}")
    if int(overlap_samples) != overlap_samples or not 0 <= overlap_samples < window_samples:
        raise LoperInputError(f"overlap_samples must lie in 0 .. window_samples - 1, got {overlap_samples}")
    fd = finite_vector("desired_n", desired_n, min_count=int(window_samples))
    fm = finite_vector("measured_n", measured_n, min_count=int(window_samples))
    if fd.size != fm.size:
        raise LoperInputError(f"desired_n ({fd.size}) and measured_n ({fm.size}) differ in length")
    kw = dict(fs=fs, window="hann", nperseg=int(window_samples), noverlap=int(overlap_samples), detrend="constant")
    f, s_dm = csd(fd, fm, **kw)  # scipy: conj(FFT(fd)) * FFT(fm)  ->  S_{Fm,Fd} in our notation
    _, s_dd = welch(fd, **kw)
    _, coh = coherence(fd, fm, **kw)
    if np.any(s_dd[1:] <= 0):
        raise LoperInputError("desired_n has no power at some frequencies: is it a broadband signal?")
    h = s_dm[1:] / s_dd[1:]
    return pd.DataFrame(
        {
            "frequency_hz": f[1:],
            "gain": np.abs(h),
            "phase_deg": np.degrees(np.unwrap(np.angle(h))),
            "coherence": coh[1:],
        }
    )


def bandwidth_hz(
    frequency_hz,
    gain,
    reference_band_hz: tuple[float, float] = BANDWIDTH_REFERENCE_BAND_HZ,
    drop_db: float = 3.0,
    min_coherence: float | None = None,
    coherence=None,
) -> float:
    """Lowest frequency above the reference band where the gain is ``drop_db`` below the reference.

    The reference is the mean gain in ``reference_band_hz``; the crossing is
    interpolated linearly in log-frequency (gain in dB).
    """
    f = finite_vector("frequency_hz", frequency_hz)
    g = finite_vector("gain", gain)
    if f.size != g.size:
        raise LoperInputError(f"frequency_hz ({f.size}) and gain ({g.size}) differ in length")
    lo, hi = reference_band_hz
    keep = np.ones(f.size, bool)
    if min_coherence is not None:
        c = finite_vector("coherence", coherence)
        keep = c >= min_coherence
    band = keep & (f >= lo) & (f <= hi)
    if not band.any():
        raise LoperInputError(f"no frequencies in the reference band {lo} .. {hi} Hz")
    ref_db = 20 * np.log10(np.mean(g[band]))
    sel = keep & (f > hi) & (g > 0)
    fs_, db = f[sel], 20 * np.log10(g[sel])
    below = np.flatnonzero(db <= ref_db - drop_db)
    if below.size == 0:
        raise LoperInputError(f"the gain never drops {drop_db} dB below {ref_db:.2f} dB up to {f.max():.1f} Hz")
    i = below[0]
    if i == 0:
        return float(fs_[0])
    x0, x1 = np.log(fs_[i - 1]), np.log(fs_[i])
    y0, y1 = db[i - 1], db[i]
    target = ref_db - drop_db
    return float(np.exp(x0 + (target - y0) * (x1 - x0) / (y1 - y0)))


def step_onsets(desired_n, sample_rate_hz: float, min_step_n: float = 5.0, min_interval_s: float = 0.2) -> np.ndarray:
    """Sample indices of rising edges (>= ``min_step_n`` within one sample) of the desired force."""
    fs = positive("sample_rate_hz", sample_rate_hz)
    fd = finite_vector("desired_n", desired_n)
    rise = np.flatnonzero(np.diff(fd) >= min_step_n) + 1
    onsets: list[int] = []
    for i in rise:
        if not onsets or i - onsets[-1] >= min_interval_s * fs:
            onsets.append(int(i))
    if not onsets:
        raise LoperInputError(f"no step found: the desired force never rises by {min_step_n} N within one sample")
    return np.array(onsets)


def average_step(
    desired_n, measured_n, sample_rate_hz: float, onsets, before_s: float = STEP_BEFORE_S, after_s: float = STEP_AFTER_S
) -> pd.DataFrame:
    """Mean (and SD) over repetitions of the responses around ``onsets`` (baseline removed)."""
    fs = positive("sample_rate_hz", sample_rate_hz)
    fd = finite_vector("desired_n", desired_n)
    fm = finite_vector("measured_n", measured_n)
    if fd.size != fm.size:
        raise LoperInputError(f"desired_n ({fd.size}) and measured_n ({fm.size}) differ in length")
    nb, na = int(round(before_s * fs)), int(round(after_s * fs))
    if nb < 1 or na < 2:
        raise LoperInputError(f"before_s and after_s must hold samples, got {before_s}, {after_s}")
    on = np.asarray(onsets, dtype=int)
    if on.size == 0:
        raise LoperInputError("no onsets to average")
    d, m = [], []
    for i in on:
        if i - nb < 0 or i + na > fd.size:
            raise LoperInputError(
                f"step at sample {i}: window -{before_s} .. +{after_s} s leaves the signal (0 .. {fd.size - 1})"
            )
        seg_d, seg_m = fd[i - nb : i + na], fm[i - nb : i + na]
        d.append(seg_d - seg_d[:nb].mean())
        m.append(seg_m - seg_m[:nb].mean())
    d, m = np.array(d), np.array(m)
    return pd.DataFrame(
        {
            "time_s": (np.arange(-nb, na)) / fs,
            "desired_n": d.mean(axis=0),
            "measured_n": m.mean(axis=0),
            "measured_sd_n": m.std(axis=0, ddof=1) if len(m) > 1 else np.zeros(nb + na),
        }
    )


def _first_crossing(t: np.ndarray, y: np.ndarray, level: float) -> float:
    above = np.flatnonzero(y >= level)
    if above.size == 0:
        raise LoperInputError(f"the response never reaches {level:.3g} N")
    i = above[0]
    if i == 0:
        return float(t[0])
    return float(t[i - 1] + (level - y[i - 1]) * (t[i] - t[i - 1]) / (y[i] - y[i - 1]))


def step_metrics(time_s, response_n, target_n: float, steady_window_s: tuple[float, float] = STEADY_WINDOW_S) -> dict:
    """Rise time (10-90 % of steady state, ms), overshoot (%), steady state, peak of one step response."""
    t = finite_vector("time_s", time_s)
    y = finite_vector("response_n", response_n)
    if t.size != y.size:
        raise LoperInputError(f"time_s ({t.size}) and response_n ({y.size}) differ in length")
    w = (t >= steady_window_s[0]) & (t <= steady_window_s[1])
    if not w.any():
        raise LoperInputError(f"steady_window_s {steady_window_s} holds no samples of time_s ({t[0]} .. {t[-1]} s)")
    ss = float(np.mean(y[w]))
    if ss <= 0:
        raise LoperInputError(f"steady state {ss:.3g} N is not positive: not a rising step")
    after = t >= 0
    ta, ya = t[after], y[after]
    t10 = _first_crossing(ta, ya, 0.1 * ss)
    t90 = _first_crossing(ta, ya, 0.9 * ss)
    k = int(np.argmax(ya))
    return {
        "rise_time_ms": 1e3 * (t90 - t10),
        "overshoot_pct": 100.0 * (ya[k] - ss) / ss,
        "steady_state_n": ss,
        "target_n": float(target_n),
        "peak_n": float(ya[k]),
        "peak_time_ms": 1e3 * float(ta[k]),
    }


def step_averages(
    desired_n,
    measured_n,
    sample_rate_hz: float,
    amplitudes_n: tuple[float, ...] = STEP_AMPLITUDES_N,
    before_s: float = STEP_BEFORE_S,
    after_s: float = STEP_AFTER_S,
    min_step_n: float = 5.0,
) -> pd.DataFrame:
    """Averaged step responses per amplitude (columns of :func:`average_step` plus
    ``amplitude_n`` and ``n_repetitions``); every step is matched to the nearest
    amplitude and refused when more than 20 % away from all."""
    fd = finite_vector("desired_n", desired_n)
    onsets = step_onsets(fd, sample_rate_hz, min_step_n=min_step_n)
    heights = fd[onsets] - fd[np.maximum(onsets - 1, 0)]
    amps = np.asarray(amplitudes_n, dtype=float)
    nearest = np.argmin(np.abs(heights[:, None] - amps[None, :]), axis=1)
    far = np.abs(heights - amps[nearest]) > 0.2 * amps[nearest]
    if far.any():
        i = int(np.flatnonzero(far)[0])
        raise LoperInputError(
            f"step at sample {onsets[i]} has height {heights[i]:.3g} N, "
            f"more than 20 % from every amplitude {amps.tolist()}"
        )
    frames = []
    for j, a in enumerate(amps):
        sel = onsets[nearest == j]
        if sel.size == 0:
            raise LoperInputError(f"no step of {a} N found")
        avg = average_step(fd, measured_n, sample_rate_hz, sel, before_s, after_s)
        frames.append(avg.assign(amplitude_n=a, n_repetitions=int(sel.size)))
    return pd.concat(frames, ignore_index=True)


def step_table(averages: pd.DataFrame, steady_window_s: tuple[float, float] = STEADY_WINDOW_S) -> pd.DataFrame:
    """Step metrics (:func:`step_metrics`) of the averaged responses of :func:`step_averages`, one row per amplitude.

    Columns amplitude_n, n_repetitions, rise_time_ms, overshoot_pct, steady_state_n, peak_n.
    """
    rows = []
    for a, avg in averages.groupby("amplitude_n", sort=True):
        m = step_metrics(avg["time_s"].to_numpy(), avg["measured_n"].to_numpy(), a, steady_window_s)
        rows.append(
            {
                "amplitude_n": a,
                "n_repetitions": int(avg["n_repetitions"].iloc[0]),
                "rise_time_ms": m["rise_time_ms"],
                "overshoot_pct": m["overshoot_pct"],
                "steady_state_n": m["steady_state_n"],
                "peak_n": m["peak_n"],
            }
        )
    return pd.DataFrame(rows)


def device_summary(
    frf: pd.DataFrame, steps: pd.DataFrame, reference_band_hz=BANDWIDTH_REFERENCE_BAND_HZ
) -> pd.DataFrame:
    """Simulated (or recorded) device figures beside the study's.

    ``frf`` from :func:`frequency_response`, ``steps`` from :func:`step_table`.
    Columns ``metric, value, study_value, unit, difference_pct``: the -3 dB
    bandwidth, the mean rise time and overshoot over the amplitudes, the
    steady state of the 40 N steps, then per amplitude its rise time,
    overshoot and steady state.
    """
    bw = bandwidth_hz(
        frf["frequency_hz"].to_numpy(), frf["gain"].to_numpy(), reference_band_hz=tuple(reference_band_hz)
    )
    values = {
        "bandwidth_hz": bw,
        "rise_time_ms": float(steps["rise_time_ms"].mean()),
        "overshoot_pct": float(steps["overshoot_pct"].mean()),
    }
    at40 = steps.loc[np.isclose(steps["amplitude_n"], PULSE_FORCE_N), "steady_state_n"]  # steps of the pulse's height
    values["steady_state_40n_n"] = float(at40.iloc[0]) if len(at40) else np.nan
    rows = []
    for metric, (study, unit) in STUDY_DEVICE.items():
        v = values[metric]
        rows.append(
            {
                "metric": metric,
                "value": v,
                "study_value": study,
                "unit": unit,
                "difference_pct": 100.0 * (v - study) / study,
            }
        )
    for _, r in steps.iterrows():
        a = int(round(r["amplitude_n"]))
        rows += [
            {
                "metric": f"rise_time_ms_at_{a}n",
                "value": r["rise_time_ms"],
                "study_value": np.nan,
                "unit": "ms",
                "difference_pct": np.nan,
            },
            {
                "metric": f"overshoot_pct_at_{a}n",
                "value": r["overshoot_pct"],
                "study_value": np.nan,
                "unit": "%",
                "difference_pct": np.nan,
            },
            {
                "metric": f"steady_state_n_at_{a}n",
                "value": r["steady_state_n"],
                "study_value": np.nan,
                "unit": "N",
                "difference_pct": np.nan,
            },
        ]
    return pd.DataFrame(rows)
