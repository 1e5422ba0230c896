"""File steps of the impedance analysis: the fit per subject and onset, the aggregate tables, the figures."""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike, write_figure, write_tsv
from loper_analysis.io.readers import read_tsv
from loper_analysis.io.truth import read_truth

__all__ = ["fit", "subject_fits", "impedance_table", "impedance_summary", "subject_figures", "impedance_figure"]

log = logging.getLogger(__name__)


class _Tables:
    """TSV tables read once per path (the null pairs reuse the onset's own trials)."""

    def __init__(self):
        self._frames: dict[str, pd.DataFrame] = {}

    def __call__(self, path: PathLike, what: str) -> pd.DataFrame:
        key = str(path)
        if key not in self._frames:
            self._frames[key] = read_tsv(path, what)
        return self._frames[key]


def fit(
    trials: Sequence[str],
    angles: Sequence[PathLike],
    strides: Sequence[PathLike],
    force: Sequence[PathLike],
    markers: Sequence[PathLike],
    segments_tsv: PathLike,
    onset_ms: int,
    subject: str,
    response_out: PathLike,
    counts_out: PathLike,
    fit_out: PathLike,
    curves_out: PathLike,
    truth_yaml: PathLike | None = None,
    null_trials: Sequence[str] = (),
    null_angles: Sequence[PathLike] = (),
    null_strides: Sequence[PathLike] = (),
    response: Mapping | None = None,
    identification: Mapping | None = None,
    force_native: Sequence[PathLike] = (),
    force_out: PathLike | None = None,
) -> pd.DataFrame:
    """Responses and the impedance fit of one subject at one onset
    (:func:`loper_analysis.identification.impedance.fit_onset`).

    ``trials`` names the onset's trials; ``angles``, ``strides``, ``force``
    (TSV tables of the processing steps) and ``markers`` (TRC, for the brace
    markers) give their files in the same order. ``null_trials`` with
    ``null_angles`` and ``null_strides``: the trials whose unperturbed strides
    are the null pairs. ``force_native``: the load cell at the robot rate per
    trial (``{trial}.force_native.tsv``, same order), from which the fit takes
    its force; ``force_out`` gets the mean forces the model saw. ``response`` and ``identification`` are the keyword
    arguments of :class:`~loper_analysis.responses.ResponseSettings` and
    :class:`~loper_analysis.identification.impedance.IdentificationSettings`. Writes the
    mean response, the stride counts, the fit rows and the fit curves; returns the rows.
    """
    return _fit(
        trials,
        angles,
        strides,
        force,
        markers,
        segments_tsv,
        onset_ms,
        subject,
        response_out,
        counts_out,
        fit_out,
        curves_out,
        truth_yaml,
        null_trials,
        null_angles,
        null_strides,
        response,
        identification,
        force_native,
        force_out,
        _Tables(),
    )


def _fit(
    trials,
    angles,
    strides,
    force,
    markers,
    segments_tsv,
    onset_ms,
    subject,
    response_out,
    counts_out,
    fit_out,
    curves_out,
    truth_yaml,
    null_trials,
    null_angles,
    null_strides,
    response,
    identification,
    force_native,
    force_out,
    tables: _Tables,
) -> pd.DataFrame:
    """:func:`fit` with the subject's tables read through ``tables`` (shared by its onsets)."""
    from loper_analysis.identification.impedance import IdentificationSettings, fit_onset
    from loper_analysis.io.opensim_tables import read_markers
    from loper_analysis.responses import ResponseSettings
    from loper_analysis.swing_leg.dynamics import read_segments

    ident = IdentificationSettings(**(identification or {}))
    settings = ResponseSettings(**(response or {}))
    truth = None
    if truth_yaml:
        truth = read_truth(truth_yaml).get(int(onset_ms))
    inputs = []
    natives = list(force_native) if len(force_native) else [None] * len(trials)
    for name, a, s, f, m, fn in zip(trials, angles, strides, force, markers, natives, strict=True):
        angle_table = tables(a, "angle table")
        t, X, labels = read_markers(m)
        if len(t) != len(angle_table) or not np.allclose(t, angle_table["time_s"].to_numpy(), atol=1e-6):
            raise LoperInputError(f"{m}: frames differ from {a}")
        inputs.append(
            {
                "name": name,
                "angles": angle_table,
                "strides": tables(s, "stride table"),
                "force": tables(f, "force table"),
                "markers": (t, X, labels),
                "force_native": None
                if fn is None
                else read_tsv(fn, "robot-rate force table", ("time_s", "force_measured_n")),
            }
        )
    null = [
        {"name": name, "angles": tables(a, "angle table"), "strides": tables(s, "stride table")}
        for name, a, s in zip(null_trials, null_angles, null_strides, strict=True)
    ]
    params = read_segments(segments_tsv) if inputs else None
    result = fit_onset(inputs, params, int(onset_ms), subject, truth, null, settings, ident)
    write_tsv(result.response, response_out)
    write_tsv(result.counts, counts_out)
    write_tsv(result.rows, fit_out)
    write_tsv(result.curves, curves_out)
    if force_out is not None:
        write_tsv(result.force, force_out)
    log.info("impedance:\n%s", result.rows.to_string(index=False))
    return result.rows


