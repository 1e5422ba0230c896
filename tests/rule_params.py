"""The workflow's rules as Snakemake parses them for a config, and what each rule's jobs would be given: its
params (functions of the wildcards called for a few wildcard sets) and its file patterns. Two configs whose
rules differ here differ in exactly the jobs Snakemake reruns for a changed setting (params trigger) or file."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from snakemake.api import SnakemakeApi
from snakemake.settings.types import ConfigSettings, OutputSettings, Quietness, ResourceSettings, StorageSettings

#: Wildcard sets a rule's param functions are called with (a synthetic subject's trials and a device test).
WILDCARDS = [
    SimpleNamespace(subject="S01", trial=trial, onset="050", chunk="000")
    for trial in ("static", "walk-nodevice", "walk-device", "pert050-1", "device-frf")
]


def _value(value) -> str:
    """A param's value as text; a function of the wildcards called with each set of :data:`WILDCARDS` (an input
    function as Snakemake keeps it, a file object around the function, too)."""
    value = getattr(getattr(value, "_file", None), "callable", None) or value
    if not callable(value):
        return repr(value)
    out = []
    for wildcards in WILDCARDS:
        try:
            out.append(repr(value(wildcards)))
        except Exception as exc:  # a function for other wildcards (a subject's row of a device subject, ...)
            out.append(type(exc).__name__)
    return " | ".join(out)


def rule_signatures(work: Path, config: dict) -> dict[str, str]:
    """Rule -> the text of its params and file patterns, for the workflow in ``work`` with ``config`` over its
    config files (as ``--config``)."""
    with SnakemakeApi(OutputSettings(quiet={Quietness.ALL})) as api:
        workflow_api = api.workflow(
            resource_settings=ResourceSettings(cores=1),
            config_settings=ConfigSettings(config=config),
            storage_settings=StorageSettings(),
            snakefile=work / "Snakefile",
            workdir=work,
        )
        workflow = workflow_api._workflow
        return {
            rule.name: "\n".join(
                [f"{k}={_value(v)}" for k, v in rule.params.items()]
                + [f"input {_value(f)}" for f in rule.input]
                + [f"output {f}" for f in rule.output]
            )
            for rule in workflow.rules
        }
