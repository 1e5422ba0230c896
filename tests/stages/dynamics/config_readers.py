"""The rules that read each key of the ``dynamics`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "dynamics.cutoff_hz": "dynamics",
    "dynamics.foot_bodies.left": "dynamics",
    "dynamics.foot_bodies.right": "dynamics",
}