def subject_fits(
    onsets_ms: Sequence[int],
    trials: Mapping[str, Sequence[str]],
    null_trials: Mapping[str, Sequence[str]],
    angles: Mapping[str, PathLike],
    strides: Mapping[str, PathLike],
    force: Mapping[str, PathLike],
    force_native: Mapping[str, PathLike],
    markers: Mapping[str, PathLike],
    segments_tsv: PathLike,
    subject: str,
    response_outs: Sequence[PathLike],
    counts_outs: Sequence[PathLike],
    fit_outs: Sequence[PathLike],
    curves_outs: Sequence[PathLike],
    force_outs: Sequence[PathLike],
    truth_yaml: PathLike | None = None,
    response: Mapping | None = None,
    identification: Mapping | None = None,
) -> pd.DataFrame:
    """:func:`fit` of one subject at every onset in one process, each table read once.

    ``trials`` and ``null_trials`` map each onset (``"050"``, in the order of
    ``onsets_ms``) to its own trials and its null-pair trials; ``angles``,
    ``strides``, ``force``, ``force_native`` and ``markers`` map trial names
    to their files. The outputs are per onset, in the order of ``onsets_ms``.
    Returns every onset's fit rows.
    """
    tables = _Tables()
    rows = []
    for i, onset in enumerate(onsets_ms):
        key = f"{int(onset):03d}"
        own, null = list(trials[key]), list(null_trials[key])
        rows.append(
            _fit(
                own,
                [angles[t] for t in own],
                [strides[t] for t in own],
                [force[t] for t in own],
                [markers[t] for t in own],
                segments_tsv,
                int(onset),
                subject,
                response_outs[i],
                counts_outs[i],
                fit_outs[i],
                curves_outs[i],
                truth_yaml,
                null,
                [angles[t] for t in null],
                [strides[t] for t in null],
                response,
                identification,
                [force_native[t] for t in own],
                force_outs[i],
                tables,
            )
        )
    return pd.concat(rows, ignore_index=True)


def impedance_table(fit_tsvs: Sequence[PathLike], out_tsv: PathLike) -> pd.DataFrame:
    """The fit rows of every subject and onset in one table (``results/tables/impedance.tsv``)."""
    table = pd.concat([read_tsv(f, "impedance rows") for f in fit_tsvs], ignore_index=True)
    write_tsv(table, out_tsv)
    log.info("%d rows, status counts:\n%s", len(table), table.status.value_counts().to_string())
    return table


def impedance_summary(
    impedance_tsv: PathLike,
    summary_out: PathLike,
    literature_out: PathLike,
    upper_bounds: tuple[float, float] | None = None,
) -> pd.DataFrame:
    """Across-subject summary per joint and onset and the literature table with our row.

    ``upper_bounds`` (K, D): rows with an estimate on its upper bound are left out of the summary.
    """
    from loper_analysis.identification.impedance import impedance_summary as summarise
    from loper_analysis.identification.impedance import literature_table

    summary = summarise(read_tsv(impedance_tsv, "impedance table"), upper_bounds=upper_bounds)
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
