"""File step of the experiment planner: a pilot subject's tables in, the predicted precision table out.

:func:`plan` reads the pilot's joint-angle and stride tables (the trials with
the device, whose unperturbed strides give the null pairs and whose perturbed
strides at an onset give that onset's perturbed pairs), its segment table
(or another subject's) and its impedance rows (the planned impedance): a
:class:`PilotFiles` bundle. It writes the table of
:func:`loper_analysis.planning.precision.precision_table` for every onset and
the answers to the targets (method: ``docs/planning.md``; with the conditional
counterfactual, counts the pilot holds at least twice at an onset are planned
from its stretches of that size,
:func:`loper_analysis.planning.covariance.stretch_covariances`), with the settings
:class:`PlanningSettings`, which the rule ``planning`` and ``loper-analysis
plan`` both build with :mod:`loper_analysis.stages.planning.settings`.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence

import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike, write_text, write_tsv
from loper_analysis.io.readers import read_tsv
from loper_analysis.planning.pilot_plan import STRIDES, PlanningSettings, check_plan_request, pilot_plan
from loper_analysis.stages.planning.files import PilotFiles

__all__ = ["STRIDES", "PlanningSettings", "plan"]

log = logging.getLogger(__name__)


def plan(
    files: PilotFiles,
    subject: str,
    settings: PlanningSettings,
    out_tsv: PathLike | None = None,
    answers_out: PathLike | None = None,
    *,
    impedance: Mapping[int, Sequence[float]] | Sequence[float] | None = None,
    unplannable: str = "raise",
    pool_scatter: bool = True,
) -> tuple[pd.DataFrame, list[str]]:
    """Predicted SD and 95 % CI half-width of K and D for a planned experiment, from a pilot subject's files.

    Parameters
    ----------
    files
        The pilot's trials with the device, the segment table of the subject to plan for and the impedance
        rows of the planned impedance (:class:`PilotFiles`).
    subject
        The pilot's ID (rows of the impedance tables, messages).
    settings
        Onsets, stride counts, targets, pulse, identification, response and device settings
        (:class:`~loper_analysis.planning.pilot_plan.PlanningSettings`).
    out_tsv, answers_out
        The table (:data:`loper_analysis.planning.precision.PLAN_COLUMNS`) and the text answers; None writes
        nothing.
    impedance, unplannable, pool_scatter
        As :func:`loper_analysis.planning.pilot_plan.pilot_plan` (``impedance`` instead of the rows of
        ``files.impedance``; the workflow notes an onset that cannot be planned instead of stopping).

    Returns
    -------
    (pandas.DataFrame, list of str)
        The table and the answers.
    """
    from loper_analysis.io.segment_table import read_segments

    check_plan_request(settings, unplannable)  # before any file is read
    if not files.trials:
        raise LoperInputError(f"pilot {subject}: no trial walked with the device: the null pairs need one")
    params = read_segments(files.segments)
    pool = [
        {"name": name, "angles": read_tsv(t.angles, "angle table"), "strides": read_tsv(t.strides, "stride table")}
        for name, t in files.trials.items()
    ]
    rows = None
    if impedance is None:
        if not files.impedance:
            raise LoperInputError("planned impedance: give the pilot's impedance rows or the values")
        rows = pd.concat([read_tsv(f, "impedance rows") for f in files.impedance], ignore_index=True)
    table, answers = pilot_plan(
        pool,
        params,
        settings,
        subject,
        impedance_rows=rows,
        impedance=impedance,
        source=", ".join(map(str, files.impedance)),
        unplannable=unplannable,
        pool_scatter=pool_scatter,
    )
    if out_tsv is not None:
        write_tsv(table, out_tsv)
    if answers_out is not None:
        write_text(answers_out, "".join(a + "\n" for a in answers), "planning answers")
    for a in answers:
        log.info("%s", a)
    return table, answers
