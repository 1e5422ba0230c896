"""What the inter-joint coupling option costs the default six-parameter path: bit-identity and speed against
another source tree (e.g. the commit before the option), and the coupled path's own speed.

Usage::

    mkdir -p /tmp/before && git archive <commit> src | tar -x -C /tmp/before
    nice -n 10 python benchmarks/coupling_speed.py --before-src /tmp/before/src [--calls 150000] [--fits 3]
                                                   [--rounds 4]
    python benchmarks/coupling_speed.py --measure [--calls N] [--fits N]   # one tree's numbers as JSON

The driver runs ``--measure`` in a fresh interpreter for the other tree (``PYTHONPATH`` = ``--before-src``) and
for this one, alternating which goes first from round to round (``--rounds``), so that a busy machine slows both
alike. Each run:

* hashes (SHA-256 of the bytes) ``simulate_deviation`` of 20 seeded impedance sets on four windows of the
  validation study's strides (mid and study impedance, noise-free and with the validation's noise; one window
  pushed by two rods) and the fits (``identify_impedance``, 10 starts: estimate, SD, intervals, correlation,
  costs, every start's end point, the simulations counted) of the noisy windows: equal hashes are results equal
  to the bit;
* times ``--calls`` calls of ``simulate_deviation`` with one impedance set on the mid noisy window (the fit's
  inner call, Python layer included), and ``--fits`` fits of the noisy study window (median);
* where the tree has the option, the same with the hip-knee coupling (7 parameters), timed and not hashed.

Printed: whether every hash agrees, and per tree the median over rounds of the time per call and per fit, with
the ratio this tree / other tree.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve()
SRC = HERE.parents[1] / "src"
#: The study's hip (K 55, D 3.5), its knee (3, 0.1) and an ankle of 8 and 0.3; the validation's mid impedance.
STUDY = np.array([55.0, 3.5, 3.0, 0.1, 8.0, 0.3])
MID = np.array([75.0, 2.0, 75.0, 2.0, 75.0, 2.0])


def _digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(np.asarray(a, dtype=float)).tobytes())
    return h.hexdigest()[:16]


def measure(calls: int, fits: int) -> dict:
    """One tree's hashes and times (see the module docstring)."""
    from loper_analysis.impedance.identification import identify_impedance, simulate_deviation
    from loper_analysis.impedance.identification.validation import (
        ValidationSettings,
        perturbed_trial,
        two_rod_trial,
        validation_window,
    )
    from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry

    params = segment_parameters_from_anthropometry(1.73, 64.9)
    two = params.replace(shank_attachment_m=0.85 * params.length_m[1])
    settings = ValidationSettings()
    a = settings.noise_peak_to_peak / 2

    def noisy(p, trial, seed, **extra):
        rng = np.random.default_rng(seed)
        qu, qp = trial[1], trial[2]
        return validation_window(
            p, settings, trial[:6], qu + rng.uniform(-a, a, qu.shape), qp + rng.uniform(-a, a, qp.shape), **extra
        )

    mid, study = perturbed_trial(params, MID, settings), perturbed_trial(params, STUDY, settings)
    rods = two_rod_trial(two, STUDY, settings, 1.0)
    windows = {
        "mid": validation_window(params, settings, mid),
        "mid_noise": noisy(params, mid, 1),
        "study_noise": noisy(params, study, 2),
        "two_rods_noise": noisy(two, rods, 3, shank_force_perturbed_n=rods[6]),
    }
    lo, hi = np.array([0.0, 0.0] * 3), np.array([200.0, 10.0] * 3)
    sets = np.random.default_rng(5).uniform(lo, hi, (20, 6))
    out: dict = {"hash": {}, "time": {}}
    for name, w in windows.items():
        out["hash"][f"simulate {name}"] = _digest(simulate_deviation(w, sets))
    fitted = {}
    for name in ("study_noise", "two_rods_noise"):
        f = identify_impedance(windows[name], n_starts=10, seed=0)
        fitted[name] = f
        out["hash"][f"fit {name}"] = _digest(
            f.estimate,
            f.sd,
            f.ci95_low,
            f.ci95_high,
            f.correlation,
            [f.cost, f.n_simulations, f.n_starts_at_best],
            f.start_costs,
            f.start_estimates,
            f.model,
        )

    def time_calls(window, row) -> float:
        simulate_deviation(window, row)
        t0 = time.perf_counter()
        for _ in range(calls):
            simulate_deviation(window, row)
        return (time.perf_counter() - t0) / calls

    def time_fits(window) -> float:
        times = []
        for k in range(fits):
            t0 = time.perf_counter()
            identify_impedance(window, n_starts=10, seed=k)
            times.append(time.perf_counter() - t0)
        return statistics.median(times)

    w = windows["mid_noise"]
    out["time"]["call"] = time_calls(w, MID[None])
    out["time"]["fit"] = time_fits(windows["study_noise"])
    if hasattr(w, "couplings"):
        coupled = replace(w, couplings=("hip_knee",))
        out["time"]["call coupled"] = time_calls(coupled, np.append(MID, -5.0)[None])
        out["time"]["fit coupled"] = time_fits(replace(windows["study_noise"], couplings=("hip_knee",)))
    return out


