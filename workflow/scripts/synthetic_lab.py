from _logging import setup

from loper_analysis.constants import JOINTS
from loper_analysis.device.controller import DeviceParameters
from loper_analysis.synthetic.subjects import read_truth
from loper_analysis.synthetic.trials import (
    LabSettings,
    PerturbationSettings,
    synthetic_static_file,
    synthetic_walking_files,
)

log = setup(snakemake.log[0])
p, out, subject = snakemake.params, snakemake.output, snakemake.wildcards.subject
s = p.settings
lab, device = LabSettings(**p.lab), DeviceParameters(**p.device)
synthetic_static_file(out.static, subject, p.row["height_m"], p.row["mass_kg"], s["static_duration_s"], lab, p.seed)
log.info("static trial of %s: %s", subject, out.static)
truth = read_truth(snakemake.input.truth)
logs = iter(out.logs)
for trial, c3d, onset_ms in zip(p.trials, out.c3d, p.onsets_ms):
    perturbation = None
    if onset_ms is not None:
        impedance = tuple(truth[onset_ms][j][name] for j in JOINTS for name in ("K", "D"))
        perturbation = PerturbationSettings(onset_ms / 1000.0, impedance, s["pulse_force_n"], s["pulse_duration_s"],
                                            tuple(s["perturb_every_strides"]))
    robot_log = None if trial == p.no_device else next(logs)
    walk = synthetic_walking_files(
        c3d, robot_log, subject, trial, p.row["height_m"], p.row["mass_kg"], s["walking_duration_s"],
        s["timing_cv"], s["amplitude_cv"], lab, device, p.seed, perturbation,
    )
    log.info("%s: true events:\n%s", trial, walk.mocap_events().to_string(index=False))
    log.info("%s: perturbations:\n%s", trial, walk.schedule.to_string(index=False))
