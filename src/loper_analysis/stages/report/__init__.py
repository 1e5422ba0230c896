"""The report stage: the Markdown rendering of the result tables and the report's front page.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.report.files import FILES, targets
from loper_analysis.stages.stage import Stage

STAGE = Stage(name="report", files=FILES, targets=targets)

__all__ = ["STAGE"]
