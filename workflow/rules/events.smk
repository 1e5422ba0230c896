# Gait events (force platforms with the heel markers, or one channel per belt) and the robot's load cell
# on the motion-capture clock: one job per trial reads the C3D once.


rule events:
    """Heel strikes and toe-offs of the trial without the device: force platforms with the heel markers, or the
    named GRF channels of each belt."""
    input:
        c3d=PATHS.raw.c3d,
        label_map=label_map_files,
    output:
        events=PATHS.events.events,
        contacts=PATHS.events.contacts,
    log:
        PATHS.log("events", "{subject}/{trial}"),
    benchmark:
        PATHS.benchmark("events", "{subject}/{trial}")
    wildcard_constraints:
        trial=DESIGN.no_device,
    group:
        "trial"
    params:
        **settings_params(event_settings),
        **raw_checksums(PATHS.raw.c3d),
    script:
        "../scripts/events.py"


rule events_loadcell:
    """Gait events and the load cell of a trial with the device, in one process that reads the C3D once: the
    heel strikes and toe-offs (as rule events), and the robot log's force on the mocap frames and at its own
    rate. Both feed only the stride table, so a change of either's settings reruns a cheap sibling at most."""
    input:
        c3d=PATHS.raw.c3d,
        label_map=label_map_files,
        log=by_trial(STUDY.robot_log),
    output:
        events=PATHS.events.events,
        contacts=PATHS.events.contacts,
        force=PATHS.events.force,
        native=PATHS.events.force_native,
    log:
        PATHS.log("events_loadcell", "{subject}/{trial}"),
    benchmark:
        PATHS.benchmark("events_loadcell", "{subject}/{trial}")
    wildcard_constraints:
        # any trial but the one without the device (the lookahead ends at the wildcard's end, not the path's)
        trial=f"(?!{re.escape(DESIGN.no_device)}(?![A-Za-z0-9-]))[A-Za-z0-9-]+",
    group:
        "trial"
    params:
        **settings_params(event_settings, "events"),
        **settings_params(SETTINGS["events"].loadcell, "loadcell"),
        **raw_checksums(PATHS.raw.c3d, by_trial(STUDY.robot_log)),
    script:
        "../scripts/events_loadcell.py"
