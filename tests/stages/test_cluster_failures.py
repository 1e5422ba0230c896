"""The file step of a failed SLURM run (loper_analysis.stages.cluster_failures): why SLURM ended each failed job, from
Snakemake's log and the jobs' outputs on disk; the partitions a run asks for, from Snakemake's own parsers."""

from snakemake.cli import parse_set_resources
from snakemake.resources import Resources
from snakemake.settings.types import ResourceSettings

from loper_analysis.stages.cluster_failures import requested_partitions, slurm_failure_lines
from tests.test_cluster import CONSOLE, MEMORY_KILLED


def test_the_summary_names_job_reason_and_output_only_for_jobs_slurm_ended(tmp_path):
    logs = tmp_path / ".snakemake" / "slurm_logs"
    (logs / "rule_synthetic_lab" / "S02").mkdir(parents=True)
    (logs / "rule_synthetic_lab" / "S02" / "9.log").write_text("Building DAG of jobs...\n" + MEMORY_KILLED)
    (logs / "rule_events_loadcell").mkdir()
    (logs / "rule_events_loadcell" / "12.log").write_text("LoperInputError: data/raw/S01/pert050-1.loper.tsv\n")
    console = tmp_path / "snakemake.log"
    console.write_text(
        CONSOLE.replace("/w/", f"{tmp_path}/")
        + f"    log: {logs}/rule_events_loadcell/12.log (check log file(s) for error details)\n"
    )
    assert slurm_failure_lines(console) == [
        f"SLURM job 9 (rule_synthetic_lab/S02): killed by SLURM for exceeding its memory: raise the rule's mem_mb "
        f"under set-resources in the profile (SLURM's output: {logs}/rule_synthetic_lab/S02/9.log)"
    ]


def test_a_missing_snakemake_log_or_job_output_gives_no_line(tmp_path):
    assert slurm_failure_lines(tmp_path / "absent.log") == []
    console = tmp_path / "snakemake.log"
    console.write_text(CONSOLE.replace("/w/", f"{tmp_path}/"))  # no SLURM output written
    assert slurm_failure_lines(console) == []


def _default_resources(*exprs: str) -> Resources:
    """``--default-resources`` as Snakemake's command line parses it."""
    return Resources.parser_factory(defaults="full", allow_expressions=True)(list(exprs))


def test_the_partitions_are_read_where_they_were_given():
    settings = ResourceSettings(
        default_resources=_default_resources("slurm_partition='standard'", "mem_mb=1000"),
        overwrite_resources=parse_set_resources(["ik:slurm_partition=long", "ik:mem_mb=4000", "grf:mem_mb=10"]),
    )
    assert requested_partitions(settings) == {"default-resources": "standard", "set-resources ik": "long"}


def test_no_partition_asked_for_gives_none():
    assert requested_partitions(ResourceSettings()) == {}
    settings = ResourceSettings(
        default_resources=_default_resources("mem_mb=1000"),
        overwrite_resources=parse_set_resources(["strides:slurm_partition=short"]),
    )
    assert requested_partitions(settings) == {"set-resources strides": "short"}
