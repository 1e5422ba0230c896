from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import report

    report.front_page(
        snakemake.output[0],
        snakemake.input.get("device"),
        snakemake.input.validation,
        snakemake.params.subjects,
        snakemake.params.trials,
        snakemake.params.settings,
        impedance_tsv=snakemake.input.get("impedance"),
        summary_tsv=snakemake.input.get("summary"),
        figure_png=snakemake.input.get("figure"),
        rmsd_tsv=snakemake.input.get("rmsd"),
    )
