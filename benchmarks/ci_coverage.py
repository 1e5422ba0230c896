"""How often do the 95 % confidence intervals of the impedance fits hold the truth? A coverage measurement.

Usage: python benchmarks/ci_coverage.py [--mode coordinates|chain] [--subjects N] [--seed S] [--jobs J]
                                        [--ik-noise-scale X] [--keep PATH] [--configfile FILE ...]

N synthetic subjects (anthropometrics drawn from the study's subjects, true K and D drawn around the
group values as in the default study; the default design of ``config/config.yaml``: 2 trials of 45 s per
onset, noise model ``null_pairs``; ``--configfile config/paper.yaml``: the study's design, 4-minute
trials), three fits each (onsets 50, 175, 300 ms): 34 subjects give 102 fits.
Counts, per joint and parameter, the rows whose 95 % CI holds the truth and prints a Markdown table
(:func:`coverage_table`): over the fitted rows (``ok`` or ``not_identifiable``), over those whose interval
stands (less the rows ``not_identifiable`` because the joint's response is smaller than its residual or its
perturbed pairs scatter beyond the interval) and over the rows ``ok``, each with its share and binomial
(Clopper-Pearson) 95 % interval; median CI width, rows ``not_identifiable`` and those of each finding.

``--mode coordinates`` (default; 34 subjects with ``--jobs 2`` on two shared cores: 1-4 min at the default
design, 5-17 min at the study's): the
same simulated walking trials as the workflow (same seeds: subject C001 here is C001 there), taken at
the coordinate level. The motion-capture coordinates (128 Hz) become the joint-angle table with
IK-like noise added (Gaussian, low-passed like the markers, with the SDs and correlations of the whole
chain's IK error, :data:`IK_NOISE_SD`, measured by ``--mode chain --keep DIR`` below; times
``--ik-noise-scale``); the true gait events make the stride
tables; the robot log goes through the load-cell step's own clock map, filter and resampling; the brace
markers are the model's; the segment table is the subject's generated model (not scaled from a static
trial). Then the workflow's :func:`loper_analysis.impedance.identification.impedance.fit_onset`. Skips C3D files,
markers, IK,
scaling and event detection.

``--mode chain`` (the cross-check, ~35-70 min for 34 subjects): builds a copy of the workflow with the
N subjects and runs ``snakemake -jJ results/impedance/impedance.tsv`` (from the simulated C3D files to
the fits). With ``--keep DIR`` the project stays, and the script also prints the IK noise of the chain
(SD of IK angle minus true coordinate, per column) behind :data:`IK_NOISE_SD`.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import shutil
import subprocess
import sys
import tempfile
import time
import warnings
import zlib
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from scipy.stats import beta

from loper_analysis.layout import fill
from loper_analysis.report.markdown import markdown_table
from loper_analysis.stages import study_paths
from loper_analysis.stages.settings import stage_settings

ROOT = Path(__file__).resolve().parents[1]
PATHS = study_paths()
#: Columns of the angle table that get IK-like noise, and the noise measured in the whole chain (``--mode chain
#: --keep``: IK angle minus true coordinate, minimal-impedance trials of C014 and C030, 0.5 mm marker noise,
#: 40 Hz marker filter, generated model): SD (m, rad) and correlations. The noise is close to white noise
#: through the 40 Hz marker filter (lag-1 correlation 0.52 in the chain and 0.52 for filtered white noise).
IK_NOISE_COLUMNS = ("pelvis_x_m", "pelvis_angle_rad", "hip_left_rad", "knee_left_rad", "ankle_left_rad")
IK_NOISE_SD = np.array([0.000155, 0.001912, 0.002218, 0.001034, 0.001636])
IK_NOISE_CORR = np.array(
    [
        [1.00, -0.54, -0.67, -0.52, -0.03],
        [-0.54, 1.00, 0.97, 0.26, -0.02],
        [-0.67, 0.97, 1.00, 0.46, 0.02],
        [-0.52, 0.26, 0.46, 1.00, 0.35],
        [-0.03, -0.02, 0.02, 0.35, 1.00],
    ]
)
_ANGLES = ("pelvis_x", "pelvis_angle", "hip_left", "knee_left", "ankle_left")


def study_lab_config(configfiles=(), seed: int = 2024) -> dict:
    """``config/config.yaml`` with ``configfiles`` layered over it, the seed ``seed`` and the study-level lab."""
    from loper_analysis.config_file import update_config

    config = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    for extra in configfiles:
        update_config(config, yaml.safe_load(Path(extra).read_text()) or {})
    config["seed"] = seed
    config["synthetic"]["variability"] = "study"
    return config


def binomial_interval(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """Clopper-Pearson interval of a share k / n (0..1)."""
    a = (1 - level) / 2
    low = beta.ppf(a, k, n - k + 1) if k > 0 else 0.0
    high = beta.ppf(1 - a, k + 1, n - k) if k < n else 1.0
    return float(low), float(high)


#: Words of the reason of a row whose interval the status says can miss the truth by more than its width (rule 7
#: of ``joint_status``): the joint's model response smaller than its residual.
DATA_FINDINGS = {"response": "MIN_RESPONSE_TO_RESIDUAL"}


def _share(inside: pd.Series, has_ci: pd.Series) -> dict:
    """Rows with an interval, how many hold the truth, the share (%) and its Clopper-Pearson 95 % interval (%)."""
    n, k = int(has_ci.sum()), int((inside & has_ci).sum())
    low, high = binomial_interval(k, n) if n else (np.nan, np.nan)
    return {"n": n, "holds": k, "pct": 100.0 * k / n if n else np.nan, "low_pct": 100 * low, "high_pct": 100 * high}


def coverage_table(table: pd.DataFrame) -> pd.DataFrame:
    """Per joint and parameter, how often the 95 % intervals hold the truth, over three sets of rows.

    ``fits``: every fitted row (``ok`` or ``not_identifiable``) with an interval, as the table reports them;
    ``standing``: those rows less the ones whose reason names one of :data:`DATA_FINDINGS` (the joint's model
    response smaller than its residual: the status says their interval can miss the truth by more than it shows);
    ``ok``: the rows still ``ok``. Each with the number of rows, how many intervals hold the truth, the share (%)
    and its binomial (Clopper-Pearson) 95 % interval (%); the median width of the fitted rows' intervals, the rows
    ``not_identifiable``, those whose reason names each finding and (``n_widened``) those whose interval of this
    parameter comes from the perturbed pairs' scatter (the reason's
    :data:`~loper_analysis.impedance.identification.jackknife.WIDENED`).
    """
    from loper_analysis.impedance.identification.jackknife import WIDENED

    fitted = table[table["status"].isin(["ok", "not_identifiable"])]
    rows = []
    for joint in ("hip", "knee", "ankle"):
        g = fitted[fitted["joint"] == joint]
        reason = g["reason"].fillna("")
        found = {name: reason.str.contains(words, regex=False) for name, words in DATA_FINDINGS.items()}
        flagged = found["response"]
        for p, unit in (("K", "nm_per_rad"), ("D", "nms_per_rad")):
            low, high = g[f"{p}_ci95_low_{unit}"], g[f"{p}_ci95_high_{unit}"]
            truth = g[f"{p}_true_{unit}"]
            has_ci = low.notna() & high.notna()
            inside = has_ci & (low <= truth) & (truth <= high)
            row = {"joint": joint, "parameter": p}
            for name, keep in (
                ("fits", has_ci),
                ("standing", has_ci & ~flagged),
                ("ok", has_ci & (g["status"] == "ok")),
            ):
                row.update({f"{name}_{k}": v for k, v in _share(inside, keep).items()})
            row.update(
                median_ci_width=float(np.median((high - low)[has_ci])) if has_ci.any() else np.nan,
                n_not_identifiable=int((g["status"] == "not_identifiable").sum()),
                **{f"n_{name}": int(f.sum()) for name, f in found.items()},
                n_widened=int(reason.str.contains(f"{p}_{joint}: {WIDENED}", regex=False).sum()),
            )
            rows.append(row)
    return pd.DataFrame(rows)


def _settings(config: dict):
    """ResponseSettings and IdentificationSettings as the workflow's rule impedance_fit builds them."""

    settings = stage_settings(config, "impedance")
    return settings.response, settings.identification


