"""What a stage of the pipeline owns, as one record: its name, its result files and its targets.

A stage's name is the address of everything it owns: its slice
``loper_analysis/stages/<name>/`` (the file step ``step.py`` and the result
files ``files.py``), its rule file ``workflow/rules/<name>.smk`` and its
results folder ``results/<name>/``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

__all__ = ["Stage"]


@dataclass(frozen=True)
class Stage:
    """One stage of the pipeline.

    Attributes
    ----------
    name : str
        The stage's name: its slice, rule file and results folder.
    files : mapping
        Its result files: name -> pattern under ``results/<name>/`` (Snakemake wildcards in braces); empty for a
        stage that writes elsewhere (the synthetic lab writes raw files).
    targets : callable or None
        ``targets(study) -> list of paths``: what a run builds of this stage by default for a
        :class:`~loper_analysis.layout.Study` (None: only what later stages read).
    tables : callable or None
        ``tables(study) -> {heading: path}``: the stage's tables in the Markdown rendering of the run's tables
        (``results/report/tables.md``), in its order (None: none).
    """

    name: str
    files: Mapping[str, str] = field(default_factory=dict)
    targets: Callable[[Any], list[str]] | None = None
    tables: Callable[[Any], dict[str, str]] | None = None

    @property
    def rule_file(self) -> str:
        """The stage's rule file, relative to the project's folder."""
        return f"workflow/rules/{self.name}.smk"
