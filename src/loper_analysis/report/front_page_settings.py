"""The report stage's settings (:class:`FrontPageSettings`): the run's headline settings the front page lists,
composed from the settings types that read them (:mod:`loper_analysis.stages.report.settings`), the calibration
run its truth verdicts rest on and the fingerprint of the run's design."""

from __future__ import annotations

from dataclasses import dataclass, field

from loper_analysis.report.front_page import RunSettings

__all__ = ["FrontPageSettings"]


@dataclass(frozen=True)
class FrontPageSettings:
    """The settings of the front page.

    ``run``: the run's :class:`~loper_analysis.report.front_page.RunSettings` (the workflow's configuration);
    ``calibration``: the calibration table the truth verdicts rest on (``report.calibration``, a path relative to
    the working directory; None: none, the verdicts rest on the run's own counts); ``design_fingerprint``: the
    fingerprint of the run's design (:func:`loper_analysis.report.calibration.design_fingerprint`), compared with
    the calibration's. The fingerprint is left out of the repr the front page rule's params compare: every
    setting it covers decides the fits, so a changed one reruns the fits and the page after them through its
    inputs.
    """

    run: RunSettings
    calibration: str | None = None
    design_fingerprint: str = field(default="", repr=False)
