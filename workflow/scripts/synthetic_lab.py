from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import synthetic

    p, out = snakemake.params, snakemake.output
    synthetic.lab_session(
        snakemake.wildcards.subject,
        p.row,
        snakemake.input.truth,
        out.static,
        p.trials,
        p.onsets_ms,
        out.c3d,
        out.logs,
        p.no_device,
        p.settings,
        p.lab,
        p.device,
        p.seed,
    )
