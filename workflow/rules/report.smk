# The report: its front page (what was run, the headline numbers and the main figure, as one HTML fragment
# that workflow/report/workflow.rst pulls in above the methods text) and every result table in Markdown.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    front_page,
    tables_markdown,


rule front_page:
    input:
        unpack(front_page_inputs),
    output:
        "results/report/front_page.html",
    log:
        "results/logs/front_page/front_page.log",
    benchmark:
        "results/benchmarks/front_page/front_page.tsv"
    params:
        subjects=SUBJECT_SOURCE,
        trials={s: subject_trials(s) for s in processed_subjects()},
        settings=dict(
            seed=config["seed"],
            perturbation_onsets_ms=TRIALS["perturbation_onsets_ms"],
            perturbation_repeats=TRIALS["perturbation_repeats"],
            perturbed_side=TRIALS["perturbed_side"],
            filter_cutoff_hz=FILTER["cutoff_hz"],
            filter_order=FILTER["order"],
            window_before_s=IDENT["window_before_s"],
            window_after_s=IDENT["window_after_s"],
            stiffness_bounds_nm_per_rad=IDENT["stiffness_bounds_nm_per_rad"],
            damping_bounds_nms_per_rad=IDENT["damping_bounds_nms_per_rad"],
            n_starts=IDENT["n_starts"],
            noise_model=IDENT["noise_model"],
            null_pair_components=IDENT["null_pair_components"],
            synthetic_variability=config["synthetic"]["variability"],
            synthetic_walking_duration_s=config["synthetic"]["walking_duration_s"],
            pulse_force_n=config["synthetic"]["pulse_force_n"],
            pulse_duration_s=config["synthetic"]["pulse_duration_s"],
        ),
    script:
        "../scripts/front_page.py"


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
