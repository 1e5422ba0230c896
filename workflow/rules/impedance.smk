# Perturbation analysis: responses (matched strides) and impedance fits per subject and onset, aggregate tables.

from loper_analysis.stages.impedance.files import fit_files, fit_inputs, fits_couplings


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
        lambda wc: fit_inputs(STUDY, wc.subject),
    output:
        # the inter-joint couplings' rows, written by a fit with impedance.couplings
        **(
            {"couplings": expand(PATHS.impedance.couplings, onset=ONSETS, allow_missing=True)}
            if fits_couplings(STUDY)
            else {}
        ),
        response=expand(PATHS.impedance.response, onset=ONSETS, allow_missing=True),
        counts=expand(PATHS.impedance.counts, onset=ONSETS, allow_missing=True),
        fit=expand(PATHS.impedance.fit, onset=ONSETS, allow_missing=True),
        curves=expand(PATHS.impedance.curves, onset=ONSETS, allow_missing=True),
        force=expand(PATHS.impedance.force, onset=ONSETS, allow_missing=True),
    log:
        PATHS.log("impedance_fit", "{subject}"),
    benchmark:
        PATHS.benchmark("impedance_fit", "{subject}")
    params:
        **settings_params(SETTINGS["impedance"]),
        fits=lambda wc: fit_files(STUDY, wc.subject),
    script:
        "../scripts/impedance_fit.py"


rule impedance_table:
    input:
        STUDY.onset_files("impedance", "fit"),
    output:
        report(
            PATHS.impedance.table,
            caption="../report/impedance_table.rst",
            category="Impedance",
            labels={"table": "impedance per subject, onset and joint"},
        ),
    log:
        PATHS.log("impedance_table", "impedance"),
    benchmark:
        PATHS.benchmark("impedance_table", "impedance")
    script:
        "../scripts/impedance_table.py"


if fits_couplings(STUDY):

    localrules:
        impedance_couplings_table,

    rule impedance_couplings_table:
        input:
            STUDY.onset_files("impedance", "couplings"),
        output:
            report(
                PATHS.impedance.coupling_table,
                caption="../report/coupling_table.rst",
                category="Impedance",
                labels={"table": "inter-joint couplings per subject and onset"},
            ),
        log:
            PATHS.log("impedance_couplings_table", "couplings"),
        benchmark:
            PATHS.benchmark("impedance_couplings_table", "couplings")
        script:
            "../scripts/impedance_table.py"


rule impedance_summary:
    input:
        PATHS.impedance.table,
    output:
        summary=report(
            PATHS.impedance.summary,
            caption="../report/impedance_summary.rst",
            category="Impedance",
            labels={"table": "across-subject summary per onset"},
        ),
        literature=report(
            PATHS.impedance.literature,
            caption="../report/literature.rst",
            category="Impedance",
            labels={"table": "literature comparison"},
        ),
    log:
        PATHS.log("impedance_summary", "summary"),
    benchmark:
        PATHS.benchmark("impedance_summary", "summary")
    params:
        upper_bounds=fit_bounds(1),
        lower_bounds=fit_bounds(0),
    script:
        "../scripts/impedance_summary.py"


rule impedance_figures:
    input:
        responses=lambda wc: STUDY.onset_files("impedance", "response", wc.subject),
        curves=lambda wc: STUDY.onset_files("impedance", "curves", wc.subject),
    output:
        responses=report(
            PATHS.impedance.responses_figure,
            caption="../report/responses_figure.rst",
            category="Impedance",
            subcategory="{subject}",
            labels={"subject": "{subject}", "figure": "responses"},
        ),
        fit=report(
            PATHS.impedance.fit_figure,
            caption="../report/fit_figure.rst",
            category="Impedance",
            subcategory="{subject}",
            labels={"subject": "{subject}", "figure": "fit vs data"},
        ),
    log:
        PATHS.log("impedance_figures", "{subject}"),
    benchmark:
        PATHS.benchmark("impedance_figures", "{subject}")
    params:
        onsets=list(DESIGN.perturbation_onsets_ms),
    script:
        "../scripts/impedance_figures.py"


rule impedance_figure:
    input:
        PATHS.impedance.table,
    output:
        report(
            PATHS.impedance.figure,
            caption="../report/impedance_figure.rst",
            category="Impedance",
            labels={"figure": "K and D per onset"},
        ),
    log:
        PATHS.log("impedance_figure", "impedance"),
    benchmark:
        PATHS.benchmark("impedance_figure", "impedance")
    script:
        "../scripts/impedance_figure.py"
