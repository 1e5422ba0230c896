"""Ground reaction, gait events and strides: the ``grf``, ``events`` and ``strides`` stages.

* :mod:`.grf`, :mod:`.plate_geometry` - force platforms: resting level, centre of pressure, external loads;
* :mod:`.contacts`, :mod:`.events` - foot contacts and gait events from plates or treadmill belts;
* :mod:`.plate_contacts`, :mod:`.contact_flags`, :mod:`.foot_across_plates` - a plate's contacts, each one's
  foot, flag and reason, one foot across plates;
* :mod:`.strides`, :mod:`.resampling` - strides of one leg on normalised time;
* :mod:`.outliers` - the per-sample IQR rule for strides.
"""
