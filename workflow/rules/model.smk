# Model: the generic OpenSim model, scaled to the static trial (ScaleTool), and the swing leg's segment
# table.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    model_generic,
    model_segments,


rule model_generic:
    """The generated sagittal model (used when model.generic_model is null)."""
    input:
        static_c3d=by_subject(STUDY.static_c3d_for_mass),
    output:
        PATHS.model.generic,
    log:
        PATHS.log("model_generic", "{subject}"),
    benchmark:
        PATHS.benchmark("model_generic", "{subject}")
    params:
        **settings_params(SETTINGS["model"].for_generic()),
        **raw_checksums(by_subject(STUDY.static_c3d_for_mass)),
        height_m=lambda wc: SUBJECT_ROWS[wc.subject]["height_m"],
        mass_kg=lambda wc: SUBJECT_ROWS[wc.subject].get("mass_kg"),
    script:
        "../scripts/model_generic.py"


rule model_scaled:
    """The generic model scaled to the static trial (OpenSim's ScaleTool, with model.scale_setup when given), and
    the scale report: scale factors per body, marker errors after scaling, the mass and height used."""
    input:
        generic=by_subject(STUDY.generic_model),
        static=fill(PATHS.markers.trc, trial=DESIGN.static),
        static_summary=fill(PATHS.markers.summary, trial=DESIGN.static),
        static_lab_angles=fill(PATHS.markers.lab_angles, trial=DESIGN.static),
        static_c3d=by_subject(STUDY.static_c3d_for_scaling),
        setup=[SETTINGS["model"].scale_setup] if SETTINGS["model"].scale_setup else [],
    output:
        model=PATHS.model.scaled,
        report=report(
            PATHS.model.scale,
            caption="../report/scale_report.rst",
            category="Model",
            subcategory="{subject}",
            labels={"subject": "{subject}", "table": "scaling"},
        ),
    log:
        PATHS.log("model_scaled", "{subject}"),
    benchmark:
        PATHS.benchmark("model_scaled", "{subject}")
    group:
        "model"
    params:
        **settings_params(SETTINGS["model"].for_scaling()),
        **raw_checksums(by_subject(STUDY.static_c3d_for_scaling)),
        mass_kg=lambda wc: SUBJECT_ROWS[wc.subject].get("mass_kg"),
        height_m=lambda wc: SUBJECT_ROWS[wc.subject].get("height_m"),
        scale_setup=SETTINGS["model"].scale_setup,
    script:
        "../scripts/model_scaled.py"


rule model_segments:
    """The swing leg's segment table, exported from the subject's model (model.segment_bodies)."""
    input:
        by_subject(STUDY.subject_model),
    output:
        PATHS.model.segments,
    log:
        PATHS.log("model_segments", "{subject}"),
    benchmark:
        PATHS.benchmark("model_segments", "{subject}")
    params:
        **settings_params(SETTINGS["model"].for_segments()),
    script:
        "../scripts/model_segments.py"
