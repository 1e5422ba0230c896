from loper_analysis.steps import rule_log, transparency

inp, out = snakemake.input, snakemake.output
trials = {s: {c: (inp[f"{c}_strides_{s}"], inp[f"{c}_cycles_{s}"]) for c in ("no_device", "device")}
          for s in snakemake.params.subjects}
with rule_log(snakemake.log[0]):
    transparency.transparency(trials, out.rmsd, out.force, out.figure, snakemake.params.side)
