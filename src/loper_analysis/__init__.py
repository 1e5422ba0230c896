"""loper_analysis: swing-phase joint impedance from LOPER perturbation experiments.

Three layers. :mod:`.io` reads and writes the lab's file formats (and holds
the one atomic writer). The analysis packages take arrays and tables, never
paths; each is named after the pipeline stages it serves (the rule files
under ``workflow/rules/`` and the folders under ``results/``):

* :mod:`.swing_leg` - the swing-leg model every stage shares;
* :mod:`.motion` - markers, the OpenSim model and scaling, inverse kinematics (``markers``, ``model``, ``ik``);
* :mod:`.gait` - ground reaction, gait events, strides and their outliers (``grf``, ``events``, ``strides``);
* :mod:`.device` - the robot: controller, device tests, load cell and clock sync (``device``, ``loadcell``);
* :mod:`.transparency` - the device's transparency (``transparency``);
* :mod:`.responses`, :mod:`.identification` - perturbation responses and the impedance fits (``impedance``,
  ``validation``);
* :mod:`.planning` - the precision of an experiment before it is run (``planning``);
* :mod:`.synthetic` - the synthetic lab (``synthetic``);
* :mod:`.report` - headline tables, figures and the front page (``report``);
* :mod:`.inspection` - what a lab's C3D file holds (``loper-analysis inspect``).

:mod:`.steps` is the file layer that the workflow rules and the
``loper-analysis`` command call. Shared homes: :mod:`.constants` (names and
the sign convention), :mod:`.checks` (input checks), :mod:`.errors`,
:mod:`.reference` (the study's published values), :mod:`.study_design` (trials
and onsets), :mod:`.config_file` and :mod:`.schema` (the configuration).
Importing the package has no side effects.
"""

__version__ = "0.1.0"
