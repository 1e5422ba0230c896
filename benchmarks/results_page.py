"""Rewrite the generated parts of docs/results.md from the results of a finished run.

Usage: python benchmarks/results_page.py [--results DIR] [--configfile FILE ...] [--page PAGE] [--check]

Run it in the folder of a finished run (``snakemake -j2``: the default study). It reads the run's tables
under ``results/`` (``--results``) and the config the run used: ``config/config.yaml`` of that folder, with
every ``--configfile`` given to Snakemake on top of it, in the same order. In the page (``--page``, default
``docs/results.md`` of this repository) it rewrites every part between a line
``<!-- generated: NAME -->`` and the next line ``<!-- end generated -->`` and leaves every other byte as it
was. The names (:data:`BLOCKS`):

* ``run`` - the command, the config files (with their SHA-256) and the design the figures come from;
* ``impedance-summary`` - across-subject K and D per joint and onset (``results/impedance/summary.tsv``);
* ``truth-recovery`` - estimates against the synthetic subjects' truth per joint and onset, the fits' status
  and the ``ok`` rows whose 95 % interval misses the truth (``results/impedance/impedance.tsv``);
* ``validation`` - the validation study's errors against the study's (``results/validation/summary.tsv``,
  ``fits.tsv``);
* ``transparency``, ``interaction-force`` - ``results/transparency/rmsd.tsv`` and ``force.tsv``;
* ``device`` - ``results/device/summary.tsv``;
* ``strides`` - stride counts per subject (``results/strides/summary.tsv``);
* ``planning`` - the workflow's planning answers (``results/planning/answers.txt``).

A part whose table the run did not make says so. ``--check`` writes nothing and exits with 1 when the page
differs from what the command would write (the figures are not those of the results at hand).
"""

from __future__ import annotations

import argparse
import datetime
import hashlib
import math
import re
import sys
from collections.abc import Callable
from pathlib import Path

import pandas as pd
import yaml

from loper_analysis.layout import RESULTS_DIR
from loper_analysis.stages import study_paths

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_PAGE = ROOT / "docs" / "results.md"
DEFAULT_CONFIG = "config/config.yaml"
#: An opening marker line, its name, and everything up to the closing marker line (both lines kept).
BLOCK = re.compile(
    r"^(<!-- generated: ([A-Za-z0-9_-]+) -->\n)(.*?)^(<!-- end generated -->)$", re.MULTILINE | re.DOTALL
)
OPENING = re.compile(r"^<!-- generated: ", re.MULTILINE)
CLOSING = re.compile(r"^<!-- end generated -->$", re.MULTILINE)
MINUS = "\u2212"
JOINT_ORDER = ("hip", "knee", "ankle")
PHASE_ORDER = ("stance", "swing")
FITTED = ("ok", "not_identifiable")


class PageError(Exception):
    """The page, the results or the config cannot give the page: one line naming the file and the cause."""


# --- numbers -----------------------------------------------------------------------------------------------


def num(x, sig: int = 3) -> str:
    """``x`` with ``sig`` significant digits in fixed notation (a true minus sign); blank or NaN: an em dash."""
    try:
        x = float(x)
    except (TypeError, ValueError):
        return "—"
    if not math.isfinite(x):
        return "—"
    if x == 0:
        return "0"
    exponent = math.floor(math.log10(abs(x)))
    decimals = max(sig - 1 - exponent, 0)
    text = f"{x:.{sig - 1}e}" if decimals > 9 else f"{x:.{decimals}f}"
    return text.replace("-", MINUS)


def plain(x) -> str:
    """A count or a setting as written: no trailing zeros (``45.0`` -> ``45``, ``0.1`` -> ``0.1``)."""
    try:
        x = float(x)
    except (TypeError, ValueError):
        return "—"
    return "—" if not math.isfinite(x) else f"{x:.6g}".replace("-", MINUS)


