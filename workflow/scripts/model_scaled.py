from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.model import step as model

    p, i, out = snakemake.params, snakemake.input, snakemake.output
    files = model.ScaleFiles(
        i.generic,
        i.static,
        out.model,
        setup_xml=p.scale_setup,
        static_c3d=(i.static_c3d or [None])[0],
        report_out=out.report,
        static_lab_angles=i.static_lab_angles,
    )
    model.scale(files, p.mass_kg, p.settings, height_m=p.height_m, lab_labels=i.static_summary)
