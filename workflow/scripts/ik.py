from loper_analysis.steps import ik, rule_log

p, out = snakemake.params, snakemake.output
with rule_log(snakemake.log[0]):
    ik.ik_trial(snakemake.input.model, snakemake.input.trc, out.mot, out.angles, p.coordinate_map, **p.settings)
