"""The device stage: device tests: simulated logs, FRF, step responses, summary, figures.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.device.files import FILES, report_tables, targets
from loper_analysis.stages.stage import Stage

STAGE = Stage(name="device", files=FILES, targets=targets, tables=report_tables)

__all__ = ["STAGE"]
