"""The model stage: the generic model, its scaling to the static trial, the segment table.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.model.files import FILES, targets
from loper_analysis.stages.stage import Stage

STAGE = Stage(name="model", files=FILES, targets=targets)

__all__ = ["STAGE"]
