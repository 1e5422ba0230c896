from _logging import setup

from loper_analysis.io.robot_log import read_robot_log_mat, write_robot_log

log = setup(snakemake.log[0])
frame, meta = read_robot_log_mat(snakemake.input[0], snakemake.params.column_map, snakemake.params.sample_rate_hz)
write_robot_log(snakemake.output[0], frame, snakemake.params.sample_rate_hz, {"source": str(snakemake.input[0])})
log.info("converted %s (%d samples)", snakemake.input[0], len(frame))
