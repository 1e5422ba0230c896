"""Does a design identify the bi-articular hip-knee stiffness? The planner's answer for the default pilot, with the
thigh rod alone and with both rods.

Usage: nice -n 10 python benchmarks/coupling_plan.py [--onsets-ms 50 175 300] [--strides 20 60] [--seed 2024]
                                                     [--shank-force-n 40]

The pilot is :mod:`benchmarks.planner_check`'s: one synthetic trial with the device at the coordinate level
(:func:`loper_analysis.synthetic.coordinate_trials.perturbation_experiment`, the lab of ``config/config.yaml``
``synthetic``, 0.001 rad of angle noise), perturbed at the onset by the thigh rod alone, the subject answering
with the default study's group values at that onset and no inter-joint coupling; its fit of all its perturbed
strides (the pipeline's :func:`~loper_analysis.impedance.identification.impedance.fit_onset`) gives the planned K
and D. The planner (:func:`loper_analysis.planning.pilot_plan.pilot_plan`, the default conditional counterfactual
with the pilot's stretches) then plans the fit with the hip-knee coupling (``PlanSettings(couplings=("hip_knee",))``,
the coupling planned at 0) for the thigh rod alone and with a second rod of ``--shank-force-n`` at the shank, and
the same designs without the coupling for the price it costs the other parameters.

Printed per onset and design: the predicted SD and 95 % half-width of K_hip_knee at each stride count, the verdict
(half-width within the study's 2 N·m/rad) and the strides the verdict needs; and the SD of hip and knee K with the
coupling over their SD without it.
"""

from __future__ import annotations

import argparse
import logging
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, parameter_column
from loper_analysis.impedance.identification.impedance import IdentificationSettings, fit_onset
from loper_analysis.impedance.responses import ResponseSettings
from loper_analysis.planning.pilot_plan import PlanningSettings, pilot_plan
from loper_analysis.planning.window import PlanSettings
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry
from loper_analysis.synthetic.coordinate_trials import perturbation_experiment

sys.path.insert(0, str(Path(__file__).resolve().parent))
from planner_check import ANGLE_NOISE_SD_RAD, HEIGHT_M, MASS_KG, TRUTH, lab  # noqa: E402  (the same pilot)


def pilot(onset_ms: int, seed: int, counts: list[int], params) -> tuple[dict, np.ndarray]:
    """The pilot's trial and its fitted K, D (6,) at ``onset_ms``."""
    truth = TRUTH[onset_ms]
    full, cut = perturbation_experiment(
        [seed, 0],
        params,
        HEIGHT_M,
        onset_ms,
        truth,
        counts,
        angle_noise_sd_rad=ANGLE_NOISE_SD_RAD,
        **lab(None, seed, onset_ms, truth),
    )
    ident = IdentificationSettings(seed=seed)
    fit = fit_onset([cut[max(counts)]], params, onset_ms, "pilot", None, [full], ResponseSettings(), ident)
    rows = fit.rows.set_index("joint")
    planned = np.array([rows.loc[j, parameter_column(p)] for j in JOINTS for p in ("K", "D")], float)
    return full, np.clip(planned, ident.lower, ident.upper)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--onsets-ms", type=int, nargs="+", default=sorted(TRUTH), choices=sorted(TRUTH))
    ap.add_argument("--strides", type=int, nargs="+", default=[20, 60])
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--shank-force-n", type=float, default=40.0)
    args = ap.parse_args()
    logging.basicConfig(level=logging.WARNING)
    params = segment_parameters_from_anthropometry(HEIGHT_M, MASS_KG)
    t0 = time.perf_counter()
    rows = []
    for onset in args.onsets_ms:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            full, planned = pilot(onset, args.seed, args.strides, params)
        print(f"onset {onset} ms: planned K, D {np.round(planned, 3).tolist()} ({time.perf_counter() - t0:.0f} s)")
        for design, shank in (("thigh rod", 0.0), ("both rods", args.shank_force_n)):
            tables = {}
            for couplings in ((), ("hip_knee",)):
                settings = PlanningSettings(
                    onsets_ms=(onset,),
                    strides=tuple(args.strides),
                    plan=PlanSettings(shank_pulse_force_n=shank, couplings=couplings),
                )
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    tables[couplings], _ = pilot_plan([full], params, settings, "pilot", impedance=planned)
            coupled, plain = tables[("hip_knee",)], tables[()]
            for n in args.strides:
                row = coupled[(coupled["joint"] == "hip_knee") & (coupled["n_strides"] == n)].iloc[0]

                def sd(table, joint, n=n):
                    sel = (table["joint"] == joint) & (table["parameter"] == "K") & (table["n_strides"] == n)
                    return float(table.loc[sel, "predicted_sd"].iloc[0])

                rows.append(
                    {
                        "onset_ms": onset,
                        "design": design,
                        "n_strides": n,
                        "K_hip_knee_sd": row["predicted_sd"],
                        "K_hip_knee_half_width": row["ci95_half_width"],
                        "verdict": row["verdict"],
                        "strides_to_identify": row["strides_to_identify"],
                        "hip_K_sd_ratio": sd(coupled, "hip") / sd(plain, "hip"),
                        "knee_K_sd_ratio": sd(coupled, "knee") / sd(plain, "knee"),
                        "scatter": row["scatter"],
                    }
                )
            print(pd.DataFrame(rows[-len(args.strides) :]).to_string(index=False, float_format="%.3g"), flush=True)
    table = pd.DataFrame(rows)
    print(f"\n{time.perf_counter() - t0:.0f} s")
    print(table.to_string(index=False, float_format="%.3g"))


if __name__ == "__main__":
    main()
