"""The segment table of the swing-leg model (``results/model/{subject}/segments.tsv``): TSV, 10 significant digits.

One row per segment (cart, thigh, shank, foot), the columns of
:meth:`loper_analysis.swing_leg.dynamics.SegmentParameters.to_frame`; :func:`read_segments` and
:func:`write_segments` read and write it as :class:`~loper_analysis.swing_leg.dynamics.SegmentParameters`.
"""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd

from loper_analysis.io.atomic import write_tsv
from loper_analysis.io.readers import read_tsv

__all__ = ["SEGMENT_FLOAT_FORMAT", "read_segment_table", "read_segments", "write_segment_table", "write_segments"]

#: Significant digits of the segment table.
SEGMENT_FLOAT_FORMAT = "%.10g"


def write_segment_table(table: pd.DataFrame, path: str | os.PathLike) -> Path:
    """Write a segment table as TSV atomically, floats by :data:`SEGMENT_FLOAT_FORMAT`."""
    return write_tsv(table, path, SEGMENT_FLOAT_FORMAT)


def read_segment_table(path: str | os.PathLike) -> pd.DataFrame:
    """The rows of a segment table file (LoperInputError naming the file when missing or unreadable)."""
    return read_tsv(path, "segment table")


def write_segments(params, path: str | os.PathLike) -> Path:
    """Write segment parameters (:class:`~loper_analysis.swing_leg.dynamics.SegmentParameters`) as the segment
    table (:meth:`~loper_analysis.swing_leg.dynamics.SegmentParameters.to_frame`)."""
    return write_segment_table(params.to_frame(), path)


def read_segments(path: str | os.PathLike):
    """The segment parameters of a table written by :func:`write_segments`
    (:class:`~loper_analysis.swing_leg.dynamics.SegmentParameters`)."""
    from loper_analysis.swing_leg.dynamics import SegmentParameters

    return SegmentParameters.from_frame(read_segment_table(path), source=str(path))
