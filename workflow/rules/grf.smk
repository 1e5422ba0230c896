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
        **raw_checksums("data/raw/{subject}/{trial}.c3d"),
    script:
        "../scripts/grf.py"


rule grf_figure:
    """The trial's force plates over time with the heel strikes and toe-offs found (recorded subjects)."""
    input:
        grf="results/grf/{subject}/{trial}.grf.mot",
        events="results/events/{subject}/{trial}.events.tsv",
    output:
        report(
            "results/grf/{subject}/{trial}.grf.png",
            caption="../report/grf_figure.rst",
            category="Processing",
            subcategory="{subject}",
            labels={"subject": "{subject}", "trial": "{trial}", "figure": "force plates and events"},
        ),
    log:
        "results/logs/grf_figure/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/grf_figure/{subject}/{trial}.tsv"
    params:
        title=lambda wc: f"{wc.subject} {wc.trial}: force plates; heel strikes solid, toe-offs dotted",
    script:
        "../scripts/grf_figure.py"
