from _logging import setup

from loper_analysis.device.controller import DeviceParameters
from loper_analysis.synthetic.trials import LabSettings, synthetic_walking_files

log = setup(snakemake.log[0])
p = snakemake.params
out = snakemake.output
events = synthetic_walking_files(
    out.c3d, out.get("log"), snakemake.wildcards.subject, p.trial, p.row["height_m"], p.row["mass_kg"],
    p.settings["walking_duration_s"], p.settings["timing_cv"], p.settings["amplitude_cv"], LabSettings(**p.lab),
    DeviceParameters(**p.device), p.settings["brace_attachment_fraction"], p.seed,
)
log.info("true events:\n%s", events.to_string(index=False))
