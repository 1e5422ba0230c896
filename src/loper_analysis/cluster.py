"""SLURM runs: the checks made before anything is submitted, and why a SLURM job ended, in words.

Without the checks a run through the SLURM profile reports a missing ``sbatch`` or a misspelt partition only
after its first status check, inside a long sbatch command line. Without the explanation a job that SLURM
killed for memory or time shows as ``FAILED`` or as a failed group, the reason only in its SLURM log.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from collections.abc import Collection, Mapping

from loper_analysis.errors import LoperInputError

__all__ = [
    "available_partitions",
    "check_slurm_submission",
    "failed_slurm_logs",
    "slurm_end_reason",
    "submission_problems",
]

#: What slurmstepd writes into a job's output when SLURM ends it, first match wins -> the reason in words.
_SLURM_ENDS = (
    (
        re.compile(r"exceeded (job )?memory limit|oom[-_ ]kill|out of memory", re.I),
        "killed by SLURM for exceeding its memory: raise the rule's mem_mb under set-resources in the profile",
    ),
    (
        re.compile(r"DUE TO TIME LIMIT"),
        "stopped by SLURM at its time limit: raise the rule's runtime (minutes) under set-resources in the profile",
    ),
    (re.compile(r"DUE TO NODE FAIL"), "ended by a node failure: run the same command again"),
    (re.compile(r"DUE TO PREEMPTION"), "preempted by another job: run the same command again"),
    (re.compile(r"\*\*\* JOB \d+ ON \S+ CANCELLED"), "cancelled (scancel): run the same command again to finish"),
)


def submission_problems(
    requested: Mapping[str, str], available: Collection[str] | None, sbatch: str | None
) -> list[str]:
    """What stops a SLURM submission, one sentence per problem; empty when nothing does.

    Parameters
    ----------
    requested : mapping
        Where each partition is asked for (e.g. ``"default-resources"``, ``"set-resources ik"``) -> partition.
    available : collection of str or None
        The cluster's partitions (``sinfo``); None when they could not be listed (then not checked).
    sbatch : str or None
        Path of ``sbatch`` on PATH, None when it is missing.
    """
    problems = []
    if sbatch is None:
        problems.append(
            "the SLURM profile submits jobs with sbatch, which is not on PATH: run snakemake on a "
            "node that submits jobs (the login node), or load SLURM first (e.g. `module load slurm`)"
        )
    if available is not None:
        known = sorted(set(available))
        for origin, partition in requested.items():
            if partition not in known:
                problems.append(
                    f"{origin}: slurm_partition '{partition}' is not a partition of this cluster "
                    f"(sinfo lists: {', '.join(known) or 'none'})"
                )
    return problems


def available_partitions() -> list[str] | None:
    """The cluster's partition names from ``sinfo`` (the default partition's ``*`` removed); None without sinfo."""
    sinfo = shutil.which("sinfo")
    if sinfo is None:
        return None
    done = subprocess.run([sinfo, "--noheader", "--format=%P"], capture_output=True, text=True, timeout=60)
    if done.returncode != 0:
        raise LoperInputError(f"sinfo failed (exit {done.returncode}): {' '.join(done.stderr.split())}")
    return [line.strip().rstrip("*") for line in done.stdout.splitlines() if line.strip()]


def check_slurm_submission(requested: Mapping[str, str]) -> None:
    """Raise :class:`LoperInputError` naming every problem of :func:`submission_problems` on this machine."""
    sbatch = shutil.which("sbatch")
    problems = submission_problems(requested, available_partitions() if sbatch else None, sbatch)
    if problems:
        raise LoperInputError("cannot submit to SLURM: " + "; ".join(problems))


def slurm_end_reason(slurm_output: str) -> str | None:
    """Why SLURM ended a job, from the job's SLURM output (``.snakemake/slurm_logs/…/{jobid}.log``); None when
    SLURM did not end it (the job itself failed: its rule's log says why)."""
    for pattern, reason in _SLURM_ENDS:
        if pattern.search(slurm_output):
            return reason
    return None


def failed_slurm_logs(console: str) -> list[str]:
    """The SLURM output files of the failed jobs in Snakemake's console text, in order, each once."""
    found: list[str] = []
    for line in console.splitlines():
        match = re.match(r"\s+log: (.*)$", line)
        if match is None:
            continue
        for item in match.group(1).split(" (check log file")[0].split(", "):
            item = item.strip()
            if "/slurm_logs/" in item and item.endswith(".log") and item not in found:
                found.append(item)
    return found
