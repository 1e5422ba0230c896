# Markers: a C3D's markers in the model's names and frame, gaps filled or left missing, low-passed (TRC).


rule markers:
    """Markers of a C3D in the model's names and frame (each trial turned to walk along +X), gaps filled or left
    missing, low-passed: a TRC (mm), and per marker its lab label, gaps and the trial's frames, span and rotation."""
    input:
        c3d=PATHS.raw.c3d,
        label_map=label_map_files,
    output:
        trc=PATHS.markers.trc,
        gaps=PATHS.markers.gaps,
        summary=PATHS.markers.summary,
        lab_angles=PATHS.markers.lab_angles,
    log:
        PATHS.log("markers", "{subject}/{trial}"),
    benchmark:
        PATHS.benchmark("markers", "{subject}/{trial}")
    group:
        trial_group
    params:
        **settings_params(marker_settings),
        **raw_checksums(PATHS.raw.c3d),
    script:
        "../scripts/markers.py"
