"""File step of the transparency analysis: RMSD vs ISV_ave, interaction force, and the study's figure."""

from __future__ import annotations

import logging
from collections.abc import Mapping

from ..io.atomic import PathLike, write_figure, write_tsv
from ..io.readers import read_tsv

__all__ = ["transparency"]

log = logging.getLogger(__name__)


def transparency(trials: Mapping[str, Mapping[str, tuple[PathLike, PathLike]]], rmsd_out: PathLike,
                 force_out: PathLike, figure_out: PathLike, side: str = "left"):
    """Transparency of the device from the stride and cycle tables of each subject's two walking trials.

    ``trials``: ``{subject: {"no_device": (strides_tsv, cycles_tsv), "device": (strides_tsv, cycles_tsv)}}``.
    Writes the tables of :func:`loper_analysis.transparency.transparency_results`
    and the figure (kept strides of all subjects pooled); returns the results.
    """
    from ..figures.transparency import transparency_figure
    from ..transparency import transparency_results

    frames = {
        subject: {cond: (read_tsv(strides, "stride table"), read_tsv(cycles, "cycle table"))
                  for cond, (strides, cycles) in conds.items()}
        for subject, conds in trials.items()
    }
    results = transparency_results(frames, side)
    write_tsv(results.rmsd, rmsd_out)
    write_tsv(results.force, force_out)
    write_figure(transparency_figure(results.angles_rad, results.force_n, results.toe_off_pct,
                                     title=f"Transparency: {len(trials)} subject(s), kept strides pooled"), figure_out)
    log.info("transparency:\n%s", results.rmsd.to_string())
    return results
