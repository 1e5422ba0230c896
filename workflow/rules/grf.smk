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
        **settings_params(GRF_SETTINGS),
    script:
        "../scripts/grf.py"
