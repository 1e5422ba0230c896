# Perturbation analysis: responses (matched strides) and impedance fits per subject and onset, aggregate tables.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    impedance_table,
    impedance_summary,
    impedance_figures,
    impedance_figure,


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
