"""File steps of the impedance analysis: the fit per subject and onset, the aggregate tables, the figures.

:func:`subject_fits` reads the files of a :class:`FitFiles` bundle (per trial a
:class:`TrialFiles`, the outputs a :class:`FitOutputs`) with the settings :class:`FitSettings`
(from the config by :mod:`loper_analysis.stages.impedance.settings`).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.impedance import IdentificationSettings
from loper_analysis.impedance.responses import ResponseSettings
from loper_analysis.io.atomic import PathLike, write_figure, write_tsv
from loper_analysis.io.readers import read_tsv
from loper_analysis.io.truth import read_truth
from loper_analysis.stages.impedance.files import FitFiles
from loper_analysis.swing_leg.rods import ShankRod

__all__ = [
    "FitSettings",
    "subject_fits",
    "impedance_table",
    "impedance_summary",
    "subject_figures",
    "impedance_figure",
]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class FitSettings:
    """How a subject's responses are windowed and averaged and its impedance fitted and judged.

    ``response``: :class:`~loper_analysis.impedance.responses.ResponseSettings` (fit window and initial-state span in s,
    the IQR rule, the fewest kept pairs); ``identification``:
    :class:`~loper_analysis.impedance.identification.impedance.IdentificationSettings` (noise model, starts, bounds in
    N·m/rad and N·m·s/rad, judgement, seed); ``shank_rod``: where a second rod just above the ankle pushes
    (:class:`~loper_analysis.swing_leg.rods.ShankRod`), used for trials whose force tables hold its load cell.
    """

    response: ResponseSettings = field(default_factory=ResponseSettings)
    identification: IdentificationSettings = field(default_factory=IdentificationSettings)
    shank_rod: ShankRod = field(default_factory=ShankRod)


class _Tables:
    """TSV tables read once per path (the null pairs reuse the onset's own trials)."""

    def __init__(self):
        self._frames: dict[str, pd.DataFrame] = {}

    def __call__(self, path: PathLike, what: str) -> pd.DataFrame:
        key = str(path)
        if key not in self._frames:
            self._frames[key] = read_tsv(path, what)
        return self._frames[key]


def _fit(subject: str, onset_ms: int, files: FitFiles, settings: FitSettings, tables: _Tables) -> pd.DataFrame:
    """Responses and the impedance fit of one subject at one onset
    (:func:`loper_analysis.impedance.identification.impedance.fit_onset`), the subject's tables read through
    ``tables`` (shared by its onsets).

    ``files`` (:class:`FitFiles`): the onset's trials, the null-pair trials, the segment table, the truth and
    the outputs; ``settings`` (:class:`FitSettings`): the response and identification settings. Writes the
    mean response, the stride counts, the fit rows, the fit curves and, when ``files.outputs`` names them, the
    mean forces the model saw and the inter-joint couplings' rows; returns the rows.
    """
    from loper_analysis.impedance.identification.impedance import fit_onset
    from loper_analysis.io.opensim_tables import read_markers
    from loper_analysis.io.segment_table import read_segments

    truth = None
    if files.truth:
        truth = read_truth(files.truth).get(int(onset_ms))
    inputs = []
    for name, trial in files.trials.items():
        angle_table = tables(trial.angles, "angle table")
        t, X, labels = read_markers(trial.markers)
        if len(t) != len(angle_table) or not np.allclose(t, angle_table["time_s"].to_numpy(), atol=1e-6):
            raise LoperInputError(f"{trial.markers}: frames differ from {trial.angles}")
        inputs.append(
            {
                "name": name,
                "angles": angle_table,
                "strides": tables(trial.strides, "stride table"),
                "force": tables(trial.force, "force table"),
                "markers": (t, X, labels),
                "force_native": None
                if trial.force_native is None
                else read_tsv(trial.force_native, "robot-rate force table", ("time_s", "force_measured_n")),
            }
        )
    null = [
        {"name": name, "angles": tables(trial.angles, "angle table"), "strides": tables(trial.strides, "stride table")}
        for name, trial in files.null_trials.items()
    ]
    params = read_segments(files.segments) if inputs else None
    result = fit_onset(
        inputs,
        params,
        int(onset_ms),
        subject,
        truth,
        null,
        settings.response,
        settings.identification,
        shank_rod=settings.shank_rod,
    )
    out = files.outputs
    write_tsv(result.response, out.response)
    write_tsv(result.counts, out.counts)
    write_tsv(result.rows, out.fit)
    write_tsv(result.curves, out.curves)
    if out.force is not None:
        write_tsv(result.force, out.force)
    if out.couplings is not None:
        write_tsv(result.couplings, out.couplings)
    log.info("impedance:\n%s", result.rows.to_string(index=False))
    return result.rows


def subject_fits(subject: str, fits: Mapping[int, FitFiles], settings: FitSettings = FitSettings()) -> pd.DataFrame:
    """Responses and the impedance fit of one subject at every onset in one process, each table read once.

    ``fits`` maps each onset (ms after toe-off) to its :class:`FitFiles` (the onset's trials, the null-pair
    trials, the segment table, the truth and the outputs); the onsets are fitted in its order. Writes per onset
    the mean response, the stride counts, the fit rows, the fit curves and (when ``outputs.force`` is given)
    the mean forces the model saw. Returns every onset's fit rows.
    """
    tables = _Tables()
    rows = [_fit(subject, int(onset), files, settings, tables) for onset, files in fits.items()]
    return pd.concat(rows, ignore_index=True)


def impedance_table(fit_tsvs: Sequence[PathLike], out_tsv: PathLike) -> pd.DataFrame:
    """The fit rows of every subject and onset in one table (``results/impedance/impedance.tsv``; the couplings'
    rows likewise in ``results/impedance/couplings.tsv``)."""
    table = pd.concat([read_tsv(f, "impedance rows") for f in fit_tsvs], ignore_index=True)
    write_tsv(table, out_tsv)
    log.info("%d rows, status counts:\n%s", len(table), table.status.value_counts().to_string())
    return table


def impedance_summary(
    impedance_tsv: PathLike,
    summary_out: PathLike,
    literature_out: PathLike,
    upper_bounds: tuple[float, float] | None = None,
    lower_bounds: tuple[float, float] = (0.0, 0.0),
) -> pd.DataFrame:
    """Across-subject summary per joint and onset and the literature table with our row.

    ``upper_bounds`` (K, D): rows with an estimate on its upper bound are left out of the summary;
    ``lower_bounds`` (K, D): where the across-subject intervals are cut (N·m/rad, N·m·s/rad).
    """
    from loper_analysis.impedance.identification.across_subjects import impedance_summary as summarise
    from loper_analysis.impedance.identification.across_subjects import literature_table

    summary = summarise(
        read_tsv(impedance_tsv, "impedance table"), upper_bounds=upper_bounds, lower_bounds=lower_bounds
    )
    write_tsv(summary, summary_out)
    write_tsv(literature_table(summary), literature_out)
    log.info("summary:\n%s", summary.to_string(index=False))
    return summary


def subject_figures(
    onsets_ms: Sequence[int],
    response_tsvs: Sequence[PathLike],
    curve_tsvs: Sequence[PathLike],
    subject: str,
    responses_out: PathLike,
    fit_out: PathLike,
) -> pd.DataFrame:
    """A subject's responses figure and fit figure over the onsets; returns the peak responses (rad)."""
    from loper_analysis.report.figures.impedance import fit_figure, response_peaks, responses_figure

    onsets = [int(o) for o in onsets_ms]
    responses = {o: read_tsv(p, "response table") for o, p in zip(onsets, response_tsvs, strict=True)}
    curves = {o: read_tsv(p, "fit-curve table") for o, p in zip(onsets, curve_tsvs, strict=True)}
    response_sources = dict(zip(onsets, map(str, response_tsvs)))
    curve_sources = dict(zip(onsets, map(str, curve_tsvs)))
    peaks = response_peaks(responses, response_sources)
    write_figure(responses_figure(responses, f"{subject}: perturbed vs unperturbed", response_sources), responses_out)
    write_figure(fit_figure(curves, f"{subject}: model fit vs data", curve_sources), fit_out)
    log.info("peak |response| (rad):\n%s", peaks.to_string())
    return peaks


def impedance_figure(impedance_tsv: PathLike, out_png: PathLike) -> pd.DataFrame:
    """The study's figure of K and D per onset; returns the across-subject means."""
    from loper_analysis.report.figures.impedance import impedance_figure as draw
    from loper_analysis.report.figures.impedance import impedance_means

    table = read_tsv(impedance_tsv, "impedance table")
    mean = impedance_means(table, str(impedance_tsv))
    write_figure(draw(table, str(impedance_tsv)), out_png)
    log.info("across-subject mean:\n%s", mean.to_string())
    return mean
