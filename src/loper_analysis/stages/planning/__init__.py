"""The planning stage: the experiment planner: strides needed for a target precision.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.planning.files import FILES, targets
from loper_analysis.stages.stage import Stage

STAGE = Stage(name="planning", files=FILES, targets=targets)

__all__ = ["STAGE"]
