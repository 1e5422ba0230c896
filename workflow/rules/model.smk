# Model: the generic OpenSim model, scaled to the static trial (ScaleTool), and the swing leg's segment
# table.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    model_generic,
    model_segments,


rule model_generic:
    """The generated sagittal model (used when opensim.generic_model is null)."""
    input:
        static_c3d=static_c3d_for_mass,
    output:
        "results/model/{subject}/generic.osim",
    log:
        "results/logs/model_generic/{subject}.log",
    benchmark:
        "results/benchmarks/model_generic/{subject}.tsv"
    params:
        **settings_params(MODEL_SETTINGS),
        **raw_checksums(static_c3d_for_mass),
        height_m=lambda wc: SUBJECT_ROWS[wc.subject]["height_m"],
        mass_kg=lambda wc: SUBJECT_ROWS[wc.subject].get("mass_kg"),
    script:
        "../scripts/model_generic.py"


rule model_scaled:
    """The generic model scaled to the static trial (OpenSim's ScaleTool, with opensim.scale_setup when given), and
    the scale report: scale factors per body, marker errors after scaling, the mass and height used."""
    input:
        generic=generic_model,
        static=f"results/markers/{{subject}}/{TRIALS['static']}.trc",
        static_summary=f"results/markers/{{subject}}/{TRIALS['static']}.markers.tsv",
        static_lab_angles=f"results/markers/{{subject}}/{TRIALS['static']}.lab_angles.tsv",
        static_c3d=static_c3d_for_mass,
        setup=[OPENSIM["scale_setup"]] if OPENSIM["scale_setup"] else [],
    output:
        model="results/model/{subject}/scaled.osim",
        report=report(
            "results/model/{subject}/scale.tsv",
            caption="../report/scale_report.rst",
            category="Model",
            subcategory="{subject}",
            labels={"subject": "{subject}", "table": "scaling"},
        ),
    log:
        "results/logs/model_scaled/{subject}.log",
    benchmark:
        "results/benchmarks/model_scaled/{subject}.tsv"
    group:
        "model"
    params:
        **settings_params(MODEL_SETTINGS),
        **raw_checksums(static_c3d_for_mass),
        mass_kg=lambda wc: SUBJECT_ROWS[wc.subject].get("mass_kg"),
        height_m=lambda wc: SUBJECT_ROWS[wc.subject].get("height_m"),
        scale_setup=OPENSIM["scale_setup"],
    script:
        "../scripts/model_scaled.py"


rule model_segments:
    """The swing leg's segment table, exported from the subject's model (opensim.segment_bodies)."""
    input:
        subject_model,
    output:
        "results/model/{subject}/segments.tsv",
    log:
        "results/logs/model_segments/{subject}.log",
    benchmark:
        "results/benchmarks/model_segments/{subject}.tsv"
    params:
        **settings_params(MODEL_SETTINGS),
    script:
        "../scripts/model_segments.py"
