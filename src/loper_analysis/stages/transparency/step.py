"""File step of the transparency analysis: RMSD vs ISV_ave, interaction force, and the study's figure.

:func:`transparency` reads each subject's :class:`TransparencyFiles` with the settings
:class:`loper_analysis.transparency.TransparencySettings` (from the config by
:mod:`loper_analysis.stages.transparency.settings`).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping

from loper_analysis.io.atomic import PathLike, write_figure, write_tsv
from loper_analysis.io.readers import read_tsv
from loper_analysis.stages.transparency.files import TransparencyFiles
from loper_analysis.transparency import TransparencySettings

__all__ = ["transparency"]

log = logging.getLogger(__name__)


def transparency(
    files: Mapping[str, TransparencyFiles],
    rmsd_out: PathLike,
    force_out: PathLike,
    figure_out: PathLike,
    settings: TransparencySettings = TransparencySettings(),
):
    """Transparency of the device from the stride and cycle tables of each subject's two walking trials.

    ``files`` maps each subject to its tables (:class:`TransparencyFiles`; the rows follow its order);
    ``settings`` (:class:`TransparencySettings`): the leg and the fewest kept strides. Writes the tables of
    :func:`loper_analysis.transparency.transparency_results` and the figure (kept strides of all subjects
    pooled); returns the results. A subject with fewer than ``settings.min_strides`` kept strides in either
    trial is left out of the comparison (its rows keep the counts, with empty metrics).
    """
    from loper_analysis.report.figures.transparency import transparency_figure
    from loper_analysis.transparency import transparency_results

    frames = {
        subject: {
            "no_device": (read_tsv(f.no_device_strides, "stride table"), read_tsv(f.no_device_cycles, "cycle table")),
            "device": (read_tsv(f.device_strides, "stride table"), read_tsv(f.device_cycles, "cycle table")),
        }
        for subject, f in files.items()
    }
    results = transparency_results(frames, settings.side, settings.min_strides)
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
