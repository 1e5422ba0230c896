# Strides: joint angles and forces cut heel strike to heel strike, the outlier rule, the trials' summary.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    strides_summary,


rule strides:
    input:
        angles=PATHS.ik.angles,
        events=PATHS.events.events,
        force=by_trial(STUDY.stride_force),
    output:
        strides=PATHS.strides.strides,
        cycles=PATHS.strides.cycles,
        dropped=PATHS.strides.dropped,
    log:
        PATHS.log("strides", "{subject}/{trial}"),
    benchmark:
        PATHS.benchmark("strides", "{subject}/{trial}")
    group:
        "trial"
    params:
        **settings_params(SETTINGS["strides"]),
    script:
        "../scripts/strides.py"


rule strides_summary:
    input:
        strides=STUDY.trial_files("strides", "strides"),
        contacts=STUDY.trial_files("events", "contacts"),
        ik=STUDY.trial_files("ik", "summary"),
        markers=STUDY.trial_files("markers", "summary"),
        agreement=STUDY.trial_files("ik", "agreement"),
        dropped=STUDY.trial_files("strides", "dropped"),
    output:
        report(
            PATHS.strides.summary,
            caption="../report/strides_summary.rst",
            category="Processing",
            labels={"table": "strides per trial"},
        ),
    log:
        PATHS.log("strides_summary", "summary"),
    benchmark:
        PATHS.benchmark("strides_summary", "summary")
    params:
        subject_trial=[(s, t) for s in STUDY.processed_subjects() for t in STUDY.subject_trials(s)],
        min_valid=SETTINGS["strides"].min_valid,
    script:
        "../scripts/strides_summary.py"


rule strides_figure:
    """Both sides' joint angles over the gait cycle, with the lab's own where its file holds them (recorded
    subjects)."""
    input:
        angles=PATHS.ik.angles,
        events=PATHS.events.events,
        lab_angles=PATHS.markers.lab_angles,
    output:
        report(
            PATHS.strides.figure,
            caption="../report/strides_figure.rst",
            category="Processing",
            subcategory="{subject}",
            labels={"subject": "{subject}", "trial": "{trial}", "figure": "joint angles"},
        ),
    log:
        PATHS.log("strides_figure", "{subject}/{trial}"),
    benchmark:
        PATHS.benchmark("strides_figure", "{subject}/{trial}")
    params:
        title=lambda wc: f"{wc.subject} {wc.trial}: joint angles over the gait cycle (mean ± SD; dashed: the lab's)",
    script:
        "../scripts/strides_figure.py"
