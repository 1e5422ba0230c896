"""The ik stage: inverse kinematics (one job per trial, or in time chunks), agreement with the lab's angles.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.ik.files import FILES
from loper_analysis.stages.stage import Stage

STAGE = Stage(name="ik", files=FILES)

__all__ = ["STAGE"]
