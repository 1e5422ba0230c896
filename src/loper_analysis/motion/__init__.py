"""Marker motion to joint angles: the ``markers``, ``model`` and ``ik`` stages.

* :mod:`.markers` - gap filling, gap summaries and the lab-to-model rotation;
* :mod:`.marker_names`, :mod:`.label_matching` - a lab's C3D labels to a model's marker names;
* :mod:`.lab_frame`, :mod:`.heading` - the lab's axes and the walking direction read from a recording;
* :mod:`.filtering` - zero-phase low-pass filters (markers and forces);
* :mod:`.plausibility` - body lengths and IK marker errors a good recording can have;
* :mod:`.model`, :mod:`.static_trial` - the generic OpenSim model and the static trial scaling uses;
* :mod:`.still_window`, :mod:`.body_size` - the static trial's stillest window; the subject's mass and height;
* :mod:`.segments` - the swing-leg segment table from any scaled OpenSim model;
* :mod:`.ik`, :mod:`.ik_determinacy` - inverse kinematics through OpenSim and which coordinates markers determine.
"""
