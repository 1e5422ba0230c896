"""loper_analysis: swing-phase joint impedance from LOPER perturbation experiments.

Each stage of the pipeline is a slice under :mod:`.stages` (``stages/<stage>/``: its file step, its result
files, its settings reader and its subcommands), named as its rule file under ``workflow/rules/`` and its folder
under ``results/``; :data:`.stages.STAGES` lists them in the workflow's order. Below the slices the science
packages take arrays, tables, models and settings objects, never paths or the configuration:

* :mod:`.swing_leg` - the swing-leg model every stage shares;
* :mod:`.motion` - markers, the OpenSim model and scaling, inverse kinematics;
* :mod:`.gait` - ground reactions, gait events, strides and their outliers;
* :mod:`.dynamics` - inverse dynamics: joint moments and powers;
* :mod:`.device` - the robot: controller, device tests, load cell and clock sync;
* :mod:`.transparency` - the device's transparency;
* :mod:`.impedance` - perturbation responses and the impedance fits;
* :mod:`.planning` - the precision of an experiment before it is run;
* :mod:`.synthetic` - the synthetic lab;
* :mod:`.report` - headline tables, figures and the front page;
* :mod:`.inspection` - what a lab's C3D file holds (``loper-analysis inspect``).

:mod:`.io` reads and writes the lab's file formats (and holds the one atomic writer); :mod:`.layout` spells
every path. Shared homes: :mod:`.constants` (names and the sign convention), :mod:`.checks` (input checks),
:mod:`.errors`, :mod:`.reference` (the study's published values), :mod:`.study_design` (trials and onsets),
:mod:`.filtering` (the low-pass), :mod:`.timing` (a job's clock), :mod:`.config_file`, :mod:`.config_sections`
and :mod:`.schema` (the configuration). Importing the package has no side effects.
"""

__version__ = "0.1.0"