def _run(src: Path, calls: int, fits: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(src))
    cmd = [sys.executable, str(HERE), "--measure", "--calls", str(calls), "--fits", str(fits)]
    done = subprocess.run(cmd, env=env, check=True, capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--measure", action="store_true", help="print this interpreter's tree's numbers as JSON")
    ap.add_argument("--before-src", type=Path, help="the other tree's src directory")
    ap.add_argument("--calls", type=int, default=150_000)
    ap.add_argument("--fits", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=4)
    args = ap.parse_args()
    if args.measure:
        print(json.dumps(measure(args.calls, args.fits)))
        return
    if args.before_src is None:
        ap.error("--before-src is needed (or --measure)")
    trees = {"before": args.before_src.resolve(), "after": SRC}
    runs: dict[str, list[dict]] = {"before": [], "after": []}
    t0 = time.perf_counter()
    for r in range(args.rounds):
        order = ("before", "after") if r % 2 == 0 else ("after", "before")
        for name in order:
            runs[name].append(_run(trees[name], args.calls, args.fits))
            print(f"round {r + 1}, {name}: {runs[name][-1]['time']}", flush=True)
    hashes = {name: runs[name][0]["hash"] for name in runs}
    same = all(h == hashes["before"] for h in (r["hash"] for rs in runs.values() for r in rs))
    print(f"\n{args.rounds} rounds, {args.calls} calls and {args.fits} fits each, {time.perf_counter() - t0:.0f} s")
    for key, value in hashes["after"].items():
        print(f"  {key:28s} after {value}  before {hashes['before'].get(key)}")
    print(f"every hash equal in every run: {same}")
    med = {n: {k: statistics.median(r["time"][k] for r in runs[n]) for k in runs[n][0]["time"]} for n in runs}
    print(
        f"simulate_deviation per call: before {1e6 * med['before']['call']:.2f} us, after "
        f"{1e6 * med['after']['call']:.2f} us, after / before {med['after']['call'] / med['before']['call']:.3f}"
    )
    print(
        f"fit (10 starts): before {med['before']['fit']:.3f} s, after {med['after']['fit']:.3f} s, "
        f"after / before {med['after']['fit'] / med['before']['fit']:.3f}"
    )
    ratios = [a["time"]["call"] / b["time"]["call"] for a, b in zip(runs["after"], runs["before"], strict=True)]
    print(f"per-round call ratios after / before: {', '.join(f'{x:.3f}' for x in ratios)}")
    if "call coupled" in med["after"]:
        print(
            f"with the hip-knee coupling (after): {1e6 * med['after']['call coupled']:.2f} us per call "
            f"({med['after']['call coupled'] / med['after']['call']:.3f} of the default), fit "
            f"{med['after']['fit coupled']:.3f} s"
        )


if __name__ == "__main__":
    main()
