"""The impedance stage: perturbation responses and impedance fits per subject and onset, aggregates, figures.

``step`` is its file step (the rules' scripts and the command line call it), ``files`` its result files.
"""

from loper_analysis.stages.impedance.files import FILES, report_tables, targets
from loper_analysis.stages.stage import Stage

STAGE = Stage(name="impedance", files=FILES, targets=targets, tables=report_tables)

__all__ = ["STAGE"]
