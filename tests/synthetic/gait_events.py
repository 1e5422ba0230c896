"""Event helpers shared by the synthetic-gait tests: event times per side and complete stances."""

import numpy as np


def event_times(events, side, event):
    """Times (s) of one side's events of one kind."""
    sel = (events["side"] == side) & (events["event"] == event)
    return events.loc[sel, "time_s"].to_numpy()


def stances(events, side):
    """(heel strike, toe-off) pairs of complete stances."""
    hs, to = event_times(events, side, "heel_strike"), event_times(events, side, "toe_off")
    return [(h, to[to > h][0]) for h in hs if np.any(to > h)]