def fixed(x, decimals: int) -> str:
    """``x`` with a fixed number of decimals (a true minus sign)."""
    try:
        x = float(x)
    except (TypeError, ValueError):
        return "—"
    return "—" if not math.isfinite(x) else f"{x:.{decimals}f}".replace("-", MINUS)


def table(header: list[str], rows: list[list[str]]) -> str:
    """A Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def ordered(values, order) -> list:
    """The distinct values, those of ``order`` first in its order, the rest sorted."""
    seen = list(dict.fromkeys(values))
    return [v for v in order if v in seen] + sorted(v for v in seen if v not in order)


# --- the run -----------------------------------------------------------------------------------------------


def deep_merge(base: dict, top: dict) -> dict:
    """``top`` over ``base``, nested mappings merged key by key (as Snakemake merges --configfile)."""
    out = dict(base)
    for key, value in top.items():
        out[key] = deep_merge(out[key], value) if isinstance(value, dict) and isinstance(out.get(key), dict) else value
    return out


def sha256(path: Path) -> str:
    """The first 12 hex digits of a file's SHA-256."""
    return hashlib.sha256(path.read_bytes()).hexdigest()[:12]


class Run:
    """A finished run: its results folder, the config files it used and the tables read from it."""

    def __init__(self, results: Path, configfiles: list[str]):
        self.results = results
        self.paths = study_paths(results_dir=str(results))
        self.configfiles = [DEFAULT_CONFIG, *configfiles]
        self.config: dict = {}
        for name in self.configfiles:
            path = Path(name)
            if not path.is_file():
                raise PageError(f"{path}: no such config file (run the command in the folder of the run)")
            self.config = deep_merge(self.config, yaml.safe_load(path.read_text()) or {})
        self.read: list[Path] = []

    def path(self, name: str) -> Path:
        """A result file (``name``: its path, from ``self.paths``)."""
        return Path(name)

    def tsv(self, name: str) -> pd.DataFrame | None:
        """A result table, or None when the run did not write it."""
        path = self.path(name)
        if not path.is_file():
            return None
        self.read.append(path)
        try:
            return pd.read_csv(path, sep="\t")
        except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
            raise PageError(f"{path}: not a readable TSV table ({exc})") from None

    def need(self, frame: pd.DataFrame, name: str, columns: list[str]) -> pd.DataFrame:
        """``frame`` when it holds ``columns``, else a PageError naming the table and the missing columns."""
        missing = [c for c in columns if c not in frame.columns]
        if missing:
            raise PageError(f"{self.path(name)}: columns {missing} missing (has {list(frame.columns)})")
        return frame


def not_in_run(run: Run, *names: str) -> str:
    """The text of a part whose tables the run did not write."""
    names = ", ".join(f"`{run.path(r).as_posix()}`" for r in names)
    return f"*Not in this run: no {names}.*"


# --- the parts ---------------------------------------------------------------------------------------------


