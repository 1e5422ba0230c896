"""How precise can K and D be with the validation study's noise? Cramér-Rao bounds.

Usage: python benchmarks/noise_information_limit.py
For a few true impedances, prints the smallest parameter SD any unbiased
estimator can reach from the prediction error alone (white noise of the
perturbed-minus-unperturbed angle difference, SD = sqrt(2) * 0.01 / sqrt(12)
rad for uniform 0.01 rad peak-to-peak noise on both strides), beside the
study's reported SDs. The initial-state noise only adds to these.
"""

from __future__ import annotations

import numpy as np

from loper_analysis.constants import PARAMETERS
from loper_analysis.impedance.identification import prepare_window, response_jacobian
from loper_analysis.impedance.identification.validation import ValidationSettings, perturbed_trial
from loper_analysis.reference import STUDY_VALIDATION_NOISE
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry


def main() -> None:
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    s = ValidationSettings()
    sd_noise = np.sqrt(2) * s.noise_peak_to_peak / np.sqrt(12)
    print("true impedance".ljust(34) + "".join(p.rjust(9) for p in PARAMETERS))
    for truth in ([0, 0, 0, 0, 0, 0], [75, 2, 0, 0, 0, 0], [75, 2, 75, 2, 75, 2], [150, 4, 150, 4, 150, 4]):
        truth = np.asarray(truth, float)
        t, qu, qp, fp, pel, tf = perturbed_trial(params, truth, s)
        w = prepare_window(
            t,
            qu,
            qp,
            params,
            s.onset_s,
            force_perturbed_n=fp,
            force_time_s=tf,
            pelvis_angle_unperturbed_rad=pel,
            pelvis_angle_perturbed_rad=pel,
        )
        J = response_jacobian(w, truth + 1e-9)
        crlb = sd_noise * np.sqrt(np.diag(np.linalg.inv(J.T @ J)))
        print(f"CRLB SD at {truth.astype(int).tolist()}".ljust(34) + "".join(f"{v:9.3g}" for v in crlb))
    print("study SD (noise)".ljust(34) + "".join(f"{STUDY_VALIDATION_NOISE[p][2]:9.3g}" for p in PARAMETERS))


if __name__ == "__main__":
    main()
