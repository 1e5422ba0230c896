"""How precise can K and D be with the validation study's noise? The information limit of the fit.

Usage: python benchmarks/noise_information_limit.py

The noise of the validation study is on the generalised coordinates: independent uniform noise of 0.01 peak
to peak (SD sigma = 0.01 / sqrt(12)) on the cart and the thigh, shank and foot angles of both the perturbed
and the unperturbed stride. The fit's prediction error is a difference of joint angles, perturbed minus
unperturbed (``PreparedWindow.measured`` minus the model, whose reference is noise free); the joint angles
are linear in the coordinates, hip = pelvis - thigh, knee = shank - thigh, ankle = shank - foot
(:func:`loper_analysis.swing_leg.dynamics.joint_angles`, the pelvis angle noise free). The noise of one
sample of the prediction error therefore has the covariance ``S = 2 sigma^2 M M^T`` (M, 3 x 4: the joint
angles' map of the coordinates; 2: both strides), the same at every sample and independent between samples:

    S / (2 sigma^2) = [[1, 1, 0], [1, 2, 1], [0, 1, 2]]    (hip, knee, ankle)

The knee and the ankle carry two coordinates' noise, the hip one, and neighbouring joints share one. With the
model's sensitivity J (samples x hip/knee/ankle, 6 parameters; :func:`response_jacobian`) at the truth and
the initial state known, the smallest SD of an unbiased estimator is ``sqrt(diag((J^T Sigma^-1 J)^-1))``,
Sigma = S on the block diagonal (the Cramér-Rao bound for Gaussian noise of this covariance; for any noise
the smallest SD of a linear unbiased estimator, the weighted least squares). The fit's initial state comes
from noisy pre-onset samples and only adds to it.

Prints, for the study's design, the bound at four points of the grid beside the bound that would hold for
independent noise of SD sqrt(2) sigma on each joint angle (what the joint angles would carry if the noise
were on them instead of on the coordinates), then the range and the root mean square of the bound over all
729 combinations and over the 64 whose every K and D is inside the fit's bounds (75 or 150, 2 or 4), beside
the study's reported SDs. The root mean square is the smallest SD of errors pooled over the combinations that
unbiased estimates can have. Takes about 5 s.
"""

from __future__ import annotations

import time

import numpy as np

from loper_analysis.constants import PARAMETERS
from loper_analysis.impedance.identification import response_jacobian
from loper_analysis.impedance.identification.validation import (
    ValidationSettings,
    impedance_grid,
    perturbed_trial,
    validation_window,
)
from loper_analysis.reference import STUDY_VALIDATION_NOISE
from loper_analysis.swing_leg.dynamics import SegmentParameters, joint_angles, segment_parameters_from_anthropometry

#: Four points of the grid (order of PARAMETERS): no impedance; the hip alone; every joint 75 / 2; every 150 / 4.
GRID_POINTS: tuple[tuple[float, ...], ...] = (
    (0, 0, 0, 0, 0, 0),
    (75, 2, 0, 0, 0, 0),
    (75, 2, 75, 2, 75, 2),
    (150, 4, 150, 4, 150, 4),
)


def joint_angle_map() -> np.ndarray:
    """The joint angles' linear map of the coordinates (3, 4): hip/knee/ankle from [x, thigh, shank, foot], the
    pelvis angle held (from :func:`~loper_analysis.swing_leg.dynamics.joint_angles` itself)."""
    return joint_angles(np.eye(4), 0.0).T


def uniform_sd(peak_to_peak: float) -> float:
    """SD of uniform noise of the given peak-to-peak width."""
    return float(peak_to_peak) / np.sqrt(12.0)


def residual_noise_covariance(coordinate_sd: float, n_strides: int = 2) -> np.ndarray:
    """Covariance (3, 3; rad^2) of one sample of the prediction error's noise, hip/knee/ankle.

    Every coordinate of each of ``n_strides`` strides (2: the perturbed and the unperturbed one, whose
    difference the prediction error is) carries independent noise of SD ``coordinate_sd``.
    """
    M = joint_angle_map()
    return n_strides * coordinate_sd**2 * (M @ M.T)


def information_bound(jacobian: np.ndarray, sample_covariance: np.ndarray) -> np.ndarray:
    """``sqrt(diag((J^T Sigma^-1 J)^-1))`` (6,) for a residual whose samples are independent with the same
    covariance.

    ``jacobian`` (n * k, p): rows samples, then the k components of a sample (hip/knee/ankle for the fit);
    ``sample_covariance`` (k, k): the covariance of one sample's noise; Sigma is it on the block diagonal.
    """
    k = sample_covariance.shape[0]
    J = np.asarray(jacobian, dtype=float).reshape(-1, k, jacobian.shape[-1])
    fisher = np.einsum("nai,ab,nbj->ij", J, np.linalg.inv(sample_covariance), J)
    return np.sqrt(np.diag(np.linalg.inv(fisher)))


