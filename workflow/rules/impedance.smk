# Perturbation analysis: responses (matched strides) and impedance fits per subject and onset, aggregate tables.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    impedance_figures,
    impedance_table,
    impedance_summary,
    impedance_figure,
    tables_markdown,


IDENT = config["identification"]


def onset_trials(subject: str, onset: str) -> list[str]:
    """The subject's trials of one onset that are on disk (or generated)."""
    return [t for t in subject_trials(subject) if DESIGN.onset_ms(t) == int(onset)]


def null_pair_trials(subject: str) -> list[str]:
    """The subject's trials with the device (minimal impedance and perturbation): their unperturbed strides
    are the null pairs of every onset's fit."""
    return [t for t in subject_trials(subject) if t != config["trials"]["no_device"]]


ONSETS = [f"{o:03d}" for o in TRIALS["perturbation_onsets_ms"]]


def fit_trials(subject: str) -> list[str]:
    """The subject's trials any of its fits reads, in subject_trials order: the onsets' own trials and the
    null-pair trials."""
    used = {t for o in ONSETS for t in onset_trials(subject, o) + fit_null_trials(subject, o)}
    return [t for t in subject_trials(subject) if t in used]


def fit_inputs(wildcards):
    """Files of a subject's fits: angles and strides of every trial a fit reads (order of fit_trials), the force
    at 128 Hz and at the robot rate and the markers of the perturbation trials (order of their onsets' trials),
    the segment table and a synthetic truth."""
    s = wildcards.subject
    out = {"segments": f"results/model/{s}/segments.tsv"}
    if SUBJECT_SOURCE[s] == "synthetic":
        out["truth"] = f"data/raw/{s}/truth.yaml"
    used = fit_trials(s)
    out["angles"] = [f"results/ik/{s}/{t}.angles.tsv" for t in used]
    out["strides"] = [f"results/strides/{s}/{t}.strides.tsv" for t in used]
    own = [t for o in ONSETS for t in onset_trials(s, o)]
    out["force"] = [f"results/loadcell/{s}/{t}.force.tsv" for t in own]
    out["force_native"] = [f"results/loadcell/{s}/{t}.force_native.tsv" for t in own]
    out["markers"] = [f"results/markers/{s}/{t}.trc" for t in own]
    return out


def fit_null_trials(subject: str, onset: str) -> list[str]:
    """Null-pair trials of a fit: none for a white-noise fit or a missing onset (reported without any input)."""
    if IDENT["noise_model"] != "null_pairs" or not onset_trials(subject, onset):
        return []
    return null_pair_trials(subject)


rule impedance_fit:
    """Responses and impedance fits of one subject at every onset, in one job: the onsets share the null-pair
    trials, so a change to any of the subject's trials reruns every onset's fit anyway."""
    input:
        unpack(fit_inputs),
    output:
        response=expand("results/responses/{{subject}}/{onset}.response.tsv", onset=ONSETS),
        counts=expand("results/responses/{{subject}}/{onset}.counts.tsv", onset=ONSETS),
        fit=expand("results/impedance/{{subject}}/{onset}.tsv", onset=ONSETS),
        curves=expand("results/impedance/{{subject}}/{onset}.curves.tsv", onset=ONSETS),
        force=expand("results/responses/{{subject}}/{onset}.force.tsv", onset=ONSETS),
    log:
        "results/logs/impedance_fit/{subject}.log",
    benchmark:
        "results/benchmarks/impedance_fit/{subject}.tsv"
    params:
        onsets_ms=TRIALS["perturbation_onsets_ms"],
        trials=lambda wc: {o: onset_trials(wc.subject, o) for o in ONSETS},
        null_trials=lambda wc: {o: fit_null_trials(wc.subject, o) for o in ONSETS},
        fit_trials=lambda wc: fit_trials(wc.subject),
        own_trials=lambda wc: [t for o in ONSETS for t in onset_trials(wc.subject, o)],
        response=dict(
            window_before_s=IDENT["window_before_s"],
            window_after_s=IDENT["window_after_s"],
            initial_state_span_s=IDENT["initial_state_span_s"],
            whisker=config["strides"]["iqr_whisker"],
            max_fraction=config["strides"]["max_outlier_fraction"],
            min_strides=config["strides"]["min_valid_strides"],
        ),
        identification=dict(
            noise_model=IDENT["noise_model"],
            interval_scatter=IDENT["interval_scatter"],
            null_pair_components=IDENT["null_pair_components"],
            min_null_pairs=IDENT["min_null_pairs"],
            initial_state_degree=IDENT["initial_state_degree"],
            n_starts=IDENT["n_starts"],
            n_substeps=IDENT["n_substeps"],
            tolerance=IDENT["tolerance"],
            merge_tolerance=IDENT["merge_tolerance"],
            stiffness_bounds_nm_per_rad=IDENT["stiffness_bounds_nm_per_rad"],
            damping_bounds_nms_per_rad=IDENT["damping_bounds_nms_per_rad"],
            max_ci_fraction=IDENT["max_ci_fraction"],
            plausible_ranges=IDENT["plausible_ranges"],
            min_vaf_pct=IDENT["min_vaf_pct"],
            max_null_trial_ratio=IDENT["max_null_trial_ratio"],
            seed=config["seed"],
        ),
    script:
        "../scripts/impedance_fit.py"


