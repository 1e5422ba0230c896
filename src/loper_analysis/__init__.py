"""loper_analysis: swing-phase joint impedance from LOPER perturbation experiments.

Modules: :mod:`dynamics` (planar swing-leg model), :mod:`identification`
(impedance fits), :mod:`validation` (the synthetic validation study).
Importing the package has no side effects.
"""

__version__ = "0.1.0"
