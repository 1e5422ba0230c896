# Ground reactions of the force platforms as OpenSim external loads.


rule grf:
    """Ground reaction forces of the C3D's force platforms as an OpenSim external-loads .mot, in the frame the
    trial's markers were turned into (its markers summary)."""
    input:
        c3d="data/raw/{subject}/{trial}.c3d",
        markers="results/markers/{subject}/{trial}.markers.tsv",
    output:
        "results/grf/{subject}/{trial}.grf.mot",
    log:
        "results/logs/grf/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/grf/{subject}/{trial}.tsv"
    params:
        rotation_deg=config["markers"]["lab_to_model_rotation_deg"],
        threshold_n=config["grf"]["loaded_threshold_n"],
        band_n=config["grf"]["resting_band_n"],
        max_rest_n=config["grf"]["max_resting_n"],
    script:
        "../scripts/grf.py"