def block_run(run: Run) -> str:
    """The command, the config files and the design the generated figures come from."""
    cfg = run.config
    extra = "".join(f" --configfile {f}" for f in run.configfiles[1:])
    results = "" if run.results == Path(RESULTS_DIR) else f" --results {run.results.as_posix()}"
    files = [f"`{f}` (SHA-256 {sha256(Path(f))}…)" for f in run.configfiles]
    sheet = cfg.get("subjects")
    design = []
    if sheet and Path(sheet).is_file():
        files.append(f"the subject sheet `{sheet}` (SHA-256 {sha256(Path(sheet))}…)")
        subjects = pd.read_csv(sheet, sep="\t", dtype=str)
        if "source" in subjects.columns:
            kinds = subjects["source"].value_counts()
            design.append(f"{len(subjects)} subjects (" + ", ".join(f"{n} {k}" for k, n in kinds.items()) + ")")
    trials = cfg.get("study", {})
    synthetic = cfg.get("synthetic", {})
    if "seed" in cfg:
        design.append(f"seed {cfg['seed']}")
    if "variability" in synthetic:
        design.append(f"`synthetic.variability: {synthetic['variability']}`")
    if "walking_duration_s" in synthetic:
        design.append(f"synthetic walking trials of {plain(synthetic['walking_duration_s'])} s")
    if trials.get("perturbation_onsets_ms"):
        design.append("onsets " + ", ".join(str(o) for o in trials["perturbation_onsets_ms"]) + " ms")
    if "perturbation_repeats" in trials:
        n = trials["perturbation_repeats"]
        design.append(f"{n} trial{'' if n == 1 else 's'} per onset")
    dates = sorted({datetime.date.fromtimestamp(p.stat().st_mtime).isoformat() for p in run.read})
    written = (
        f", tables written {dates[0]}"
        if len(dates) == 1
        else f", tables written {dates[0]} to {dates[-1]}"
        if dates
        else ""
    )
    return (
        f"Results of `snakemake -j2{extra}`{written}; page written by "
        f"`python benchmarks/results_page.py{extra}{results}` in the run's folder.\n"
        f"Config: {', '.join(files)}.\n"
        f"Design: {'; '.join(design) if design else 'not stated in the config'}."
    )


#: The summary's random-effects columns of a parameter, between its letter and its unit.
GROUP_COLUMNS = ("group_mean", "group_ci95_low", "group_ci95_high", "between_sd")


def block_impedance_summary(run: Run) -> str:
    """Across-subject K and D per joint and onset: the random-effects mean, its 95 % interval and the SD between
    subjects."""
    name = run.paths.impedance.summary
    s = run.tsv(name)
    if s is None:
        return not_in_run(run, name)
    per_p = [f"{p}_{w}_{u}" for p, u in zip("KD", ("nm_per_rad", "nms_per_rad")) for w in GROUP_COLUMNS]
    s = run.need(s, name, ["joint", "onset_ms", "n_subjects", "n_not_identifiable", *per_p, "vaf_pct_mean"])
    rows = []
    for joint in ordered(s["joint"], JOINT_ORDER):
        for _, r in s[s["joint"] == joint].sort_values("onset_ms").iterrows():
            cells = [joint, int(r["onset_ms"]), int(r["n_subjects"]), int(r["n_not_identifiable"])]
            for p, u in zip("KD", ("nm_per_rad", "nms_per_rad")):
                mean, low, high, between = (r[f"{p}_{w}_{u}"] for w in GROUP_COLUMNS)
                cells += [f"{num(mean)} [{num(low)}, {num(high)}]", num(between)]
            rows.append([*cells, fixed(r["vaf_pct_mean"], 1)])
    return table(
        [
            "joint",
            "onset (ms)",
            "subjects",
            "not identifiable",
            "K mean [95 % CI] (N·m/rad)",
            "K SD between subjects",
            "D mean [95 % CI] (N·m·s/rad)",
            "D SD between subjects",
            "mean VAF (%)",
        ],
        rows,
    )


def _recovery_row(rows: pd.DataFrame, tolerance: dict) -> list[str]:
    """Status counts, and per parameter the fits within tolerance, the intervals holding the truth and the
    largest error, over ``rows`` of the impedance table (those with a truth)."""
    fitted = rows[rows["status"].isin(FITTED)]
    n = len(fitted)
    status = rows["status"].value_counts()
    n_ok, n_unknown = status.get("ok", 0), status.get("not_identifiable", 0)
    out = [f"{n_ok} / {n_unknown} / {len(rows) - n_ok - n_unknown}"]
    for p, unit in (("K", "nm_per_rad"), ("D", "nms_per_rad")):
        err = fitted[f"{p}_error_{unit}"].astype(float)
        true = fitted[f"{p}_true_{unit}"].astype(float)
        rel, ab = tolerance[p]
        within = int((err.abs() <= (rel * true.abs()).clip(lower=ab)).sum())
        held = int(
            (
                (true >= fitted[f"{p}_ci95_low_{unit}"].astype(float))
                & (true <= fitted[f"{p}_ci95_high_{unit}"].astype(float))
            ).sum()
        )
        out += [f"{within} / {n}", f"{held} / {n}", num(err.abs().max()) if n else "—"]
    out.append(fixed(fitted["vaf_pct"].astype(float).mean(), 1) if n else "—")
    return out


