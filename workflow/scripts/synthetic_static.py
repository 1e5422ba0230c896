from _logging import setup

from loper_analysis.synthetic.trials import LabSettings, synthetic_static_file

log = setup(snakemake.log[0])
p = snakemake.params
synthetic_static_file(snakemake.output[0], snakemake.wildcards.subject, p.row["height_m"], p.row["mass_kg"],
                      p.duration_s, LabSettings(**p.lab), p.seed)
log.info("static trial of %s", snakemake.wildcards.subject)
