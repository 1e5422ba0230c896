# Ground reactions of the force platforms as OpenSim external loads.


rule grf:
    """Ground reaction forces of the C3D's force platforms as an OpenSim external-loads .mot, in the frame the
    trial's markers were turned into (its markers summary)."""
    input:
        c3d=PATHS.raw.c3d,
        markers=PATHS.markers.summary,
    output:
        PATHS.grf.mot,
    log:
        PATHS.log("grf", "{subject}/{trial}"),
    benchmark:
        PATHS.benchmark("grf", "{subject}/{trial}")
    params:
        **settings_params(SETTINGS["grf"]),
        **raw_checksums(PATHS.raw.c3d),
    script:
        "../scripts/grf.py"


rule grf_figure:
    """The trial's force plates over time with the heel strikes and toe-offs found (recorded subjects)."""
    input:
        grf=PATHS.grf.mot,
        events=PATHS.events.events,
    output:
        report(
            PATHS.grf.figure,
            caption="../report/grf_figure.rst",
            category="Processing",
            subcategory="{subject}",
            labels={"subject": "{subject}", "trial": "{trial}", "figure": "force plates and events"},
        ),
    log:
        PATHS.log("grf_figure", "{subject}/{trial}"),
    benchmark:
        PATHS.benchmark("grf_figure", "{subject}/{trial}")
    params:
        title=lambda wc: f"{wc.subject} {wc.trial}: force plates; heel strikes solid, toe-offs dotted",
    script:
        "../scripts/grf_figure.py"
