# Markers: a C3D's markers in the model's names and frame, gaps filled or left missing, low-passed (TRC).


rule markers:
    """Markers of a C3D in the model's names and frame (each trial turned to walk along +X), gaps filled or left
    missing, low-passed: a TRC (mm), and per marker its lab label, gaps and the trial's frames, span and rotation."""
    input:
        c3d="data/raw/{subject}/{trial}.c3d",
        label_map=label_map_files,
    output:
        trc="results/markers/{subject}/{trial}.trc",
        gaps="results/markers/{subject}/{trial}.gaps.tsv",
        summary="results/markers/{subject}/{trial}.markers.tsv",
        lab_angles="results/markers/{subject}/{trial}.lab_angles.tsv",
    log:
        "results/logs/markers/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/markers/{subject}/{trial}.tsv"
    group:
        trial_group
    params:
        **settings_params(marker_settings),
        **raw_checksums("data/raw/{subject}/{trial}.c3d"),
    script:
        "../scripts/markers.py"
