"""The synthetic validation study of the identification (``docs/validation.md``).

For every combination of K in {0, 75, 150} and D in {0, 2, 4} per joint
(3^6 = 729) a representative subject's swing leg is perturbed by a 40 N,
100 ms forward pulse with the robot's rise time and overshoot
(:func:`loper_analysis.device.pulse.pulse_force`); the "measured" perturbed stride is
simulated with the true impedance by the same equations of motion but a much
finer RK4 step (``truth_substeps``) than the identification uses, then sampled
like motion capture, and the force like the robot log (``force_rate_hz``). The
identification recovers K and D from these samples, once without
and once with uniform noise (0.01 rad or m peak-to-peak) added independently to
the perturbed and the unperturbed generalised coordinates.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, PARAMETERS
from loper_analysis.device.pulse import pulse_force
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import (
    DEFAULT_LOWER,
    DEFAULT_UPPER,
    FIT_TOLERANCE,
    INITIAL_STATE_DEGREE,
    MERGE_TOLERANCE,
    N_STARTS,
    N_SUBSTEPS,
    identify_impedance,
    per_step,
    prepare_window,
    simulate_deviation,
    stage_times_s,
    window_options,
)
from loper_analysis.impedance.responses.response_window import ResponseWindow
from loper_analysis.reference import STUDY_DEVICE, STUDY_VALIDATION_NO_NOISE, STUDY_VALIDATION_NOISE
from loper_analysis.study_design import PULSE_DURATION_S, PULSE_FORCE_N, SEED
from loper_analysis.swing_leg.dynamics import BRACE_ATTACHMENT_FRACTION, SegmentParameters, segment_coordinates

__all__ = [
    "ValidationSettings",
    "impedance_grid",
    "chunk_combinations",
    "nominal_swing",
    "perturbed_trial",
    "two_rod_trial",
    "coupled_trial",
    "validation_pulse",
    "with_pulse_at_stages",
    "validation_window",
    "run_validation_chunk",
    "summarize_errors",
    "CONDITIONS",
    "gather_validation_tables",
    "with_study_values",
]

CONDITIONS: tuple[str, ...] = ("no_noise", "noise")


@dataclass(frozen=True)
class ValidationSettings:
    """Settings of the validation study (SI units); the defaults are the study's design.

    ``window``: the fit window and initial-state span
    (:class:`~loper_analysis.impedance.responses.response_window.ResponseWindow`, s), checked to lie inside the
    simulated swing ``0 .. swing_duration_s`` around ``onset_s`` (:meth:`ResponseWindow.check_in_swing`).
    ``subject_height_m`` (m), ``subject_mass_kg`` (kg) and ``attachment_fraction_of_thigh`` (the rod's place on
    the thigh from the hip): the representative subject whose segments are simulated (read from the segment
    table by the simulations, so no part of the repr, a rule's rerun trigger); ``n_chunks``: the parallel jobs
    the combinations are split into.
    """

    stiffness_levels_nm_per_rad: tuple[float, ...] = (0.0, 75.0, 150.0)
    damping_levels_nms_per_rad: tuple[float, ...] = (0.0, 2.0, 4.0)
    sample_rate_hz: float = 128.0
    swing_duration_s: float = 0.6
    onset_s: float = 0.05
    pulse_force_n: float = PULSE_FORCE_N
    pulse_duration_s: float = PULSE_DURATION_S
    pulse_rise_time_s: float = STUDY_DEVICE["rise_time_ms"][0] / 1e3
    pulse_overshoot_pct: float = STUDY_DEVICE["overshoot_pct"][0]
    force_rate_hz: float = 1000.0
    force_direction_deg: float = 0.0
    window: ResponseWindow = field(default_factory=ResponseWindow)
    noise_peak_to_peak: float = 0.01
    n_starts: int = N_STARTS
    n_substeps: int = N_SUBSTEPS
    truth_substeps: int = 32
    tolerance: float = FIT_TOLERANCE
    merge_tolerance: float = MERGE_TOLERANCE
    reference_cutoff_hz: float | None = None
    initial_state_degree: int = INITIAL_STATE_DEGREE
    seed: int = SEED
    lower: tuple[float, ...] = tuple(DEFAULT_LOWER)
    upper: tuple[float, ...] = tuple(DEFAULT_UPPER)
    subject_height_m: float = field(default=1.73, repr=False)
    subject_mass_kg: float = field(default=64.9, repr=False)
    attachment_fraction_of_thigh: float = field(default=BRACE_ATTACHMENT_FRACTION, repr=False)
    n_chunks: int = 2

    def __post_init__(self):
        self.window.check_in_swing(self.onset_s, self.swing_duration_s)


def impedance_grid(stiffness_levels, damping_levels) -> np.ndarray:
    """All combinations (n_K n_D)^3 x 6 of K and D levels per joint, order of PARAMETERS.

    The last parameter (D_ankle) varies fastest.
    """
    per_joint = [(k, d) for k in stiffness_levels for d in damping_levels]
    combos = [sum(c, ()) for c in itertools.product(per_joint, repeat=3)]
    return np.array(combos, dtype=float)


def chunk_combinations(n_combinations: int, n_chunks: int, chunk: int) -> np.ndarray:
    """Indices of combination chunk ``chunk`` (0-based) of ``n_chunks``.

    Chunks take every ``n_chunks``-th combination so that each holds the same
    mix of stiff and compliant cases (and so about the same work).
    """
    for name, v in (("n_chunks", n_chunks), ("chunk", chunk)):
        if isinstance(v, bool) or int(v) != v:
            raise LoperInputError(f"{name} must be an integer, got {v!r}")
    n_chunks, chunk = int(n_chunks), int(chunk)
    if not 1 <= n_chunks <= n_combinations:
        raise LoperInputError(f"n_chunks must lie in 1 .. {n_combinations}, got {n_chunks}")
    if not 0 <= chunk < n_chunks:
        raise LoperInputError(f"chunk must lie in 0 .. {n_chunks - 1}, got {chunk}")
    return np.arange(chunk, n_combinations, n_chunks)


def nominal_swing(time_s: np.ndarray, swing_duration_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Smooth swing-phase kinematics of slow treadmill walking.

    Time 0 is toe-off. Returns the coordinates q (n, 4) [pelvis x (m), thigh,
    shank, foot (rad)] and the pelvis angle (n,) in rad. Joint angles follow
    the shape of normal slow walking: hip flexion -0.15 -> 0.45 rad, knee
    flexion 0.70 -> peak 1.10 rad at 25 % of swing -> 0.10 rad, ankle from
    -0.25 rad plantarflexion back to neutral.
    """
    s = np.asarray(time_s, dtype=float) / swing_duration_s

    def smoothstep(x):
        x = np.clip(x, 0, 1)
        return x * x * x * (10 - 15 * x + 6 * x * x)

    hip = -0.15 + 0.60 * smoothstep(s / 0.8) - 0.05 * smoothstep((s - 0.8) / 0.2)
    knee = 0.70 + 0.40 * smoothstep(s / 0.25) - 1.00 * smoothstep((s - 0.25) / 0.75)
    ankle = -0.25 + 0.25 * smoothstep(s / 0.5) + 0.05 * np.sin(np.pi * np.clip(s, 0, 1))
    pelvis_angle = 0.10 + 0.02 * np.sin(2 * np.pi * (s * swing_duration_s) / (1.667 / 2))
    pelvis_x = 0.015 * np.sin(2 * np.pi * (s * swing_duration_s) / (1.667 / 2))
    q = segment_coordinates(np.stack([hip, knee, ankle], axis=-1), pelvis_angle, pelvis_x)
    return q, pelvis_angle


def perturbed_trial(params: SegmentParameters, impedance, settings: ValidationSettings):
    """Noise-free unperturbed and perturbed samples for one true impedance.

    Returns (time_s (n,), q_u (n, 4), q_p (n, 4), force_p (k, 2), pelvis (n,),
    force_time_s (k,)): the coordinates at ``sample_rate_hz``, the pulse
    (:func:`loper_analysis.device.pulse.pulse_force`, commanded at the onset) sampled
    like the robot log at ``force_rate_hz`` on the same clock. The data run
    from 0.1 s before the window to 0.05 s after it. The truth is plain RK4
    with ``truth_substeps`` steps per sample and the pulse itself at every
    stage (:func:`with_pulse_at_stages`), independent of how the
    identification turns sampled forces into stage forces.
    """
    t, qu, pelvis, window = _truth_window(params, settings)
    n = len(t)
    deviation = simulate_deviation(window, np.asarray(impedance, dtype=float)[None])
    qp = qu.copy()
    qp[n - window.n_samples :] += deviation[0]
    t_force = _robot_clock(t, settings)
    return t, qu, qp, validation_pulse(t_force, settings), pelvis, t_force


def two_rod_trial(params: SegmentParameters, impedance, settings: ValidationSettings, shank_scale=1.0, thigh_scale=1.0):
    """Noise-free samples of a stride pushed by two rods: :func:`perturbed_trial`'s, the study's pulse at the thigh
    times ``thigh_scale`` and the same pulse at the shank times ``shank_scale`` (``params`` with a
    ``shank_attachment_m``), both commanded at the onset.

    Returns (time_s (n,), q_u (n, 4), q_p (n, 4), force_p (k, 2), pelvis (n,), force_time_s (k,), shank_force_p
    (k, 2)); the first six as :func:`perturbed_trial` returns them, so that ``validation_window(params, settings,
    trial[:6], shank_force_perturbed_n=trial[6])`` is the window the fit sees.
    """
    if params.shank_attachment_m is None:
        raise LoperInputError("two_rod_trial: the segment parameters place no rod on the shank (shank_attachment_m)")
    t, qu, pelvis, window = _truth_window(params, settings)
    pulse = validation_pulse(stage_times_s(window), settings)
    window = replace(
        window, force_perturbed_n=per_step(thigh_scale * pulse), shank_force_perturbed_n=per_step(shank_scale * pulse)
    )
    qp = qu.copy()
    qp[len(t) - window.n_samples :] += simulate_deviation(window, np.asarray(impedance, dtype=float)[None])[0]
    t_force = _robot_clock(t, settings)
    force = validation_pulse(t_force, settings)
    return t, qu, qp, thigh_scale * force, pelvis, t_force, shank_scale * force


def coupled_trial(
    params: SegmentParameters,
    impedance,
    settings: ValidationSettings,
    couplings=("hip_knee",),
    shank_scale: float = 0.0,
):
    """Noise-free samples of a stride whose true impedance has inter-joint couplings besides K and D per joint.

    ``impedance``: (6 + number of couplings,) K and D per joint (order of ``PARAMETERS``), then each coupling's
    stiffness (N·m/rad) in the order of :data:`~loper_analysis.constants.COUPLINGS`; ``couplings``: their names.
    The stride is pushed by the study's pulse at the thigh and, with ``shank_scale`` (``params`` with a
    ``shank_attachment_m``), by the same pulse times ``shank_scale`` at the shank; the truth is
    :func:`perturbed_trial`'s fine-step RK4 with the pulses at every stage.

    Returns
    -------
    tuple
        (time_s (n,), q_u (n, 4), q_p (n, 4), force_p (k, 2), pelvis (n,), force_time_s (k,), shank_force_p (k, 2)) as
        :func:`two_rod_trial` returns them (the shank's force zero without a shank push); without couplings and
        the shank push the first six are :func:`perturbed_trial`'s to the bit.
    """
    if shank_scale and params.shank_attachment_m is None:
        raise LoperInputError("coupled_trial: a shank push needs segment parameters with a shank_attachment_m")
    t, qu, pelvis, window = _truth_window(params, settings)
    window = replace(window, couplings=couplings)
    if shank_scale:
        pulse = validation_pulse(stage_times_s(window), settings)
        window = replace(window, shank_force_perturbed_n=per_step(shank_scale * pulse))
    qp = qu.copy()
    qp[len(t) - window.n_samples :] += simulate_deviation(window, np.asarray(impedance, dtype=float)[None])[0]
    t_force = _robot_clock(t, settings)
    force = validation_pulse(t_force, settings)
    return t, qu, qp, force, pelvis, t_force, shank_scale * force


def _robot_clock(t: np.ndarray, settings: ValidationSettings) -> np.ndarray:
    """The robot log's sample times (s) at ``force_rate_hz`` over the samples ``t``, on their clock."""
    return t[0] + np.arange(int(np.floor((t[-1] - t[0]) * settings.force_rate_hz + 1e-9)) + 1) / settings.force_rate_hz


_TRUTH_WINDOWS: dict = {}


def _truth_window(params: SegmentParameters, settings: ValidationSettings):
    """Sample times, q_u, pelvis angle and the truth's prepared window (it does not depend on the impedance:
    kept for the last few parameter sets and settings)."""
    key = (params.packed.tobytes(), settings)
    if key not in _TRUTH_WINDOWS:
        fs = settings.sample_rate_hz
        t_start = settings.onset_s - settings.window.before_s - 0.1
        t_end = settings.onset_s + settings.window.after_s + 0.05
        n = int(np.floor((t_end - t_start) * fs)) + 1
        t = t_start + np.arange(n) / fs
        qu, pelvis = nominal_swing(t, settings.swing_duration_s)
        # truth: the same equations, integrated with a much finer plain RK4 step (the pulse itself at every stage)
        window = prepare_window(
            t,
            qu,
            qu,
            params,
            settings.onset_s,
            pelvis_angle_unperturbed_rad=pelvis,
            pelvis_angle_perturbed_rad=pelvis,
            window=ResponseWindow(before_s=settings.window.before_s, after_s=t[-1] - settings.onset_s),
            n_substeps=settings.truth_substeps,
        )
        window = with_pulse_at_stages(window, settings)
        if len(_TRUTH_WINDOWS) >= 4:
            _TRUTH_WINDOWS.pop(next(iter(_TRUTH_WINDOWS)))
        for a in (t, qu, pelvis):
            a.setflags(write=False)
        _TRUTH_WINDOWS[key] = (t, qu, pelvis, window)
    return _TRUTH_WINDOWS[key]


def validation_pulse(time_s, settings: ValidationSettings) -> np.ndarray:
    """The study's pulse (k, 2) in N, world x/y, at ``time_s`` (k,):
    :func:`loper_analysis.device.pulse.pulse_force` along ``force_direction_deg``, commanded at ``onset_s`` for
    ``pulse_duration_s``."""
    ang = np.deg2rad(settings.force_direction_deg)
    f = pulse_force(
        time_s,
        settings.onset_s,
        settings.pulse_duration_s,
        settings.pulse_force_n,
        settings.pulse_rise_time_s,
        settings.pulse_overshoot_pct,
    )
    return f[:, None] * np.array([np.cos(ang), np.sin(ang)])


def with_pulse_at_stages(window, settings: ValidationSettings):
    """The window with the study's pulse itself at each of its RK4 stage times (plain RK4): how the truth sees it."""
    return replace(window, force_perturbed_n=per_step(validation_pulse(stage_times_s(window), settings)))


def validation_window(
    params: SegmentParameters, settings: ValidationSettings, trial, qu_measured=None, qp_measured=None, **overrides
):
    """The identification window of one validation trial (from :func:`perturbed_trial`).

    The force reaches the identification at ``force_rate_hz``
    (``force_time_s`` of :func:`prepare_window`).
    ``qu_measured`` / ``qp_measured`` replace the noise-free coordinates in the
    prediction error and the initial state (noise condition); the reference for
    ``u_ff`` stays the noise-free unperturbed stride. ``overrides`` go to
    :func:`prepare_window`.
    """
    t, qu, qp, fp, pelvis, t_force = trial
    kwargs = dict(
        force_perturbed_n=fp,
        force_time_s=t_force,
        pelvis_angle_unperturbed_rad=pelvis,
        pelvis_angle_perturbed_rad=pelvis,
        q_reference=qu,
        reference_cutoff_hz=settings.reference_cutoff_hz,
        **window_options(settings),
    )
    kwargs.update(overrides)
    return prepare_window(
        t,
        qu if qu_measured is None else qu_measured,
        qp if qp_measured is None else qp_measured,
        params,
        settings.onset_s,
        **kwargs,
    )


def run_validation_chunk(
    params: SegmentParameters, settings: ValidationSettings, combinations
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Simulate and identify the given combination indices in both conditions.

    Returns ``errors`` (one row per combination x condition x parameter:
    condition, combination, parameter, true, estimate, error, ci95_low,
    ci95_high) and ``fits`` (one row per combination x condition: VAF per
    joint, cost (rad^2), starts, starts at the best cost, simulations, success, message).
    """
    grid = impedance_grid(settings.stiffness_levels_nm_per_rad, settings.damping_levels_nms_per_rad)
    err_rows, fit_rows = [], []
    for c in np.asarray(combinations, dtype=int):
        if not 0 <= c < len(grid):
            raise LoperInputError(f"combination {c} outside 0 .. {len(grid) - 1}")
        truth = grid[c]
        trial = perturbed_trial(params, truth, settings)
        t, qu, qp = trial[:3]
        for ci, condition in enumerate(CONDITIONS):
            qu_m, qp_m = qu, qp
            if condition == "noise":
                rng = np.random.default_rng([settings.seed, int(c), ci, 0])
                a = settings.noise_peak_to_peak / 2
                qu_m = qu + rng.uniform(-a, a, qu.shape)
                qp_m = qp + rng.uniform(-a, a, qp.shape)
            window = validation_window(params, settings, trial, qu_m, qp_m)
            fit = identify_impedance(
                window,
                n_starts=settings.n_starts,
                seed=np.random.SeedSequence([settings.seed, int(c), ci, 1]),
                lower=settings.lower,
                upper=settings.upper,
                tolerance=settings.tolerance,
                merge_tolerance=settings.merge_tolerance,
            )
            for i, name in enumerate(PARAMETERS):
                err_rows.append(
                    {
                        "condition": condition,
                        "combination": int(c),
                        "parameter": name,
                        "true": truth[i],
                        "estimate": fit.estimate[i],
                        "error": fit.estimate[i] - truth[i],
                        "ci95_low": fit.ci95_low[i],
                        "ci95_high": fit.ci95_high[i],
                        "success": fit.success,
                    }
                )
            row = {"condition": condition, "combination": int(c)}
            row.update({f"vaf_{j}_pct": fit.vaf_pct[k] for k, j in enumerate(JOINTS)})
            row.update(
                cost_rad2=fit.cost,
                n_starts=fit.n_starts,
                n_starts_at_best=fit.n_starts_at_best,
                n_simulations=fit.n_simulations,
                success=fit.success,
                message=fit.message,
            )
            fit_rows.append(row)
    return pd.DataFrame(err_rows), pd.DataFrame(fit_rows)


def summarize_errors(errors: pd.DataFrame) -> pd.DataFrame:
    """min / max / SD of the error per condition and parameter (the study's table layout)."""
    need = {"condition", "parameter", "error"}
    if not need <= set(errors.columns):
        raise LoperInputError(f"errors table lacks column(s) {sorted(need - set(errors.columns))}")
    g = errors.groupby(["condition", "parameter"], sort=False)["error"]
    out = pd.DataFrame(
        {
            "min_error": g.min(),
            "max_error": g.max(),
            "sd_error": g.std(ddof=1),
            "max_abs_error": g.apply(lambda e: e.abs().max()),
            "n": g.size(),
        }
    ).reset_index()
    order = {p: i for i, p in enumerate(PARAMETERS)}
    cond = {c: i for i, c in enumerate(CONDITIONS)}
    out = out.sort_values(by=["condition", "parameter"], key=lambda s: s.map(cond | order)).reset_index(drop=True)
    return out


def gather_validation_tables(error_chunks, fit_chunks) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """Concatenate the chunks' error and fit tables (sorted by condition, combination) and summarise them.

    Returns ``errors``, ``fits`` and the summary (:func:`summarize_errors` with the study's values).
    """
    cond = {c: i for i, c in enumerate(CONDITIONS)}
    par = {p: i for i, p in enumerate(PARAMETERS)}

    def gather(frames, keys):
        df = pd.concat(list(frames), ignore_index=True)
        return df.sort_values(
            keys, key=lambda s: s.map(cond) if s.name == "condition" else (s.map(par) if s.name == "parameter" else s)
        ).reset_index(drop=True)

    errors = gather(error_chunks, ["condition", "combination", "parameter"])
    fits = gather(fit_chunks, ["condition", "combination"])
    return errors, fits, with_study_values(summarize_errors(errors))


def with_study_values(summary: pd.DataFrame) -> pd.DataFrame:
    """Add the study's min / max / SD of the error beside ours (no SD without noise in the study)."""
    study = pd.DataFrame(
        {
            "parameter": list(PARAMETERS),
            "study_min_error": [STUDY_VALIDATION_NOISE[p][0] for p in PARAMETERS],
            "study_max_error": [STUDY_VALIDATION_NOISE[p][1] for p in PARAMETERS],
            "study_sd_error": [STUDY_VALIDATION_NOISE[p][2] for p in PARAMETERS],
        }
    ).assign(condition="noise")
    no_noise = pd.DataFrame(
        {
            "parameter": list(PARAMETERS),
            "study_min_error": [STUDY_VALIDATION_NO_NOISE[p[0]][0] for p in PARAMETERS],
            "study_max_error": [STUDY_VALIDATION_NO_NOISE[p[0]][1] for p in PARAMETERS],
            "study_sd_error": [np.nan] * 6,
            "condition": "no_noise",
        }
    )
    return summary.merge(pd.concat([no_noise, study]), on=["condition", "parameter"], how="left")
