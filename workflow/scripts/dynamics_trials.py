from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.dynamics import step as dynamics

    cycles = dict(zip(map(tuple, snakemake.params.trials), snakemake.input, strict=True))
    dynamics.trial_table(cycles, snakemake.params.without, snakemake.output[0])
