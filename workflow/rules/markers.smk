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
    log:
        "results/logs/markers/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/markers/{subject}/{trial}.tsv"
    group:
        trial_group
    params:
        rotation_deg=MARKERS["lab_to_model_rotation_deg"],
        walking_direction=MARKERS["walking_direction"],
        min_travel_speed_m_per_s=MARKERS["min_travel_speed_m_per_s"],
        # the static trial is averaged over the scaling window, each marker over the frames it is present in:
        # neither filled nor filtered (as OpenSim's ScaleTool reads a lab's static trial)
        max_gap_frames=lambda wc: 0 if wc.trial == TRIALS["static"] else MARKERS["max_gap_frames"],
        cutoff_hz=lambda wc: None if wc.trial == TRIALS["static"] else FILTER["cutoff_hz"],
        order=FILTER["order"],
        span_s=lambda wc: trial_span_s(wc.subject, wc.trial),
        label_maps=lambda wc: trial_label_maps(wc.trial),
        extent_range_m=MARKERS["extent_range_m"],
    script:
        "../scripts/markers.py"