def block_truth_recovery(run: Run) -> str:
    """The synthetic subjects' K and D recovered, per joint and onset."""
    from loper_analysis.impedance.identification.across_subjects import TRUTH_TOLERANCE

    name = run.paths.impedance.table
    t = run.tsv(name)
    if t is None:
        return not_in_run(run, name)
    units = ("nm_per_rad", "nms_per_rad")
    cols = [
        "subject",
        "onset_ms",
        "joint",
        "status",
        "vaf_pct",
        "n_strides",
        *(f"{p}_{w}_{u}" for p, u in zip("KD", units) for w in ("true", "error", "ci95_low", "ci95_high")),
        "K_nm_per_rad",
        "D_nms_per_rad",
    ]
    t = run.need(t, name, cols)
    t = t[pd.to_numeric(t["K_true_nm_per_rad"], errors="coerce").notna()]
    if not len(t):
        return "*No subject of this run has a known truth (no synthetic subjects).*"
    rows = []
    for joint in ordered(t["joint"], JOINT_ORDER):
        own = t[t["joint"] == joint]
        for onset in sorted(own["onset_ms"].unique()):
            rows.append([joint, int(onset), *_recovery_row(own[own["onset_ms"] == onset], TRUTH_TOLERANCE)])
        rows.append([f"**{joint}**", "all", *_recovery_row(own, TRUTH_TOLERANCE)])
    (k_rel, k_abs), (d_rel, d_abs) = TRUTH_TOLERANCE["K"], TRUTH_TOLERANCE["D"]
    text = [
        (
            f"{t['subject'].nunique()} subjects with a known truth, "
            f"{plain(t['n_strides'].min())}–{plain(t['n_strides'].max())} perturbed strides per fit. Within "
            f"tolerance: |error| ≤ {plain(k_rel * 100)} % of the truth or {plain(k_abs)} N·m/rad for K, "
            f"{plain(d_rel * 100)} % or {plain(d_abs)} N·m·s/rad for D; counts over the fitted rows "
            f"(`ok` and `not_identifiable`)."
        ),
        "",
        table(
            [
                "joint",
                "onset (ms)",
                "rows ok / not identifiable / failed",
                "K within tolerance",
                "K: 95 % CI holds the truth",
                "largest \\|K error\\| (N·m/rad)",
                "D within tolerance",
                "D: 95 % CI holds the truth",
                "largest \\|D error\\| (N·m·s/rad)",
                "mean VAF (%)",
            ],
            rows,
        ),
        "",
    ]
    misses = []
    ok = t[t["status"] == "ok"]
    for _, r in ok.iterrows():
        for p, unit in zip("KD", units):
            true, err = float(r[f"{p}_true_{unit}"]), float(r[f"{p}_error_{unit}"])
            rel, ab = TRUTH_TOLERANCE[p]
            low, high = float(r[f"{p}_ci95_low_{unit}"]), float(r[f"{p}_ci95_high_{unit}"])
            if abs(err) > max(rel * abs(true), ab) and not low <= true <= high:
                misses.append(
                    f"{r['subject']}, {int(r['onset_ms'])} ms, {r['joint']} {p} "
                    f"{num(r[f'{p}_{unit}'])} for {num(true)} (95 % CI {num(low)}–{num(high)})"
                )
    text.append(
        "`ok` rows off the truth beyond tolerance with a 95 % CI that misses it: "
        + ("; ".join(misses) if misses else "none")
        + "."
    )
    return "\n".join(text)


