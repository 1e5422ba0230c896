"""Ground reaction, gait events and strides: the ``grf``, ``events`` and ``strides`` stages.

* :mod:`.grf`, :mod:`.plate_geometry` - force platforms: resting level, centre of pressure, external loads;
* :mod:`.contacts`, :mod:`.events` - foot contacts and gait events from plates or treadmill belts;
* :mod:`.strides`, :mod:`.resampling` - strides of one leg on normalised time;
* :mod:`.outliers` - the per-sample IQR rule for strides.
"""
