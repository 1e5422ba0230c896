"""The events stage's load-cell half on its own: a trial's robot log on the mocap frames written to a table, as
:func:`loper_analysis.stages.events.step.events_loadcell` writes it, for the tests that need the forces of a trial
(or the refusal of its records) without its events."""

from __future__ import annotations

import pandas as pd

from loper_analysis.device.loadcell import LoadcellSettings
from loper_analysis.io.atomic import PathLike
from loper_analysis.io.c3d import read_c3d
from loper_analysis.stages.events.step import _loadcell_of, _write_loadcell

__all__ = ["loadcell"]


def loadcell(
    c3d_path: PathLike,
    log_path: PathLike,
    out_tsv: PathLike,
    settings: LoadcellSettings = LoadcellSettings(),
    native_out: PathLike | None = None,
) -> pd.DataFrame:
    """The robot log's forces on the mocap frames, written to ``out_tsv`` (and at the robot rate to ``native_out``
    when given); nothing is written when the records are refused. Returns the frame table."""
    out, native = _loadcell_of(read_c3d(c3d_path), log_path, settings)
    return _write_loadcell(out, native, out_tsv, native_out)
