"""The grf stage: force platforms to OpenSim external loads, and their figure.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.grf.files import FILES, targets
from loper_analysis.stages.stage import Stage

STAGE = Stage(name="grf", files=FILES, targets=targets)

__all__ = ["STAGE"]
