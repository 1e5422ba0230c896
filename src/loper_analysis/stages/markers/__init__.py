"""The markers stage: a C3D's markers as a TRC in the model's names and frame, the lab's own angles.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.markers.files import FILES
from loper_analysis.stages.stage import Stage

STAGE = Stage(name="markers", files=FILES)

__all__ = ["STAGE"]
