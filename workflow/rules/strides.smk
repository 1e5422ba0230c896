# Strides: joint angles and forces cut heel strike to heel strike, the outlier rule, the trials' summary.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    strides_summary,


rule strides:
    input:
        angles="results/ik/{subject}/{trial}.angles.tsv",
        events="results/events/{subject}/{trial}.events.tsv",
        force=stride_force,
    output:
        strides="results/strides/{subject}/{trial}.strides.tsv",
        cycles="results/strides/{subject}/{trial}.cycles.tsv",
        dropped="results/strides/{subject}/{trial}.dropped.tsv",
    log:
        "results/logs/strides/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/strides/{subject}/{trial}.tsv"
    group:
        "trial"
    params:
        **settings_params(STRIDE_SETTINGS),
    script:
        "../scripts/strides.py"


rule strides_summary:
    input:
        strides=[f"results/strides/{s}/{t}.strides.tsv" for s in processed_subjects() for t in subject_trials(s)],
        contacts=[f"results/events/{s}/{t}.contacts.tsv" for s in processed_subjects() for t in subject_trials(s)],
        ik=[f"results/ik/{s}/{t}.ik.tsv" for s in processed_subjects() for t in subject_trials(s)],
        markers=[f"results/markers/{s}/{t}.markers.tsv" for s in processed_subjects() for t in subject_trials(s)],
        agreement=[f"results/ik/{s}/{t}.lab_agreement.tsv" for s in processed_subjects() for t in subject_trials(s)],
        dropped=[f"results/strides/{s}/{t}.dropped.tsv" for s in processed_subjects() for t in subject_trials(s)],
    output:
        report(
            "results/strides/summary.tsv",
            caption="../report/strides_summary.rst",
            category="Processing",
            labels={"table": "strides per trial"},
        ),
    log:
        "results/logs/strides_summary/summary.log",
    benchmark:
        "results/benchmarks/strides_summary/summary.tsv"
    params:
        subject_trial=[(s, t) for s in processed_subjects() for t in subject_trials(s)],
        min_valid=STRIDE_SETTINGS.min_valid,
    script:
        "../scripts/strides_summary.py"


rule strides_figure:
    """Both sides' joint angles over the gait cycle, with the lab's own where its file holds them (recorded
    subjects)."""
    input:
        angles="results/ik/{subject}/{trial}.angles.tsv",
        events="results/events/{subject}/{trial}.events.tsv",
        lab_angles="results/markers/{subject}/{trial}.lab_angles.tsv",
    output:
        report(
            "results/strides/{subject}/{trial}.angles.png",
            caption="../report/strides_figure.rst",
            category="Processing",
            subcategory="{subject}",
            labels={"subject": "{subject}", "trial": "{trial}", "figure": "joint angles"},
        ),
    log:
        "results/logs/strides_figure/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/strides_figure/{subject}/{trial}.tsv"
    params:
        title=lambda wc: f"{wc.subject} {wc.trial}: joint angles over the gait cycle (mean ± SD; dashed: the lab's)",
    script:
        "../scripts/strides_figure.py"
