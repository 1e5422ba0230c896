# Gait events (force platforms with the heel markers, or one channel per belt) and the robot's load cell
# on the motion-capture clock: one job per trial reads the C3D once.


rule events:
    """Heel strikes and toe-offs of the trial without the device: force platforms with the heel markers, or the
    named GRF channels of each belt."""
    input:
        c3d="data/raw/{subject}/{trial}.c3d",
        label_map=label_map_files,
    output:
        events="results/events/{subject}/{trial}.events.tsv",
        contacts="results/events/{subject}/{trial}.contacts.tsv",
    log:
        "results/logs/events/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/events/{subject}/{trial}.tsv"
    wildcard_constraints:
        trial=TRIALS["no_device"],
    group:
        "trial"
    params:
        **settings_params(event_settings),
        **raw_checksums("data/raw/{subject}/{trial}.c3d"),
    script:
        "../scripts/events.py"


rule events_loadcell:
    """Gait events and the load cell of a trial with the device, in one process that reads the C3D once: the
    heel strikes and toe-offs (as rule events), and the robot log's force on the mocap frames and at its own
    rate. Both feed only the stride table, so a change of either's settings reruns a cheap sibling at most."""
    input:
        c3d="data/raw/{subject}/{trial}.c3d",
        label_map=label_map_files,
        log=robot_log,
    output:
        events="results/events/{subject}/{trial}.events.tsv",
        contacts="results/events/{subject}/{trial}.contacts.tsv",
        force="results/events/{subject}/{trial}.force.tsv",
        native="results/events/{subject}/{trial}.force_native.tsv",
    log:
        "results/logs/events_loadcell/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/events_loadcell/{subject}/{trial}.tsv"
    wildcard_constraints:
        # any trial but the one without the device (the lookahead ends at the wildcard's end, not the path's)
        trial=f"(?!{re.escape(TRIALS['no_device'])}(?![A-Za-z0-9-]))[A-Za-z0-9-]+",
    group:
        "trial"
    params:
        **settings_params(event_settings, "events"),
        **settings_params(LOADCELL_SETTINGS, "loadcell"),
        **raw_checksums("data/raw/{subject}/{trial}.c3d", robot_log),
    script:
        "../scripts/events_loadcell.py"
