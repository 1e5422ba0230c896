from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.device import step as device

    p, wc = snakemake.params, snakemake.wildcards
    device.device_trial(snakemake.output[0], wc.subject, wc.trial, p.device, p.leg, p.tests, p.seed)
