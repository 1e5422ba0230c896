# The simulated gait lab: raw files of synthetic subjects (never of recorded ones, see SYNTHETIC_PATTERN).


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    synthetic_truth,


rule synthetic_truth:
    output:
        PATHS.raw.truth,
    log:
        PATHS.log("synthetic_truth", "{subject}"),
    benchmark:
        PATHS.benchmark("synthetic_truth", "{subject}")
    wildcard_constraints:
        subject=SYNTHETIC_PATTERN,
    params:
        **settings_params(SETTINGS["synthetic"].truth, "truth"),
        row=lambda wc: SUBJECT_ROWS[wc.subject],
        seed=SETTINGS["study"].seed,
    script:
        "../scripts/synthetic_truth.py"


rule synthetic_lab:
    """One session of the simulated gait lab per synthetic subject: the static trial and every walking trial
    (C3D, and the robot log of trials with the device). One job per subject: a trial's own work is a second,
    the start of a job (Python, SciPy, OpenSim, numba) almost three."""
    input:
        truth=PATHS.raw.truth,
    output:
        static=fill(PATHS.raw.c3d, trial=DESIGN.static),
        c3d=[fill(PATHS.raw.c3d, trial=t) for t in DESIGN.walking_trials()],
        logs=[fill(PATHS.raw.robot_log, trial=t) for t in DESIGN.walking_trials() if DESIGN.with_robot(t)],
    log:
        PATHS.log("synthetic_lab", "{subject}"),
    benchmark:
        PATHS.benchmark("synthetic_lab", "{subject}")
    wildcard_constraints:
        subject=SYNTHETIC_PATTERN,
    params:
        **settings_params(SETTINGS["synthetic"]),
        row=lambda wc: SUBJECT_ROWS[wc.subject],
    script:
        "../scripts/synthetic_lab.py"
