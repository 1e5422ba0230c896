"""The validation stage: the validation study of the identification.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.stage import Stage
from loper_analysis.stages.validation.files import FILES, report_tables, targets

STAGE = Stage(name="validation", files=FILES, targets=targets, tables=report_tables)

__all__ = ["STAGE"]
