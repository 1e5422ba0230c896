"""The transparency stage: the device's transparency: RMSD against within-subject variability.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.stage import Stage
from loper_analysis.stages.transparency.files import FILES, report_tables, targets

STAGE = Stage(name="transparency", files=FILES, targets=targets, tables=report_tables)

__all__ = ["STAGE"]
