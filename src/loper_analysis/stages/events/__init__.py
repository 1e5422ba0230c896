"""The events stage: gait events, and the robot's load cell on the motion-capture clock.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.events.files import FILES
from loper_analysis.stages.stage import Stage

STAGE = Stage(name="events", files=FILES)

__all__ = ["STAGE"]
