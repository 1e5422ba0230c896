"""File step of a failed SLURM run: why SLURM ended each failed job, from Snakemake's log and the jobs' outputs."""

from __future__ import annotations

from pathlib import Path

from loper_analysis.cluster import failed_slurm_logs, slurm_end_reason
from loper_analysis.io.atomic import PathLike

__all__ = ["requested_partitions", "slurm_failure_lines"]


def slurm_failure_lines(snakemake_log: PathLike) -> list[str]:
    """One line per failed SLURM job that SLURM itself ended (memory, time limit, cancel, node failure), naming
    the job, the reason and its SLURM output; empty when every failure was the job's own (see its rule log)."""
    log = Path(snakemake_log)
    if not log.is_file():
        return []
    lines = []
    for output in failed_slurm_logs(log.read_text(errors="replace")):
        path = Path(output)
        if not path.is_file():
            continue
        reason = slurm_end_reason(path.read_text(errors="replace"))
        if reason is not None:
            job = (
                "/".join(path.parent.parts[path.parts.index("slurm_logs") + 1 :])
                if "slurm_logs" in path.parts
                else path.parent.name
            )
            lines.append(f"SLURM job {path.stem} ({job}): {reason} (SLURM's output: {path})")
    return lines


def requested_partitions(resource_settings) -> dict[str, str]:
    """The SLURM partitions a run asks for as plain text, by where they were given (``default-resources``,
    ``set-resources {rule}``), from Snakemake's resource settings; a partition given as a function is left out."""

    def plain(resource) -> str | None:
        raw = getattr(resource, "raw", None)
        return raw.strip("'\"") if isinstance(raw, str) else None

    requested = {}
    defaults = resource_settings.default_resources
    if defaults is not None and "slurm_partition" in defaults.keys():
        requested["default-resources"] = plain(defaults.get("slurm_partition"))
    for rule, resources in resource_settings.overwrite_resources.items():
        if "slurm_partition" in resources.keys():
            requested[f"set-resources {rule}"] = plain(resources.get("slurm_partition"))
    return {k: v for k, v in requested.items() if v is not None}
