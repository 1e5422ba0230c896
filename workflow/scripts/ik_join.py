from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import ik

    ik.ik_join(snakemake.input, snakemake.output.mot, snakemake.output.angles, snakemake.params.coordinate_map)
