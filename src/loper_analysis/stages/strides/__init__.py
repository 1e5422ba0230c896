"""The strides stage: strides, their outliers and cycles, the stride summary.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.stage import Stage
from loper_analysis.stages.strides.files import FILES, report_tables, targets

STAGE = Stage(name="strides", files=FILES, targets=targets, tables=report_tables)

__all__ = ["STAGE"]
