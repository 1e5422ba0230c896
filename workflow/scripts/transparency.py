from _logging import setup

from loper_analysis.processing import transparency_tables

log = setup(snakemake.log[0])
inp = snakemake.input
trials = {
    s: {c: (inp[f"{c}_strides_{s}"], inp[f"{c}_cycles_{s}"]) for c in ("no_device", "device")}
    for s in snakemake.params.subjects
}
table = transparency_tables(trials, snakemake.output.rmsd, snakemake.output.force, snakemake.output.figure,
                            snakemake.params.side)
log.info("transparency:\n%s", table.to_string())
