from loper_analysis.steps import device, rule_log

p, wc = snakemake.params, snakemake.wildcards
with rule_log(snakemake.log[0]):
    device.device_trial(snakemake.output[0], wc.subject, wc.trial, p.device, p.leg, p.tests, p.seed)