rule impedance_table:
    input:
        [f"results/impedance/{s}/{o:03d}.tsv" for s in processed_subjects() for o in TRIALS["perturbation_onsets_ms"]],
    output:
        report(
            "results/tables/impedance.tsv",
            caption="../report/impedance_table.rst",
            category="Impedance",
            labels={"table": "impedance per subject, onset and joint"},
        ),
    log:
        "results/logs/impedance_table/impedance.log",
    benchmark:
        "results/benchmarks/impedance_table/impedance.tsv"
    script:
        "../scripts/impedance_table.py"


rule impedance_summary:
    input:
        "results/tables/impedance.tsv",
    output:
        summary=report(
            "results/tables/impedance_summary.tsv",
            caption="../report/impedance_summary.rst",
            category="Impedance",
            labels={"table": "across-subject summary per onset"},
        ),
        literature=report(
            "results/tables/literature.tsv",
            caption="../report/literature.rst",
            category="Impedance",
            labels={"table": "literature comparison"},
        ),
    log:
        "results/logs/impedance_summary/summary.log",
    benchmark:
        "results/benchmarks/impedance_summary/summary.tsv"
    params:
        upper_bounds=(IDENT["stiffness_bounds_nm_per_rad"][1], IDENT["damping_bounds_nms_per_rad"][1]),
    script:
        "../scripts/impedance_summary.py"


rule impedance_figures:
    input:
        responses=lambda wc: [
            f"results/responses/{wc.subject}/{o:03d}.response.tsv" for o in TRIALS["perturbation_onsets_ms"]
        ],
        curves=lambda wc: [
            f"results/impedance/{wc.subject}/{o:03d}.curves.tsv" for o in TRIALS["perturbation_onsets_ms"]
        ],
    output:
        responses=report(
            "results/figures/{subject}/responses.png",
            caption="../report/responses_figure.rst",
            category="Impedance",
            subcategory="{subject}",
            labels={"subject": "{subject}", "figure": "responses"},
        ),
        fit=report(
            "results/figures/{subject}/fit.png",
            caption="../report/fit_figure.rst",
            category="Impedance",
            subcategory="{subject}",
            labels={"subject": "{subject}", "figure": "fit vs data"},
        ),
    log:
        "results/logs/impedance_figures/{subject}.log",
    benchmark:
        "results/benchmarks/impedance_figures/{subject}.tsv"
    params:
        onsets=TRIALS["perturbation_onsets_ms"],
    script:
        "../scripts/impedance_figures.py"


rule impedance_figure:
    input:
        "results/tables/impedance.tsv",
    output:
        report(
            "results/figures/impedance.png",
            caption="../report/impedance_figure.rst",
            category="Impedance",
            labels={"figure": "K and D per onset"},
        ),
    log:
        "results/logs/impedance_figure/impedance.log",
    benchmark:
        "results/benchmarks/impedance_figure/impedance.tsv"
    script:
        "../scripts/impedance_figure.py"


def markdown_sections() -> dict:
    """Every result table of the run, for the Markdown rendering."""
    sections = {
        "Impedance per subject, onset and joint": "results/tables/impedance.tsv",
        "Across-subject summary": "results/tables/impedance_summary.tsv",
        "Literature": "results/tables/literature.tsv",
        "Strides per trial": "results/strides/summary.tsv",
        "Validation study": "results/validation/summary.tsv",
        "Device": "results/device/summary.tsv",
    }
    if transparency_subjects():
        sections["Transparency: RMSD vs ISV_ave"] = "results/transparency/rmsd.tsv"
        sections["Transparency: interaction force"] = "results/transparency/force.tsv"
    return sections


rule tables_markdown:
    input:
        list(markdown_sections().values()),
    output:
        "results/tables/tables.md",
    log:
        "results/logs/tables_markdown/tables.log",
    benchmark:
        "results/benchmarks/tables_markdown/tables.tsv"
    params:
        headings=list(markdown_sections()),
    script:
        "../scripts/tables_markdown.py"
