# Validation study of the identification: 729 K/D combinations x {no_noise, noise}.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    validation_segments,
    validation_gather,
    validation_figure,


rule validation_segments:
    output:
        "results/validation/segments.tsv",
    log:
        "results/logs/validation_segments/segments.log",
    benchmark:
        "results/benchmarks/validation_segments/segments.tsv"
    params:
        height_m=config["validation"]["subject_height_m"],
        mass_kg=config["validation"]["subject_mass_kg"],
        attachment_fraction=config["validation"]["attachment_fraction_of_thigh"],
    script:
        "../scripts/validation_segments.py"


rule validation_chunk:
    input:
        segments="results/validation/segments.tsv",
    output:
        errors=temp("results/validation/chunks/{chunk}.errors.tsv"),
        fits=temp("results/validation/chunks/{chunk}.fits.tsv"),
    log:
        "results/logs/validation_chunk/{chunk}.log",
    benchmark:
        "results/benchmarks/validation_chunk/{chunk}.tsv"
    params:
        settings=validation_settings(config),
        n_chunks=config["validation"]["n_chunks"],
    script:
        "../scripts/validation_chunk.py"


rule validation_gather:
    input:
        errors=expand("results/validation/chunks/{chunk}.errors.tsv", chunk=VALIDATION_CHUNKS),
        fits=expand("results/validation/chunks/{chunk}.fits.tsv", chunk=VALIDATION_CHUNKS),
    output:
        errors="results/validation/errors.tsv",
        fits="results/validation/fits.tsv",
        summary=report(
            "results/validation/summary.tsv",
            caption="../report/validation_summary.rst",
            category="Validation",
            labels={"table": "error summary"},
        ),
    log:
        "results/logs/validation_gather/gather.log",
    benchmark:
        "results/benchmarks/validation_gather/gather.tsv"
    script:
        "../scripts/validation_gather.py"


rule validation_figure:
    input:
        errors="results/validation/errors.tsv",
    output:
        report(
            "results/validation/errors.png",
            caption="../report/validation_errors.rst",
            category="Validation",
            labels={"figure": "estimation errors"},
        ),
    log:
        "results/logs/validation_figure/figure.log",
    benchmark:
        "results/benchmarks/validation_figure/figure.tsv"
    script:
        "../scripts/validation_figure.py"
