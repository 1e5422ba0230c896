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
        fit_inputs,
    output:
        response=expand(FIT_OUTPUTS["response"], onset=ONSETS, allow_missing=True),
        counts=expand(FIT_OUTPUTS["counts"], onset=ONSETS, allow_missing=True),
        fit=expand(FIT_OUTPUTS["fit"], onset=ONSETS, allow_missing=True),
        curves=expand(FIT_OUTPUTS["curves"], onset=ONSETS, allow_missing=True),
        force=expand(FIT_OUTPUTS["force"], onset=ONSETS, allow_missing=True),
    log:
        "results/logs/impedance_fit/{subject}.log",
    benchmark:
        "results/benchmarks/impedance_fit/{subject}.tsv"
    params:
        **settings_params(FIT_SETTINGS),
        fits=lambda wc: fit_files(wc.subject),
    script:
        "../scripts/impedance_fit.py"


rule impedance_table:
    input:
        [f"results/impedance/{s}/{o:03d}.tsv" for s in processed_subjects() for o in TRIALS["perturbation_onsets_ms"]],
    output:
        report(
            "results/impedance/impedance.tsv",
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
        "results/impedance/impedance.tsv",
    output:
        summary=report(
            "results/impedance/summary.tsv",
            caption="../report/impedance_summary.rst",
            category="Impedance",
            labels={"table": "across-subject summary per onset"},
        ),
        literature=report(
            "results/impedance/literature.tsv",
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
        lower_bounds=(IDENT["stiffness_bounds_nm_per_rad"][0], IDENT["damping_bounds_nms_per_rad"][0]),
    script:
        "../scripts/impedance_summary.py"


rule impedance_figures:
    input:
        responses=lambda wc: [
            f"results/impedance/{wc.subject}/{o:03d}.response.tsv" for o in TRIALS["perturbation_onsets_ms"]
        ],
        curves=lambda wc: [
            f"results/impedance/{wc.subject}/{o:03d}.curves.tsv" for o in TRIALS["perturbation_onsets_ms"]
        ],
    output:
        responses=report(
            "results/impedance/{subject}/responses.png",
            caption="../report/responses_figure.rst",
            category="Impedance",
            subcategory="{subject}",
            labels={"subject": "{subject}", "figure": "responses"},
        ),
        fit=report(
            "results/impedance/{subject}/fit.png",
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
        "results/impedance/impedance.tsv",
    output:
        report(
            "results/impedance/impedance.png",
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
