"""The swing-leg model every stage shares: a cart carrying thigh, shank and foot in the sagittal plane.

* :mod:`.anthropometry` - Winter's segment table (masses, lengths, centres of mass, radii of gyration);
* :mod:`.dynamics` - the model's segment table, kinematics and equations of motion;
* :mod:`.kernels` - the compiled (numba) equations of motion and RK4 steps.
"""
