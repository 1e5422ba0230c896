import zlib

from _logging import setup

from loper_analysis.device.controller import DeviceParameters, FreeLeg
from loper_analysis.device.files import write_device_trial
from loper_analysis.device.trials import DeviceTestSettings

log = setup(snakemake.log[0])
p = snakemake.params
tests = dict(p.tests, step_amplitudes_n=tuple(p.tests["step_amplitudes_n"]))
seed = [p.seed, zlib.crc32(snakemake.wildcards.subject.encode()), zlib.crc32(snakemake.wildcards.trial.encode())]
events = write_device_trial(
    snakemake.output[0], snakemake.wildcards.trial, DeviceParameters(**p.device), FreeLeg(**p.leg),
    DeviceTestSettings(**tests), seed,
)
log.info("wrote %s (seed %s)", snakemake.output[0], seed)
log.info("safety state changes (time_s, state, name):\n%s", events.to_string(index=False))