def block_validation(run: Run) -> str:
    """The validation study's errors against the study's."""
    name = run.paths.validation.summary
    s = run.tsv(name)
    if s is None:
        return not_in_run(run, name)
    s = run.need(
        s,
        name,
        [
            "condition",
            "parameter",
            "min_error",
            "max_error",
            "sd_error",
            "max_abs_error",
            "n",
            "study_min_error",
            "study_max_error",
            "study_sd_error",
        ],
    )
    clean, noisy = (
        s[s["condition"] == "no_noise"].set_index("parameter"),
        s[s["condition"] == "noise"].set_index("parameter"),
    )
    rows = []
    for p in ordered(s["parameter"], [f"{k}_{j}" for j in JOINT_ORDER for k in "KD"]):
        unit = " (N·m/rad)" if p == "K_hip" else " (N·m·s/rad)" if p == "D_hip" else ""
        c = clean.loc[p] if p in clean.index else None
        n = noisy.loc[p] if p in noisy.index else None
        rows.append(
            [
                f"{p}{unit}",
                f"{num(c['min_error'], 2)} … {num(c['max_error'], 2)}" if c is not None else "—",
                f"{num(c['study_min_error'], 2)} … {num(c['study_max_error'], 2)}" if c is not None else "—",
                num(n["sd_error"]) if n is not None else "—",
                num(n["study_sd_error"], 2) if n is not None else "—",
            ]
        )
    text = [
        table(
            ["parameter", "no noise: min … max error", "study (no noise)", "noise: SD of error", "study SD (noise)"],
            rows,
        ),
        "",
    ]
    if len(clean):
        k = clean[clean.index.str.startswith("K_")]["max_abs_error"].max()
        d = clean[clean.index.str.startswith("D_")]["max_abs_error"].max()
        text.append(
            f"Without noise every estimate of the {int(clean['n'].min())} combinations is within "
            f"|ΔK| ≤ {num(k, 2)} N·m/rad and |ΔD| ≤ {num(d, 2)} N·m·s/rad."
        )
    fits = run.tsv(run.paths.validation.fits)
    if fits is not None:
        from loper_analysis.impedance.identification.fit import AT_BEST_RELATIVE

        fits = run.need(fits, run.paths.validation.fits, ["condition", "n_starts", "n_starts_at_best"])
        parts = []
        for cond, label in (("no_noise", "noise-free"), ("noise", "noisy")):
            g = fits[fits["condition"] == cond]
            if len(g):
                parts.append(f"{int((g['n_starts_at_best'] == g['n_starts']).sum())} of {len(g)} {label} fits")
        starts = sorted(fits["n_starts"].unique())
        text.append(
            f"All {'/'.join(str(int(s)) for s in starts)} random starts end within "
            f"{plain(AT_BEST_RELATIVE * 100)} % of the best start's cost in {' and in '.join(parts)} "
            f"(`results/validation/fits.tsv`, `n_starts_at_best`)."
        )
    return "\n".join(text)


