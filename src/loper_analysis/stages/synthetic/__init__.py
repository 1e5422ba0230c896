"""The synthetic stage: the synthetic lab: raw files of synthetic subjects with known impedance.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.stage import Stage
from loper_analysis.stages.synthetic.files import FILES, targets

STAGE = Stage(name="synthetic", files=FILES, targets=targets)

__all__ = ["STAGE"]
