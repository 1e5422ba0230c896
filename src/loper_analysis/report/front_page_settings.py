"""The report stage's settings (:class:`FrontPageSettings`): the run's headline settings the front page lists,
composed from the settings types that read them (:mod:`loper_analysis.stages.report.settings`)."""

from __future__ import annotations

from dataclasses import dataclass

from loper_analysis.report.front_page import RunSettings

__all__ = ["FrontPageSettings"]


@dataclass(frozen=True)
class FrontPageSettings:
    """The settings the front page lists: ``run``, the run's
    :class:`~loper_analysis.report.front_page.RunSettings` (the workflow's configuration)."""

    run: RunSettings
