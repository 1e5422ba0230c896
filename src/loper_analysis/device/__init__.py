"""The LOPER device: controller simulation (:mod:`.controller`) and device-test analysis (:mod:`.analysis`)."""