def _trial_inputs(walk, model, lab, config: dict, noise_scale: float, rng: np.random.Generator) -> dict:
    """Angle table (IK-like noise, ``noise_scale`` times the chain's), stride table, force table and brace markers of
    one simulated trial, as the fit reads them."""
    from loper_analysis.device.loadcell import robot_log_frames_and_native
    from loper_analysis.filtering import lowpass
    from loper_analysis.gait.strides import stride_tables
    from loper_analysis.motion.ik import marker_positions
    from loper_analysis.motion.model import BRACE_MARKERS
    from loper_analysis.synthetic.sync import pulse_train_at

    coords = walk.mocap_coordinates(lab.marker_rate_hz)
    t = coords["time_s"].to_numpy()
    angles = {"time_s": t}
    cutoff, order = config["markers"]["filter"]["cutoff_hz"], config["markers"]["filter"]["order"]
    white = lowpass(rng.normal(size=(t.size, len(IK_NOISE_COLUMNS))), lab.marker_rate_hz, cutoff, order)
    noise = (white / white.std(axis=0)) @ np.linalg.cholesky(IK_NOISE_CORR).T * IK_NOISE_SD * noise_scale
    for name, entry in config["ik"]["coordinate_map"].items():
        column = f"{name}_m" if name == "pelvis_x" else f"{name}_rad"
        value = entry["sign"] * coords[entry["coordinate"]].to_numpy(float)
        if column in IK_NOISE_COLUMNS:
            value = value + noise[:, IK_NOISE_COLUMNS.index(column)]
        angles[column] = value
    angles = pd.DataFrame(angles)
    scale = 1.0 + 1e-6 * lab.clock_drift_ppm
    t_analog = np.arange(int(round(walk.duration_s * lab.analog_rate_hz))) / lab.analog_rate_hz
    sync = pulse_train_at((t_analog + lab.clock_offset_s) / scale, walk.sync_starts_s)
    force, native = robot_log_frames_and_native(
        walk.robot, lab.robot_rate_hz, sync, lab.analog_rate_hz, t, cutoff_hz=cutoff, order=order
    )
    s = config["strides"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        strides = stride_tables(
            angles,
            walk.mocap_events(),
            force,
            side="left",
            n_points=s["n_points"],
            whisker=s["iqr_whisker"],
            max_fraction=s["max_outlier_fraction"],
            min_valid=s["min_valid_strides"],
        ).strides
    values = {c: coords[c].to_numpy(float) for c in coords.columns if c != "time_s"}
    markers = marker_positions(model, values, list(BRACE_MARKERS))
    return {
        "angles": angles,
        "strides": strides,
        "force": force,
        "force_native": native,
        "markers": (t, markers, list(BRACE_MARKERS)),
    }


#: Parts of the study-level lab that ``coordinate_subject`` can leave out (``benchmarks/bias_sources.py``);
#: ``counterfactual``: the counterfactual's error (each perturbed stride gets its exact twin, :func:`with_twin`).
LAB_PARTS = ("adaptation", "minimal_impedance", "variability", "counterfactual")
#: Stride numbers of the twin trial's strides start here (:func:`with_twin`).
TWIN_STRIDE_OFFSET = 100_000


def with_twin(real: dict, twin: dict) -> dict:
    """One trial's inputs followed by those of its twin, the same walking simulated without the pulses.

    The twin's frames continue the trial's clock after a gap of NaN frames (the brace markers held) long enough
    that the two robot logs do not overlap (a uniform clock), its strides are numbered from
    :data:`TWIN_STRIDE_OFFSET` and none is perturbed. Its IK-like noise is the trial's own (the same seed),
    so the study's matching finds every perturbed stride's twin at a distance of 0 before the onset: its exact
    counterfactual, noise and all.
    """
    t = real["angles"]["time_s"].to_numpy(float)
    dt = t[1] - t[0]
    reach = real["force_native"]["time_s"].max() - twin["force_native"]["time_s"].min()
    k = int(np.ceil((reach + 0.5) / dt))
    shift = k * dt
    gap = t[0] + dt * np.arange(t.size, k)

    def joined(key: str) -> pd.DataFrame:
        blank = pd.DataFrame({c: np.nan for c in real[key].columns}, index=range(gap.size)).assign(time_s=gap)
        return pd.concat([real[key], blank, twin[key].assign(time_s=twin[key]["time_s"] + shift)], ignore_index=True)

    times = ("heel_strike_s", "toe_off_s", "end_s", "onset_s")
    strides = twin["strides"].assign(
        stride=twin["strides"]["stride"] + TWIN_STRIDE_OFFSET,
        **{c: twin["strides"][c] + shift for c in times if c in twin["strides"]},
    )
    tm, markers, labels = real["markers"]
    return {
        "angles": joined("angles"),
        "strides": pd.concat([real["strides"], strides], ignore_index=True),
        "force": joined("force"),
        "force_native": pd.concat(
            [real["force_native"], twin["force_native"].assign(time_s=twin["force_native"]["time_s"] + shift)],
            ignore_index=True,
        ),
        "markers": (
            np.concatenate([tm, gap, twin["markers"][0] + shift]),
            np.concatenate([markers, np.repeat(markers[-1:], gap.size, axis=0), twin["markers"][1]]),
            labels,
        ),
    }


def _truth(subject: str, config: dict) -> dict:
    """The synthetic subject's true K and D per onset and joint, as the workflow draws them."""
    from loper_analysis.synthetic.subjects import true_impedance

    syn, ident = config["synthetic"], config["impedance"]
    return true_impedance(
        subject,
        int(config["seed"]),
        syn["stiffness_nm_per_rad"],
        syn["damping_nms_per_rad"],
        syn["between_subject_cv"],
        ident["stiffness_bounds_nm_per_rad"],
        ident["damping_bounds_nms_per_rad"],
    )


def coordinate_subject(
    subject: str,
    config: dict,
    noise_scale: float,
    without: tuple[str, ...] = (),
    estimators: tuple[tuple[str, str, str, bool], ...] = (),
) -> pd.DataFrame:
    """The three fits of one synthetic subject from its simulated coordinates (rows of the impedance table).

    ``without``: parts of the study-level lab left out (:data:`LAB_PARTS`): the device adaptation, the leg's
    answer to the minimal-impedance force (only the pulses act), the stride-to-stride variability (that of the
    gentle lab instead), the counterfactual's error (each perturbation trial followed by its twin without pulses,
    :func:`with_twin`, fitted with the matched stride, which finds the twin). ``estimators``: fit the same
    simulated trials with each ``(name, counterfactual,
    interval_scatter, averaging_correction)`` (those keys of ``identification``), the rows tagged with the name in a
    column ``estimator``; empty: the config's.
    """
    from loper_analysis.constants import JOINTS
    from loper_analysis.device.controller import DeviceParameters
    from loper_analysis.impedance.identification.impedance import fit_onset
    from loper_analysis.motion.model import build_lower_body_model, segment_parameters_from_model
    from loper_analysis.synthetic.subjects import subject_anthropometry
    from loper_analysis.synthetic.trials import LabSettings, PerturbationSettings, simulate_walking_trial
    from loper_analysis.synthetic.variability import lab_variability

    syn, seed = config["synthetic"], int(config["seed"])
    row = subject_anthropometry({"subject": subject, "source": "synthetic"}, seed)
    truth = _truth(subject, config)
    lab = LabSettings(clock_offset_s=syn["clock_offset_s"], clock_drift_ppm=syn["clock_drift_ppm"])
    device = DeviceParameters(**config["device"]["parameters"])
    model = build_lower_body_model(row["height_m"], row["mass_kg"])
    params = segment_parameters_from_model(model)
    design = stage_settings(config, "study").design
    onsets = list(design.perturbation_onsets_ms)
    variability, adaptation, minimal_impedance = lab_variability(syn, seed, subject, truth)
    unknown = set(without) - set(LAB_PARTS)
    if unknown:
        raise SystemExit(f"unknown lab part(s) {sorted(unknown)}; choose from {LAB_PARTS}")
    adaptation = None if "adaptation" in without else adaptation
    minimal_impedance = None if "minimal_impedance" in without else minimal_impedance
    variability = None if "variability" in without else variability
    names = [(t, design.onset_ms(t)) for t in (design.device, *design.perturbation_trials())]
    # a second rod at the shank (synthetic.shank_pulse_force_n > 0, where device.shank_rod says): in every trial
    # with the device, as the synthetic lab attaches it
    shank_force_n = float(syn.get("shank_pulse_force_n", 0.0))
    shank_rod = stage_settings(config, "impedance").shank_rod
    attached = shank_rod if shank_force_n else None
    inputs, twins = {}, {}
    for trial, onset in names:
        perturbation = None
        if onset is not None:
            impedance = tuple(truth[onset][j][p] for j in JOINTS for p in ("K", "D"))
            perturbation = PerturbationSettings(
                onset / 1000.0,
                impedance,
                syn["pulse_force_n"],
                syn["pulse_duration_s"],
                tuple(syn["perturb_every_strides"]),
                shank_force_n,
            )
        # the workflow's seeds (synthetic.trials.subject_walking_trial): the same walking as the whole chain
        sim_seed, file_seed = np.random.SeedSequence(
            [seed, zlib.crc32(subject.encode()), zlib.crc32(trial.encode())]
        ).spawn(2)
        walk = simulate_walking_trial(
            syn["walking_duration_s"],
            lab,
            sim_seed,
            row["height_m"],
            params,
            timing_cv=syn["timing_cv"],
            amplitude_cv=syn["amplitude_cv"],
            device=device,
            perturbation=perturbation,
            variability=variability,
            adaptation=adaptation,
            minimal_impedance=minimal_impedance,
            shank_rod=attached,
        )
        inputs[trial] = {
            "name": trial,
            **_trial_inputs(walk, model, lab, config, noise_scale, np.random.default_rng(file_seed)),
        }
        if onset is not None and "counterfactual" in without:
            twin = simulate_walking_trial(
                syn["walking_duration_s"],
                lab,
                # a fresh copy: spawning children advances a SeedSequence, and the twin must walk the same
                np.random.SeedSequence(sim_seed.entropy, spawn_key=sim_seed.spawn_key),
                row["height_m"],
                params,
                timing_cv=syn["timing_cv"],
                amplitude_cv=syn["amplitude_cv"],
                device=device,
                perturbation=replace(perturbation, force_n=0.0, shank_force_n=0.0),
                variability=variability,
                adaptation=adaptation,
                minimal_impedance=minimal_impedance,
                shank_rod=attached,
            )
            own = _trial_inputs(twin, model, lab, config, noise_scale, np.random.default_rng(file_seed))
            twins[trial] = {"name": trial, **with_twin(inputs[trial], own)}
    response, ident = _settings(config)
    if "counterfactual" in without:  # the study's matching finds the twin; the conditional would predict it
        estimators = tuple((label, "matched_stride", *rest) for label, _, *rest in estimators) or (
            ("", "matched_stride", ident.interval_scatter, ident.averaging_correction),
        )
    null = [{k: v for k, v in tr.items() if k in ("name", "angles", "strides")} for tr in inputs.values()]
    inputs.update(twins)  # the null pairs stay those of the trials as they are: a twin is no unperturbed stride
    rows = []
    chosen = estimators or (("", response.counterfactual, ident.interval_scatter, ident.averaging_correction),)
    for label, counterfactual, scatter, averaging in chosen:
        settings = replace(response, counterfactual=counterfactual)
        fitting = replace(ident, interval_scatter=scatter, averaging_correction=averaging)
        for onset in onsets:
            own = [inputs[name] for name in design.perturbation_trials(onset)]
            fitted = fit_onset(
                own, params, onset, subject, truth[onset], null, settings, fitting, shank_rod=shank_rod
            ).rows
            rows.append(fitted.assign(estimator=label) if estimators else fitted)
    return pd.concat(rows, ignore_index=True)


def run_coordinates(
    names: list[str],
    config: dict,
    noise_scale: float,
    jobs: int,
    without: tuple[str, ...] = (),
    estimators: tuple[tuple[str, str, str, bool], ...] = (),
) -> pd.DataFrame:
    """Every subject's rows, ``jobs`` subjects at a time (``without``, ``estimators``: as
    :func:`coordinate_subject`)."""
    n = len(names)
    args = (names, [config] * n, [noise_scale] * n, [without] * n, [estimators] * n)
    with single_threaded_pool(max(jobs, 1)) as pool:
        frames = list(pool.map(coordinate_subject, *args))
    return pd.concat(frames, ignore_index=True)


def single_threaded_pool(jobs: int) -> ProcessPoolExecutor:
    """``jobs`` worker processes whose BLAS runs one thread each.

    Each process's OpenBLAS otherwise starts a thread per core, and ``jobs`` processes of many small solves
    and SVDs on the same cores spend their time waiting for each other (4 subjects at the study's design
    with 2 jobs: 57 s with one thread each, over 600 s without). The workers are spawned, so they read
    the thread counts set here when they import numpy (as Snakemake sets them for a rule's script).
    """
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = "1"
    return ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("spawn"))


