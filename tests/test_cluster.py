"""Checks before a SLURM submission: sbatch on PATH and the requested partitions, on this machine's real PATH."""

import shutil

import pytest

from loper_analysis.cluster import check_slurm_submission, failed_slurm_logs, slurm_end_reason, submission_problems
from loper_analysis.errors import LoperInputError
from loper_analysis.stages import study_paths

PATHS = study_paths()


def test_nothing_stops_a_submission_to_known_partitions():
    assert (
        submission_problems(
            {"default-resources": "standard", "set-resources ik": "long"}, ["standard", "long"], "/usr/bin/sbatch"
        )
        == []
    )


def test_an_unknown_partition_is_named_with_where_it_was_asked_for_and_what_exists():
    problems = submission_problems(
        {"default-resources": "standard", "set-resources ik": "nosuch"}, ["standard", "debug"], "/usr/bin/sbatch"
    )
    assert len(problems) == 1
    assert problems[0] == (
        "set-resources ik: slurm_partition 'nosuch' is not a partition of this cluster (sinfo lists: debug, standard)"
    )


def test_a_missing_sbatch_is_one_problem_and_partitions_are_not_guessed():
    problems = submission_problems({"default-resources": "nosuch"}, None, None)
    assert len(problems) == 1
    assert "sbatch, which is not on PATH" in problems[0]


def test_without_sbatch_on_path_the_check_raises_before_anything_is_submitted(tmp_path, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path))  # an empty folder: no sbatch, no sinfo
    assert shutil.which("sbatch") is None
    with pytest.raises(
        LoperInputError,
        match=r"^cannot submit to SLURM: the SLURM profile submits jobs with "
        r"sbatch, which is not on PATH",
    ):
        check_slurm_submission({"default-resources": "standard"})


# What slurmstepd (SLURM 22.05) wrote into jobs' outputs on the smoke test's cluster, and what a cgroup
# cluster writes for a memory kill.
MEMORY_KILLED = """slurmstepd-vm: error: *** JOB 9 ON vm CANCELLED AT 2026-11-25T17:06:14 ***
Killed
slurmstepd-vm: error: Exceeded job memory limit
slurmstepd-vm: error: StepId=9.batch exceeded memory limit (158093312 > 62914560), being killed
"""
CGROUP_OOM = (
    "slurmstepd: error: Detected 1 oom-kill event(s) in StepId=4242.batch. Some of your processes may "
    "have been killed by the cgroup out-of-memory handler.\n"
)
CANCELLED = "slurmstepd-vm: error: *** JOB 6 ON vm CANCELLED AT 2026-11-25T17:02:02 ***\n"
TIME_LIMIT = "slurmstepd: error: *** JOB 77 ON node12 CANCELLED AT 2026-11-25T18:00:00 DUE TO TIME LIMIT ***\n"


@pytest.mark.parametrize(
    "output, start",
    [
        (MEMORY_KILLED, "killed by SLURM for exceeding its memory"),
        (CGROUP_OOM, "killed by SLURM for exceeding its memory"),
        (TIME_LIMIT, "stopped by SLURM at its time limit"),
        (CANCELLED, "cancelled (scancel)"),
        ("Error in rule events_loadcell:\n    message: None\n", None),  # the job's own failure: its rule log says why
    ],
)
def test_why_slurm_ended_a_job_is_read_from_its_output(output, start):
    reason = slurm_end_reason(output)
    assert (reason is None) if start is None else reason.startswith(start)


#: The rule logs the console names beside the SLURM outputs.
LAB_LOG, IK_LOG = PATHS.log("synthetic_lab", "S02"), PATHS.log("ik", "S01/pert050-1")
CONSOLE = f"""Job 0 has been submitted with SLURM jobid 9 (log: /w/.snakemake/slurm_logs/rule_synthetic_lab/S02/9.log).
[Wed Nov 25 17:06:17 2026]
Error in rule synthetic_lab:
    message: SLURM-job '9' failed, SLURM status is: 'FAILED'.
    log: {LAB_LOG}, /w/.snakemake/slurm_logs/rule_synthetic_lab/S02/9.log \
(check log file(s) for error details)
[Wed Nov 25 16:59:27 2026]
    message: Error in group trial
    log: /w/.snakemake/slurm_logs/group_trial_ik_strides/6.log (check log file(s) for error details)
    jobs:
        rule ik:
            log: {IK_LOG} (check log file(s) for error details)
    Error in rule ik:
        log: {IK_LOG} (check log file(s) for error details)
"""


def test_the_failed_jobs_slurm_outputs_are_found_in_snakemakes_console_once_each():
    assert failed_slurm_logs(CONSOLE) == [
        "/w/.snakemake/slurm_logs/rule_synthetic_lab/S02/9.log",
        "/w/.snakemake/slurm_logs/group_trial_ik_strides/6.log",
    ]
