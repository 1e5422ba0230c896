"""The synthetic gait lab: virtual subjects with known impedance and the raw recordings a lab would make of them.

* :mod:`.subjects` - anthropometrics and the true impedance per onset;
* :mod:`.gait_curves`, :mod:`.walking` - nominal slow walking and stride-variable trials;
* :mod:`.variability` - study-level stride-to-stride variability and the gait adaptation to the device;
* :mod:`.treadmill` - split-belt ground reaction forces;
* :mod:`.response` - the swing leg's answer to a LOPER pulse (and the minimal-impedance force) with the true impedance;
* :mod:`.sync` - the robot's sync pulse trains;
* :mod:`.trials` - whole trials: C3D contents and robot logs;
* :mod:`.coordinate_trials` - trials at the coordinate level (no markers, no IK), for the planner's checks.

Importing the package has no side effects.
"""
