"""loper_analysis.synthetic.sync: seeded pseudo-random sync pulse trains."""

import numpy as np
import pytest

from loper_analysis.device.clock_sync import rising_edges
from loper_analysis.errors import LoperInputError
from loper_analysis.synthetic.sync import pulse_train_at, sync_pulse_starts

ROBOT_HZ = 1000.0


def sampled_train(duration_s, seed):
    """The train of ``seed`` sampled on the robot clock (1000 Hz)."""
    return pulse_train_at(np.arange(int(round(duration_s * ROBOT_HZ))) / ROBOT_HZ, sync_pulse_starts(duration_s, seed))


def test_pulse_train_is_seeded_and_random():
    a = sampled_train(60.0, seed=4)
    b = sampled_train(60.0, seed=4)
    c = sampled_train(60.0, seed=5)
    assert a.shape == (60000,)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert set(np.unique(a)) == {0.0, 5.0}
    starts = sync_pulse_starts(60.0, seed=4)
    intervals = np.diff(starts)
    assert starts[0] >= 0.5 and starts[-1] < 60.0
    assert intervals.min() >= 0.5 and intervals.max() < 1.5 and intervals.std() > 0.2
    # each pulse is 10 ms = 10 samples high
    edges = rising_edges(a, ROBOT_HZ)
    assert edges.size == starts.size
    np.testing.assert_allclose(edges, starts, atol=0.5 / ROBOT_HZ + 1e-12)
    # a longer train starts with the same pulses
    np.testing.assert_array_equal(sync_pulse_starts(120.0, seed=4)[: starts.size], starts)


def test_pulse_train_bad_settings():
    with pytest.raises(LoperInputError, match="periodic"):
        sync_pulse_starts(10.0, 1, min_interval_s=1.0, max_interval_s=1.0)
    with pytest.raises(LoperInputError, match="pulse_s"):
        pulse_train_at([0.0, 0.1], [0.05], pulse_s=0.0)
    with pytest.raises(LoperInputError, match="duration_s"):
        sync_pulse_starts(-1.0, 1)
    with pytest.raises(LoperInputError, match="starts_s"):
        pulse_train_at([0.0, 0.1], [0.2, 0.1])