def block_transparency(run: Run) -> str:
    """RMSD with vs without the device against ISV_ave, the group rows."""
    name = run.paths.transparency.rmsd
    r = run.tsv(name)
    if r is None:
        return not_in_run(run, name)
    r = run.need(
        r,
        name,
        [
            "subject",
            "phase",
            "joint",
            "n_strides_no_device",
            "n_strides_device",
            "rmsd_rad",
            "isv_ave_rad",
            "transparent",
            "study_rmsd_rad",
            "study_isv_ave_rad",
        ],
    )
    r = r.assign(subject=r["subject"].astype(str), transparent=r["transparent"].astype(str))
    group, subjects = r[r["subject"] == "all"], r[r["subject"] != "all"]
    rows = []
    for phase in ordered(group["phase"], PHASE_ORDER):
        for joint in ordered(group[group["phase"] == phase]["joint"], JOINT_ORDER):
            g = group[(group["phase"] == phase) & (group["joint"] == joint)].iloc[0]
            own = subjects[(subjects["phase"] == phase) & (subjects["joint"] == joint)]
            judged = own[own["transparent"].isin(["True", "False"])]
            rows.append(
                [
                    phase,
                    joint,
                    f"{fixed(g['rmsd_rad'], 3)} ({fixed(g['study_rmsd_rad'], 3)})",
                    f"{fixed(g['isv_ave_rad'], 3)} ({fixed(g['study_isv_ave_rad'], 3)})",
                    f"{(judged['transparent'] == 'True').sum()} / {len(judged)}",
                ]
            )
    per_subject = subjects.drop_duplicates("subject")
    counts = pd.concat([per_subject["n_strides_no_device"], per_subject["n_strides_device"]]).astype(float)
    text = [
        (
            f"{len(per_subject)} subjects, {plain(counts.min())}–{plain(counts.max())} kept strides per trial; "
            "RMSD of the mean trajectories with vs without the device and ISV_ave, in rad, ours (study):"
        ),
        "",
        table(["phase", "joint", "RMSD", "ISV_ave", "subjects transparent (RMSD < ISV_ave)"], rows),
        "",
    ]
    ratio = (group["isv_ave_rad"].astype(float) / group["study_isv_ave_rad"].astype(float) - 1).abs().max()
    below = int((group["rmsd_rad"].astype(float) < group["isv_ave_rad"].astype(float)).sum())
    text.append(
        f"ISV_ave is within {num(ratio * 100, 2)} % of the study's everywhere; {below} of {len(group)} "
        "group RMSDs lie below their ISV_ave."
    )
    return "\n".join(text)


def block_interaction_force(run: Run) -> str:
    """Interaction force in minimal-impedance walking, the group rows."""
    name = run.paths.transparency.force
    f = run.tsv(name)
    if f is None:
        return not_in_run(run, name)
    f = run.need(
        f,
        name,
        [
            "subject",
            "phase",
            "n_strides",
            "rms_force_mean_n",
            "max_abs_force_mean_n",
            "study_rms_force_mean_n",
            "study_max_abs_force_mean_n",
        ],
    )
    group = f[f["subject"].astype(str) == "all"]
    rows = [
        [
            r["phase"],
            int(r["n_strides"]),
            f"{fixed(r['rms_force_mean_n'], 2)} ({fixed(r['study_rms_force_mean_n'], 2)})",
            f"{fixed(r['max_abs_force_mean_n'], 2)} ({fixed(r['study_max_abs_force_mean_n'], 2)})",
        ]
        for _, r in group.iterrows()
    ]
    return "Mean over subjects, ours (study):\n\n" + table(
        ["phase", "strides", "RMS force (N)", "largest \\|F\\| (N)"], rows
    )


def block_device(run: Run) -> str:
    """The device figures beside the study's."""
    name = run.paths.device.summary
    d = run.tsv(name)
    if d is None:
        return not_in_run(run, name)
    d = run.need(d, name, ["metric", "value", "study_value", "unit", "difference_pct"])
    rows = [
        [
            f"`{r['metric']}`",
            num(r["value"]),
            plain(r["study_value"]),
            r["unit"] if isinstance(r["unit"], str) else "",
            fixed(r["difference_pct"], 1),
        ]
        for _, r in d.iterrows()
    ]
    return table(["metric", "ours", "study", "unit", "difference (%)"], rows)


def block_strides(run: Run) -> str:
    """Strides per subject: recorded, perturbed, removed as outliers, kept; flagged trials."""
    name = run.paths.strides.summary
    s = run.tsv(name)
    if s is None:
        return not_in_run(run, name)
    s = run.need(s, name, ["subject", "trial", "n_strides", "n_perturbed", "n_removed", "n_kept", "status"])
    rows = []

    def row(label, g):
        flagged = g[g["status"].astype(str) != "ok"]
        return [
            label,
            len(g),
            int(g["n_strides"].sum()),
            int(g["n_perturbed"].sum()),
            int(g["n_removed"].sum()),
            int(g["n_kept"].sum()),
            f"{int(g['n_kept'].min())}–{int(g['n_kept'].max())}",
            ", ".join(f"{t} ({st})" for t, st in zip(flagged["trial"], flagged["status"])) or "none",
        ]

    for subject in ordered(s["subject"].astype(str), ()):
        rows.append(row(subject, s[s["subject"].astype(str) == subject]))
    rows.append(row("**all**", s))
    return table(
        ["subject", "trials", "strides", "perturbed", "removed (outliers)", "kept", "kept per trial", "trials flagged"],
        rows,
    )


