from _logging import setup

from loper_analysis.constants import JOINTS
from loper_analysis.device.controller import DeviceParameters
from loper_analysis.synthetic.subjects import read_truth
from loper_analysis.synthetic.trials import LabSettings, PerturbationSettings, synthetic_walking_files

log = setup(snakemake.log[0])
p = snakemake.params
s = p.settings
perturbation = None
if p.onset_ms is not None:
    truth = read_truth(snakemake.input.truth)[p.onset_ms]
    impedance = tuple(truth[j][name] for j in JOINTS for name in ("K", "D"))
    perturbation = PerturbationSettings(p.onset_ms / 1000.0, impedance, s["pulse_force_n"], s["pulse_duration_s"],
                                        tuple(s["perturb_every_strides"]))
out = snakemake.output
walk = synthetic_walking_files(
    out.c3d, out.get("log"), snakemake.wildcards.subject, p.trial, p.row["height_m"], p.row["mass_kg"],
    s["walking_duration_s"], s["timing_cv"], s["amplitude_cv"], LabSettings(**p.lab), DeviceParameters(**p.device),
    p.seed, perturbation,
)
log.info("true events:\n%s", walk.mocap_events().to_string(index=False))
log.info("perturbations:\n%s", walk.schedule.to_string(index=False))