def least_squares_sd(jacobian: np.ndarray, sample_covariance: np.ndarray) -> np.ndarray:
    """SD (6,) of the unweighted least squares (the fit's, initial state known) under that noise:
    ``sqrt(diag(A J^T Sigma J A))``, A = (J^T J)^-1."""
    k = sample_covariance.shape[0]
    J = np.asarray(jacobian, dtype=float)
    A = np.linalg.inv(J.T @ J)
    Jb = J.reshape(-1, k, J.shape[-1])
    middle = np.einsum("nai,ab,nbj->ij", Jb, sample_covariance, Jb)
    return np.sqrt(np.diag(A @ middle @ A))


def bounds_at(params: SegmentParameters, settings: ValidationSettings, truths) -> np.ndarray:
    """The information bound (n_truths, 6) at each true impedance (rows of ``truths``) for the design of
    ``settings``, the initial state known."""
    S = residual_noise_covariance(uniform_sd(settings.noise_peak_to_peak))
    out = []
    for truth in np.atleast_2d(np.asarray(truths, dtype=float)):
        window = validation_window(params, settings, perturbed_trial(params, truth, settings))
        out.append(information_bound(response_jacobian(window, truth), S))
    return np.array(out)


def study_sd() -> np.ndarray:
    """The study's reported SD of the error with noise (6,), order of PARAMETERS."""
    return np.array([STUDY_VALIDATION_NOISE[p][2] for p in PARAMETERS])


def interior(grid: np.ndarray, settings: ValidationSettings) -> np.ndarray:
    """Rows of ``grid`` whose every parameter lies strictly inside the fit's bounds."""
    return np.all((grid > np.asarray(settings.lower)) & (grid < np.asarray(settings.upper)), axis=1)


#: Width of the row labels of the printed tables.
LABEL_WIDTH = 40


def header(width: int = 10) -> str:
    """The parameters' names as a table header."""
    return "".ljust(LABEL_WIDTH) + "".join(p.rjust(width) for p in PARAMETERS)


def row(label: str, values) -> str:
    """One printed table row: a label, then a value per parameter."""
    return label.ljust(LABEL_WIDTH) + "".join(f"{v:>10.3g}" for v in values)


def range_row(label: str, values: np.ndarray) -> str:
    """One printed table row: a label, then min - max over the rows of ``values`` (n, 6) per parameter."""
    return label.ljust(LABEL_WIDTH) + "".join(f"{f'{a:.3g}-{b:.3g}':>14}" for a, b in zip(values.min(0), values.max(0)))


def main() -> None:
    t0 = time.perf_counter()
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    s = ValidationSettings()
    sigma = uniform_sd(s.noise_peak_to_peak)
    S = residual_noise_covariance(sigma)
    S_angles = 2 * sigma**2 * np.eye(3)
    print(f"noise SD per coordinate {sigma:.5f}; covariance of one prediction-error sample / (2 SD^2):")
    print(np.array2string(S / (2 * sigma**2), precision=3))
    print("\nat four points of the grid (initial state known)")
    print(header())
    for truth in GRID_POINTS:
        window = validation_window(params, s, perturbed_trial(params, truth, s))
        J = response_jacobian(window, truth)
        label = str([int(v) for v in truth])
        print(row(f"{label} noise on angles", information_bound(J, S_angles)))
        print(row(f"{label} on coordinates", information_bound(J, S)))
    grid = impedance_grid(s.stiffness_levels_nm_per_rad, s.damping_levels_nms_per_rad)
    bounds = bounds_at(params, s, grid)
    inside = interior(grid, s)
    print(f"\nover the grid, noise on the coordinates (initial state known); {len(grid)} combinations")
    print(header(14))
    print(range_row("range, all", bounds))
    print(range_row(f"range, {int(inside.sum())} inside the bounds", bounds[inside]))
    print(header())
    print(row("root mean square, all", np.sqrt(np.mean(bounds**2, axis=0))))
    print(row(f"root mean square, {int(inside.sum())} inside", np.sqrt(np.mean(bounds[inside] ** 2, axis=0))))
    print(row("study SD (noise)", study_sd()))
    print(f"\n{time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
