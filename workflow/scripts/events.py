from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import processing

    processing.events(
        snakemake.input.c3d,
        snakemake.output.events,
        contacts_out=snakemake.output.contacts,
        **snakemake.params.settings,
    )
