from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.model import step as model

    model.segments_from_model_file(snakemake.input[0], snakemake.output[0], snakemake.params.settings)
