"""The dynamics stage: hip, knee and ankle moments and powers from the force platforms (inverse dynamics).

``step`` is its file step, ``files`` its result files and targets, ``settings`` its reader.
"""

from loper_analysis.stages.dynamics.files import FILES, report_tables, targets
from loper_analysis.stages.stage import Stage

STAGE = Stage(name="dynamics", files=FILES, targets=targets, tables=report_tables)

__all__ = ["STAGE"]