def chain_ik_noise(work: Path, config: dict, max_subjects: int = 3) -> pd.Series:
    """SD (rad) of the chain's IK angles minus the true coordinates, per angle (minimal-impedance trials of the first
    ``max_subjects`` subjects that have one)."""
    from loper_analysis.device.controller import DeviceParameters
    from loper_analysis.io.readers import read_tsv
    from loper_analysis.motion.model import build_lower_body_model, segment_parameters_from_model
    from loper_analysis.synthetic.subjects import subject_anthropometry
    from loper_analysis.synthetic.trials import LabSettings, simulate_walking_trial
    from loper_analysis.synthetic.variability import lab_variability

    syn, seed = config["synthetic"], int(config["seed"])
    lab = LabSettings(clock_offset_s=syn["clock_offset_s"], clock_drift_ppm=syn["clock_drift_ppm"])
    diffs: dict[str, list] = {a: [] for a in _ANGLES}
    trial = config["study"]["device"]
    angles = fill(PATHS.ik.angles, subject="*", trial=trial)
    subjects = sorted(p.parent.name for p in work.glob(angles))[:max_subjects]
    for subject in subjects:
        row = subject_anthropometry({"subject": subject, "source": "synthetic"}, seed)
        params = segment_parameters_from_model(build_lower_body_model(row["height_m"], row["mass_kg"]))
        sim_seed, _ = np.random.SeedSequence([seed, zlib.crc32(subject.encode()), zlib.crc32(trial.encode())]).spawn(2)
        truth = _truth(subject, config)
        variability, adaptation, minimal_impedance = lab_variability(syn, seed, subject, truth)
        walk = simulate_walking_trial(
            syn["walking_duration_s"],
            lab,
            sim_seed,
            row["height_m"],
            params,
            timing_cv=syn["timing_cv"],
            amplitude_cv=syn["amplitude_cv"],
            device=DeviceParameters(**config["device"]["parameters"]),
            variability=variability,
            adaptation=adaptation,
            minimal_impedance=minimal_impedance,
        )
        coords = walk.mocap_coordinates(lab.marker_rate_hz)
        ik = read_tsv(work / fill(PATHS.ik.angles, subject=subject, trial=trial), "angle table")
        for a in _ANGLES:
            entry = config["ik"]["coordinate_map"][a]
            column = f"{a}_m" if a == "pelvis_x" else f"{a}_rad"
            d = ik[column].to_numpy(float) - entry["sign"] * coords[entry["coordinate"]].to_numpy(float)
            diffs[a].append(d[np.isfinite(d)] - np.nanmean(d))
    return pd.Series({a: float(np.std(np.concatenate(v))) for a, v in diffs.items()}, name="ik_noise_sd_m_or_rad")