def block_planning(run: Run) -> str:
    """The workflow's planning answers."""
    name = run.paths.planning.answers
    path = run.path(name)
    if not path.is_file():
        return not_in_run(run, name)
    run.read.append(path)
    answers = path.read_text().strip()
    return "```\n" + (answers or "(no targets)") + "\n```"


#: The parts a page may hold, by the name in its marker.
BLOCKS: dict[str, Callable[[Run], str]] = {
    "run": block_run,
    "impedance-summary": block_impedance_summary,
    "truth-recovery": block_truth_recovery,
    "validation": block_validation,
    "transparency": block_transparency,
    "interaction-force": block_interaction_force,
    "device": block_device,
    "strides": block_strides,
    "planning": block_planning,
}


# --- the page ----------------------------------------------------------------------------------------------


def rewrite(page: str, run: Run, source: str = "page") -> str:
    """``page`` with every generated part rewritten from ``run``; every byte outside the parts kept."""
    found = list(BLOCK.finditer(page))
    if len(OPENING.findall(page)) != len(found) or len(CLOSING.findall(page)) != len(found):
        raise PageError(
            f"{source}: every '<!-- generated: NAME -->' line needs its own '<!-- end generated -->' "
            f"line below it ({len(OPENING.findall(page))} opening, {len(CLOSING.findall(page))} "
            "closing markers)"
        )
    unknown = sorted({m.group(2) for m in found} - set(BLOCKS))
    if unknown:
        raise PageError(f"{source}: unknown generated part(s) {unknown}; known: {sorted(BLOCKS)}")
    # the stamp names the tables read: the other parts first
    texts = {m.group(2): BLOCKS[m.group(2)](run) for m in found if m.group(2) != "run"}
    if any(m.group(2) == "run" for m in found):
        texts["run"] = block_run(run)
    out, end = [], 0
    for m in found:
        out += [page[end : m.start()], m.group(1), "\n", texts[m.group(2)], "\n\n", m.group(4)]
        end = m.end()
    out.append(page[end:])
    return "".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", default=RESULTS_DIR, help="the run's results folder (default: results)")
    ap.add_argument(
        "--configfile",
        action="append",
        default=[],
        metavar="FILE",
        help="a config file given to Snakemake on top of config/config.yaml (repeat in the same order)",
    )
    ap.add_argument("--page", default=str(DEFAULT_PAGE), help="the page to rewrite (default: docs/results.md)")
    ap.add_argument(
        "--check", action="store_true", help="write nothing; exit 1 when the page differs from what would be written"
    )
    args = ap.parse_args(argv)
    page = Path(args.page)
    try:
        if not page.is_file():
            raise PageError(f"{page}: no such page")
        if not Path(args.results).is_dir():
            raise PageError(f"{args.results}: no results folder (run the command in the folder of a finished run)")
        before = page.read_bytes().decode("utf-8")
        after = rewrite(before, Run(Path(args.results), args.configfile), str(page))
    except PageError as exc:
        print(f"results_page: {exc}", file=sys.stderr)
        return 2
    if args.check:
        if after != before:
            print(
                f"results_page: {page} is not that of {args.results}: run without --check to rewrite it",
                file=sys.stderr,
            )
            return 1
        return 0
    if after != before:
        from loper_analysis.io.atomic import write_text

        write_text(page, after, "results page")
    print(f"{page}: {'rewritten' if after != before else 'unchanged'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
