"""The file layer: one function per workflow rule (and command-line subcommand).

Every function here reads its input files, calls the library (which works on
arrays and frames only) and writes exactly its declared outputs through the
atomic writer (:mod:`loper_analysis.io.atomic`); nothing below this layer
touches a path. Workflow scripts call one of these functions inside
:func:`rule_log`, which routes the messages, warnings and, on failure, the
full error of the job to its log file. Each module is named after its rule
file under ``workflow/rules/`` and writes to the ``results/`` folder of that
name; a stage's settings are a frozen dataclass built from the configuration
by its ``from_config`` (rules, the command and the benchmarks alike).

* :mod:`.markers` - a C3D's markers as a TRC in the model's names and frame;
* :mod:`.events` - gait events, and the robot's load cell on the mocap clock;
* :mod:`.strides` - strides, their outliers and cycles, the stride summary;
* :mod:`.grf` - force platforms to an OpenSim external-loads ``.mot``;
* :mod:`.model` - generic model, scaling, segment tables;
* :mod:`.ik` - inverse kinematics (one job per trial, or in time chunks);
* :mod:`.transparency` - the transparency tables and figure;
* :mod:`.impedance` - responses and fits per subject and onset, aggregates, figures;
* :mod:`.validation` - the validation study;
* :mod:`.device` - device tests: simulated logs, FRF, steps, summary, figures;
* :mod:`.synthetic` - raw files of synthetic subjects;
* :mod:`.report` - the Markdown rendering of the result tables and the front page of the report;
* :mod:`.cluster` - why SLURM ended the failed jobs of a run.
"""

from loper_analysis.steps.logs import rule_log

__all__ = ["rule_log"]
