"""File steps of the validation study: one chunk of the K/D combinations, the gathered tables, the figure."""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import TYPE_CHECKING

import pandas as pd

from loper_analysis.io.atomic import PathLike, write_figure, write_tsv
from loper_analysis.io.readers import read_tsv

if TYPE_CHECKING:  # the identification package is imported by the chunk step only
    from loper_analysis.impedance.identification.validation import ValidationSettings

__all__ = [
    "VALIDATION_FLOAT_FORMAT",
    "validation_chunk",
    "validation_figure",
    "validation_segments",
    "validation_tables",
]

log = logging.getLogger(__name__)

#: Significant digits of the validation tables: errors of 1e-5 N·m/rad on values up to 150 need them.
VALIDATION_FLOAT_FORMAT = "%.15g"


def validation_segments(out_tsv: PathLike, height_m: float, mass_kg: float, attachment_fraction: float) -> None:
    """The validation study's subject: the segment table from height (m) and mass (kg) with Winter's table
    (:func:`loper_analysis.swing_leg.dynamics.segment_parameters_from_anthropometry`)."""
    from loper_analysis.io.segment_table import write_segments
    from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry

    params = segment_parameters_from_anthropometry(height_m, mass_kg, attachment_fraction)
    write_segments(params, out_tsv)
    log.info("segment table for %s m, %s kg: %s", height_m, mass_kg, params)


def validation_chunk(
    segments_tsv: PathLike,
    settings: ValidationSettings,
    chunk: int,
    n_chunks: int,
    errors_out: PathLike,
    fits_out: PathLike,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Simulate and identify chunk ``chunk`` of ``n_chunks`` of the combinations (``settings``: the study's
    :class:`~loper_analysis.impedance.identification.validation.ValidationSettings`); write its two tables."""
    from loper_analysis.impedance.identification.validation import (
        chunk_combinations,
        impedance_grid,
        run_validation_chunk,
    )
    from loper_analysis.io.segment_table import read_segments

    study = settings
    log.info("chunk %d of %d with %s", chunk, n_chunks, study)
    grid = impedance_grid(study.stiffness_levels_nm_per_rad, study.damping_levels_nms_per_rad)
    errors, fits = run_validation_chunk(
        read_segments(segments_tsv), study, chunk_combinations(len(grid), n_chunks, chunk)
    )
    write_tsv(errors, errors_out, VALIDATION_FLOAT_FORMAT)
    write_tsv(fits, fits_out, VALIDATION_FLOAT_FORMAT)
    return errors, fits


def validation_tables(
    error_tsvs: Sequence[PathLike],
    fit_tsvs: Sequence[PathLike],
    errors_out: PathLike,
    fits_out: PathLike,
    summary_out: PathLike,
) -> pd.DataFrame:
    """Gather the chunks' tables and write them with the summary beside the study's values; returns the summary."""
    from loper_analysis.impedance.identification.validation import gather_validation_tables

    errors, fits, summary = gather_validation_tables(
        [read_tsv(p, "error table") for p in error_tsvs], [read_tsv(p, "fit table") for p in fit_tsvs]
    )
    write_tsv(errors, errors_out, VALIDATION_FLOAT_FORMAT)
    write_tsv(fits, fits_out, VALIDATION_FLOAT_FORMAT)
    write_tsv(summary, summary_out, VALIDATION_FLOAT_FORMAT)
    log.info("summary:\n%s", summary.to_string())
    return summary


def validation_figure(errors_tsv: PathLike, out_png: PathLike) -> None:
    """Box plots of the estimation errors per parameter and condition."""
    from loper_analysis.report.figures.validation import validation_errors_figure

    write_figure(validation_errors_figure(read_tsv(errors_tsv, "error table")), out_png)
    log.info("wrote %s", out_png)
