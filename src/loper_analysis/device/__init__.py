"""The LOPER device: controller simulation (:mod:`.controller`), device-test trials (:mod:`.trials`) and their
analysis (:mod:`.analysis`)."""
