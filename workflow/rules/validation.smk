# Validation study of the identification: 729 K/D combinations x {no_noise, noise}.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    validation_segments,
    validation_gather,
    validation_figure,


rule validation_segments:
    output:
        PATHS.validation.segments,
    log:
        PATHS.log("validation_segments", "segments"),
    benchmark:
        PATHS.benchmark("validation_segments", "segments")
    params:
        height_m=SETTINGS["validation"].subject_height_m,
        mass_kg=SETTINGS["validation"].subject_mass_kg,
        attachment_fraction=SETTINGS["validation"].attachment_fraction_of_thigh,
    script:
        "../scripts/validation_segments.py"


rule validation_chunk:
    input:
        segments=PATHS.validation.segments,
    output:
        errors=temp(PATHS.validation.chunk_errors),
        fits=temp(PATHS.validation.chunk_fits),
    log:
        PATHS.log("validation_chunk", "{chunk}"),
    benchmark:
        PATHS.benchmark("validation_chunk", "{chunk}")
    params:
        **settings_params(SETTINGS["validation"]),
        n_chunks=SETTINGS["validation"].n_chunks,
    script:
        "../scripts/validation_chunk.py"


rule validation_gather:
    input:
        errors=expand(PATHS.validation.chunk_errors, chunk=VALIDATION_CHUNKS),
        fits=expand(PATHS.validation.chunk_fits, chunk=VALIDATION_CHUNKS),
    output:
        errors=PATHS.validation.errors,
        fits=PATHS.validation.fits,
        summary=report(
            PATHS.validation.summary,
            caption="../report/validation_summary.rst",
            category="Validation",
            labels={"table": "error summary"},
        ),
    log:
        PATHS.log("validation_gather", "gather"),
    benchmark:
        PATHS.benchmark("validation_gather", "gather")
    script:
        "../scripts/validation_gather.py"


rule validation_figure:
    input:
        errors=PATHS.validation.errors,
    output:
        report(
            PATHS.validation.figure,
            caption="../report/validation_errors.rst",
            category="Validation",
            labels={"figure": "estimation errors"},
        ),
    log:
        PATHS.log("validation_figure", "figure"),
    benchmark:
        PATHS.benchmark("validation_figure", "figure")
    script:
        "../scripts/validation_figure.py"
