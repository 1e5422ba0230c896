"""Synthetic gait lab: walking kinematics, gait events and treadmill forces of virtual subjects.

:mod:`.gait` holds the nominal gait (joint-angle curves as Fourier series),
the stride-to-stride variable trial simulation and the split-belt treadmill
ground reaction forces. Importing the package has no side effects.
"""
