"""File step of the transparency analysis: RMSD vs ISV_ave, interaction force, and the study's figure."""

from __future__ import annotations

import logging
from collections.abc import Sequence

from loper_analysis.gait.outliers import MIN_VALID_STRIDES
from loper_analysis.io.atomic import PathLike, write_figure, write_tsv
from loper_analysis.io.readers import read_tsv

__all__ = ["transparency"]

log = logging.getLogger(__name__)


def transparency(
    subjects: Sequence[str],
    no_device_strides: Sequence[PathLike],
    no_device_cycles: Sequence[PathLike],
    device_strides: Sequence[PathLike],
    device_cycles: Sequence[PathLike],
    rmsd_out: PathLike,
    force_out: PathLike,
    figure_out: PathLike,
    side: str = "left",
    min_strides: int = MIN_VALID_STRIDES,
):
    """Transparency of the device from the stride and cycle tables of each subject's two walking trials.

    The four lists hold one file per subject, in the order of ``subjects``:
    the stride and cycle tables of walking without and with the device.
    Writes the tables of :func:`loper_analysis.transparency.transparency_results`
    and the figure (kept strides of all subjects pooled); returns the results.
    A subject with fewer than ``min_strides`` kept strides in either trial is
    left out of the comparison (its rows keep the counts, with empty metrics).
    """
    from loper_analysis.report.figures.transparency import transparency_figure
    from loper_analysis.transparency import transparency_results

    files = zip(subjects, no_device_strides, no_device_cycles, device_strides, device_cycles, strict=True)
    frames = {
        subject: {
            "no_device": (read_tsv(ns, "stride table"), read_tsv(nc, "cycle table")),
            "device": (read_tsv(ds, "stride table"), read_tsv(dc, "cycle table")),
        }
        for subject, ns, nc, ds, dc in files
    }
    results = transparency_results(frames, side, min_strides)
    write_tsv(results.rmsd, rmsd_out)
    write_tsv(results.force, force_out)
    write_figure(
        transparency_figure(
            results.angles_rad,
            results.force_n,
            results.toe_off_pct,
            title=f"Transparency: {len(frames)} subject(s), kept strides pooled",
        ),
        figure_out,
    )
    log.info("transparency:\n%s", results.rmsd.to_string())
    return results
