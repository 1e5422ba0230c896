from loper_analysis.steps import model, rule_log

p = snakemake.params
with rule_log(snakemake.log[0]):
    model.segments_from_model_file(snakemake.input[0], snakemake.output[0], p.side, p.segment_bodies,
                                   p.attachment_fraction)
