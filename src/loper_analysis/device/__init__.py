"""The LOPER device and its records: the ``device`` stage and the load cell.

* :mod:`.controller` - the force controller's simulation;
* :mod:`.trials`, :mod:`.analysis` - device-test trials and their FRF and step responses;
* :mod:`.clock_sync` - the robot clock on the motion-capture clock (sync pulses);
* :mod:`.pulse` - the shape of a measured force pulse and the pulses in a force record;
* :mod:`.loadcell` - the robot log on the mocap frames: interaction force and perturbation onsets.
"""
