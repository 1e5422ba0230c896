"""loper_analysis: swing-phase joint impedance from LOPER perturbation experiments.

Three layers: :mod:`.io` reads and writes the lab's file formats (and holds
the one atomic writer); the analysis modules (:mod:`.dynamics`,
:mod:`.identification`, :mod:`.responses`, :mod:`.strides`,
:mod:`.transparency`, :mod:`.kinematics`, :mod:`.device`, :mod:`.synthetic`,
:mod:`.figures`, ...) take arrays and tables, never paths; :mod:`.steps` is
the file layer that the workflow rules and the ``loper-analysis`` command
call. Shared homes: :mod:`.constants` (names and the sign convention),
:mod:`.checks` (input checks), :mod:`.errors`, :mod:`.reference` (the study's
values), :mod:`.anthropometry` (Winter's table). Importing the package has no
side effects.
"""

__version__ = "0.1.0"
