"""Which IK frames of the perturbation trials the impedance fits depend on, from a finished run.

Usage: python benchmarks/ik_frames_read.py [results] [--configfile config/config.yaml ...]

Per perturbation trial, the share of its frames that

* the fits sample directly: the window of each perturbed stride (``impedance.initial_state_span_s`` +
  ``window_before_s`` before its onset to ``window_after_s`` after it), the same span of every unperturbed
  stride at the delays after toe-off of the onset's perturbed strides (the matching candidates) and at every
  onset of the study (the null pairs, which come from every trial with the device), each widened by
  ``--margin-s`` on both sides for the cubic splines that sample them;
* the fits depend on through the stride table's outlier verdicts: every frame of every unperturbed stride
  (the IQR rule judges whole time-normalised strides, and a removed stride is no matching candidate and no
  null pair), plus the windows of the perturbed strides.

The second share bounds what solving IK only where the fits read could save without changing a fit.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from loper_analysis.layout import RESULTS_DIR
from loper_analysis.stages.settings import stage_settings


def covered(time_s: np.ndarray, spans: list[tuple[float, float]]) -> np.ndarray:
    """Frames inside any span (s)."""
    mask = np.zeros(time_s.size, dtype=bool)
    for a, b in spans:
        mask |= (time_s >= a) & (time_s <= b)
    return mask


def trial_shares(
    time_s: np.ndarray, strides: pd.DataFrame, onsets_s: list[float], before_s: float, after_s: float, margin_s: float
) -> tuple[float, float]:
    """(share read directly, share the fits depend on) of a perturbation trial's frames."""
    pert = strides["perturbed"].astype(bool).to_numpy()
    toe = strides["toe_off_s"].to_numpy(float)
    onset = strides["onset_s"].to_numpy(float)
    delays = sorted({*(onset[pert] - toe[pert]).round(6), *onsets_s})
    lo, hi = -before_s - margin_s, after_s + margin_s
    windows = [(o + lo, o + hi) for o in onset[pert]]
    windows += [(t + min(delays) + lo, t + max(delays) + hi) for t in toe[~pert]]
    whole = [(a, b) for a, b in zip(strides["heel_strike_s"][~pert], strides["end_s"][~pert], strict=True)]
    direct = covered(time_s, windows)
    return float(direct.mean()), float((direct | covered(time_s, whole)).mean())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", nargs="?", default=RESULTS_DIR)
    parser.add_argument("--configfile", nargs="*", default=["config/config.yaml"])
    parser.add_argument("--margin-s", type=float, default=0.1, help="spline margin on each side of a window (s)")
    args = parser.parse_args()
    cfg: dict = {}
    for f in args.configfile:
        for key, value in (yaml.safe_load(Path(f).read_text()) or {}).items():
            cfg[key] = {**cfg.get(key, {}), **value} if isinstance(value, dict) else value
    window, trials = stage_settings(cfg, "impedance").response.window, cfg["study"]
    before = window.initial_state_span_s + window.before_s
    onsets_s = [o / 1e3 for o in trials["perturbation_onsets_ms"]]
    rows = []
    for table in sorted(Path(args.results, "strides").glob("*/pert*.strides.tsv")):
        subject, trial = table.parent.name, table.name.split(".")[0]
        angles = pd.read_csv(Path(args.results, "ik", subject, f"{trial}.angles.tsv"), sep="\t", usecols=["time_s"])
        direct, depends = trial_shares(
            angles["time_s"].to_numpy(),
            pd.read_csv(table, sep="\t"),
            onsets_s,
            before,
            window.after_s,
            args.margin_s,
        )
        rows.append(
            {
                "subject": subject,
                "trial": trial,
                "frames": len(angles),
                "read_directly_pct": 100 * direct,
                "fits_depend_on_pct": 100 * depends,
            }
        )
    if not rows:
        raise SystemExit(f"{args.results}: no perturbation trials' stride tables")
    frame = pd.DataFrame(rows)
    print(frame.to_string(index=False, float_format=lambda v: f"{v:.1f}"))
    w = frame["frames"] / frame["frames"].sum()
    print(
        f"all {len(frame)} perturbation trials: read directly {(w * frame.read_directly_pct).sum():.1f} %, "
        f"fits depend on {(w * frame.fits_depend_on_pct).sum():.1f} % of the frames"
    )


if __name__ == "__main__":
    main()
