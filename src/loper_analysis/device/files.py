"""File-level steps of the device rules: simulate a device trial to a robot log,
analyse logs read from disk, summarise against the study and draw the figures."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import LoperInputError
from ..io.robot_log import read_robot_log, write_robot_log
from .analysis import bandwidth_hz, frequency_response, step_averages, step_table
from .controller import DeviceParameters, FreeLeg, safety_events
from .trials import DeviceTestSettings, simulate_device_trial

__all__ = [
    "STUDY_DEVICE_FIGURES",
    "write_device_trial",
    "write_frf_table",
    "write_step_tables",
    "write_device_summary",
    "plot_bode",
    "plot_steps",
]

#: The study's device figures (DESIGN.md section 3): metric -> (value, unit).
STUDY_DEVICE_FIGURES: dict[str, tuple[float, str]] = {
    "bandwidth_hz": (39.0, "Hz"),
    "rise_time_ms": (10.0, "ms"),
    "overshoot_pct": (30.5, "%"),
    "steady_state_40n_n": (36.0, "N"),
}

_FLOAT = "%.10g"


def write_device_trial(
    out_path, trial: str, device: DeviceParameters, leg: FreeLeg, settings: DeviceTestSettings, seed
) -> pd.DataFrame:
    """Simulate one device-test trial, write it as a robot log; returns the safety events (time, state, name)."""
    frame = simulate_device_trial(trial, device, leg, settings, seed)
    write_robot_log(out_path, frame, device.sample_rate_hz, {"trial": trial, "source": "synthetic"})
    return safety_events(frame)


def write_frf_table(log_path, out_tsv, sample_rate_hz: float, window_samples: int, overlap_samples: int) -> pd.DataFrame:
    """FRF of the broadband trial read from disk -> TSV (frequency_hz, gain, phase_deg, coherence)."""
    log, _ = read_robot_log(log_path, sample_rate_hz)
    frf = frequency_response(
        log["force_desired_n"].to_numpy(), log["force_measured_n"].to_numpy(), sample_rate_hz,
        window_samples=window_samples, overlap_samples=overlap_samples,
    )
    frf.to_csv(out_tsv, sep="\t", index=False, float_format=_FLOAT)
    return frf


def write_step_tables(
    log_path, metrics_tsv, average_tsv, sample_rate_hz: float, amplitudes_n, before_s: float, after_s: float,
    steady_window_s,
) -> pd.DataFrame:
    """Step metrics per amplitude and the averaged responses of the step trial read from disk."""
    log, _ = read_robot_log(log_path, sample_rate_hz)
    fd = log["force_desired_n"].to_numpy()
    fm = log["force_measured_n"].to_numpy()
    try:
        average = step_averages(fd, fm, sample_rate_hz, tuple(amplitudes_n), before_s, after_s)
        metrics = step_table(fd, fm, sample_rate_hz, steady_window_s=tuple(steady_window_s), averages=average)
    except LoperInputError as exc:
        raise LoperInputError(f"{log_path}: {exc}") from exc
    metrics.to_csv(metrics_tsv, sep="\t", index=False, float_format=_FLOAT)
    average[["amplitude_n", "time_s", "desired_n", "measured_n", "measured_sd_n"]].to_csv(
        average_tsv, sep="\t", index=False, float_format=_FLOAT)
    return metrics


def write_device_summary(frf_tsv, metrics_tsv, out_tsv, reference_band_hz) -> pd.DataFrame:
    """Simulated (or recorded) device figures beside the study's: metric, value, study_value, unit, difference_pct."""
    frf = pd.read_csv(frf_tsv, sep="\t")
    steps = pd.read_csv(metrics_tsv, sep="\t")
    bw = bandwidth_hz(frf["frequency_hz"].to_numpy(), frf["gain"].to_numpy(), reference_band_hz=tuple(reference_band_hz))
    values = {
        "bandwidth_hz": bw,
        "rise_time_ms": float(steps["rise_time_ms"].mean()),
        "overshoot_pct": float(steps["overshoot_pct"].mean()),
    }
    at40 = steps.loc[np.isclose(steps["amplitude_n"], 40.0), "steady_state_n"]
    values["steady_state_40n_n"] = float(at40.iloc[0]) if len(at40) else np.nan
    rows = []
    for metric, (study, unit) in STUDY_DEVICE_FIGURES.items():
        v = values[metric]
        rows.append({"metric": metric, "value": v, "study_value": study, "unit": unit,
                     "difference_pct": 100.0 * (v - study) / study})
    for _, r in steps.iterrows():
        a = int(round(r["amplitude_n"]))
        rows += [
            {"metric": f"rise_time_ms_at_{a}n", "value": r["rise_time_ms"], "study_value": np.nan, "unit": "ms",
             "difference_pct": np.nan},
            {"metric": f"overshoot_pct_at_{a}n", "value": r["overshoot_pct"], "study_value": np.nan, "unit": "%",
             "difference_pct": np.nan},
            {"metric": f"steady_state_n_at_{a}n", "value": r["steady_state_n"], "study_value": np.nan, "unit": "N",
             "difference_pct": np.nan},
        ]
    out = pd.DataFrame(rows)
    out.to_csv(out_tsv, sep="\t", index=False, float_format=_FLOAT, na_rep="")
    return out


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_bode(frf_tsv, summary_tsv, out_png) -> None:
    """Bode plot (gain in dB, phase, coherence) with the -3 dB bandwidth, ours and the study's."""
    plt = _pyplot()
    frf = pd.read_csv(frf_tsv, sep="\t")
    summary = pd.read_csv(summary_tsv, sep="\t").set_index("metric")
    f = frf["frequency_hz"]
    keep = f <= 100
    fig, axes = plt.subplots(3, 1, figsize=(6.5, 7), sharex=True, constrained_layout=True,
                             gridspec_kw={"height_ratios": [3, 2, 1]})
    axes[0].semilogx(f[keep], 20 * np.log10(frf["gain"][keep]), color="k")
    bw = summary.loc["bandwidth_hz", "value"]
    axes[0].axvline(bw, color="tab:blue", ls="--", label=f"bandwidth {bw:.1f} Hz")
    axes[0].axvline(39.0, color="tab:red", ls=":", label="study 39 Hz")
    axes[0].axhline(-3, color="0.6", lw=0.8)
    axes[0].set_ylabel("gain F_m/F_d (dB)")
    axes[0].legend(frameon=False)
    axes[1].semilogx(f[keep], frf["phase_deg"][keep], color="k")
    axes[1].set_ylabel("phase (deg)")
    axes[2].semilogx(f[keep], frf["coherence"][keep], color="k")
    axes[2].set_ylim(0, 1.05)
    axes[2].set_ylabel("coherence")
    axes[2].set_xlabel("frequency (Hz)")
    fig.savefig(out_png, dpi=110, metadata={"Software": None})
    plt.close(fig)


def plot_steps(average_tsv, out_png) -> None:
    """Averaged step responses per amplitude (mean +- SD) with the target lines."""
    plt = _pyplot()
    avg = pd.read_csv(average_tsv, sep="\t")
    fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
    for (a, g), color in zip(avg.groupby("amplitude_n"), ("tab:blue", "tab:orange", "tab:green", "tab:red")):
        t = 1e3 * g["time_s"]
        ax.plot(t, g["measured_n"], color=color, label=f"{a:.0f} N")
        ax.fill_between(t, g["measured_n"] - g["measured_sd_n"], g["measured_n"] + g["measured_sd_n"],
                        color=color, alpha=0.25, lw=0)
        ax.axhline(a, color=color, ls="--", lw=0.8)
    ax.set_xlabel("time after step onset (ms)")
    ax.set_ylabel("interaction force (N)")
    ax.legend(frameon=False, title="target")
    fig.savefig(out_png, dpi=110, metadata={"Software": None})
    plt.close(fig)