def run_chain(names: list[str], seed: int, jobs: int, work: Path) -> pd.DataFrame:
    """The workflow on a copy of the project: ``results/impedance/impedance.tsv``."""
    for item in ("Snakefile", "workflow", "config"):
        target = work / item
        if not target.exists():
            (shutil.copytree if (ROOT / item).is_dir() else shutil.copy)(ROOT / item, target)
    (work / "config/coverage_subjects.tsv").write_text(
        "subject\tsource\n" + "".join(f"{s}\tsynthetic\n" for s in names)
    )
    (work / "config/coverage.yaml").write_text(
        yaml.safe_dump({"subjects": "config/coverage_subjects.tsv", "seed": seed, "device": {"subject": names[0]}})
    )
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "snakemake",
            "-j",
            str(jobs),
            PATHS.impedance.table,
            "--configfile",
            "config/coverage.yaml",
            "-q",
        ],
        cwd=work,
        check=False,
    )
    if res.returncode:
        raise SystemExit(f"snakemake failed in {work} (exit {res.returncode})")
    return pd.read_csv(work / PATHS.impedance.table, sep="\t")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mode", choices=("coordinates", "chain"), default="coordinates")
    ap.add_argument("--subjects", type=int, default=34)
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--ik-noise-scale", type=float, default=1.0, help="IK-like noise, times the chain's (0: none)")
    ap.add_argument("--keep", type=Path, help="chain: keep the project here; coordinates: write the rows here (TSV)")
    ap.add_argument(
        "--configfile", nargs="+", default=[], help="config files layered over config/config.yaml (coordinates mode)"
    )
    ap.add_argument(
        "--interval-scatter",
        choices=("perturbed_pairs", "null_pairs"),
        help="impedance.interval_scatter (coordinates mode; default: the config's)",
    )
    args = ap.parse_args()
    if args.configfile and args.mode == "chain":
        raise SystemExit("--configfile: coordinates mode only (the chain runs the workflow's own config)")
    config = study_lab_config(args.configfile, args.seed)
    if args.interval_scatter:
        config["impedance"]["interval_scatter"] = args.interval_scatter
    layered = f", --configfile {' '.join(args.configfile)}" if args.configfile else ""
    names = [f"C{k:03d}" for k in range(1, args.subjects + 1)]
    t0 = time.perf_counter()
    if args.mode == "coordinates":
        table = run_coordinates(names, config, args.ik_noise_scale, args.jobs)
        if args.keep:
            table.to_csv(args.keep, sep="\t", index=False)
        what = f"coordinate level, IK noise {args.ik_noise_scale:g} x the chain's"
    else:
        work = args.keep or Path(tempfile.mkdtemp(prefix="ci_coverage_"))
        work.mkdir(parents=True, exist_ok=True)
        table = run_chain(names, args.seed, args.jobs, work)
        what = "whole chain"
    print(
        f"{what}: {args.subjects} synthetic subjects, {table.groupby(['subject', 'onset_ms']).ngroups} subject x "
        f"onset fits, seed {args.seed}{layered}, {time.perf_counter() - t0:.0f} s with {args.jobs} job(s); statuses: "
        f"{table['status'].value_counts().to_dict()}"
    )
    print(markdown_table(coverage_table(table).round(3)))
    if args.mode == "chain":
        if args.keep is None:
            shutil.rmtree(work)
        else:
            print(markdown_table(chain_ik_noise(work, config).to_frame().reset_index(names="column")))


if __name__ == "__main__":
    main()
