"""The analysis window around a perturbation onset: one type for the responses, the fit, the planner and the
validation study.

* :class:`ResponseWindow` - how long before and after the onset the responses are cut and fitted, and the span
  before them the fit's initial state is taken from (config ``impedance.window_before_s``,
  ``impedance.window_after_s``, ``impedance.initial_state_span_s``), with the checks of the window
  against a planned pulse (:meth:`ResponseWindow.check_pulse`) and a simulated swing
  (:meth:`ResponseWindow.check_in_swing`).
"""

from __future__ import annotations

from dataclasses import dataclass

from loper_analysis.checks import number
from loper_analysis.errors import LoperInputError

__all__ = ["INITIAL_STATE_SPAN_S", "WINDOW_AFTER_S", "WINDOW_BEFORE_S", "WINDOW_KEYS", "ResponseWindow"]

# The analysis window around each onset (config ``impedance.*``, the same values): every default of these
# settings in the library (responses, identification, validation, planning) refers to these.
#: The window starts this long before the perturbation onset (s; ``impedance.window_before_s``) ...
WINDOW_BEFORE_S: float = 0.025
#: ... and ends this long after it (s; ``impedance.window_after_s``).
WINDOW_AFTER_S: float = 0.25
#: Pre-onset span of the fit's initial-state polynomial (s; ``impedance.initial_state_span_s``).
INITIAL_STATE_SPAN_S: float = 0.1

#: Field of :class:`ResponseWindow` -> its config key.
WINDOW_KEYS: dict[str, str] = {
    "before_s": "impedance.window_before_s",
    "after_s": "impedance.window_after_s",
    "initial_state_span_s": "impedance.initial_state_span_s",
}


@dataclass(frozen=True)
class ResponseWindow:
    """The analysis window around a perturbation onset (s).

    Attributes
    ----------
    before_s : float
        The window starts this long before the onset (s, >= 0; ``impedance.window_before_s``).
    after_s : float
        ... and ends this long after it (s, >= 0; ``impedance.window_after_s``).
    initial_state_span_s : float
        The span before the window's start whose perturbed-minus-unperturbed coordinates give the fit's initial
        state (s, >= 0; ``impedance.initial_state_span_s``).

    Raises
    ------
    LoperInputError
        A field that is not a finite number >= 0, naming its config key and the value.
    """

    before_s: float = WINDOW_BEFORE_S
    after_s: float = WINDOW_AFTER_S
    initial_state_span_s: float = INITIAL_STATE_SPAN_S

    def __post_init__(self) -> None:
        for name, key in WINDOW_KEYS.items():
            number(key, getattr(self, name), minimum=0.0)

    def check_pulse(self, pulse_duration_s: float) -> None:
        """Refuse a planned pulse (``pulse_duration_s``, s, > 0) that lasts beyond the window after the onset.

        Raises
        ------
        LoperInputError
            A non-finite or non-positive duration, or one longer than ``after_s``: the fit would not see the
            pulse's end (the message names ``impedance.window_after_s`` and both values).
        """
        d = number("pulse_duration_s", pulse_duration_s)
        if d <= 0:
            raise LoperInputError(f"pulse_duration_s must be > 0 s, got {d:g} s")
        if d > self.after_s:
            raise LoperInputError(
                f"pulse_duration_s = {d:g} s is longer than the fit window after the onset "
                f"(impedance.window_after_s = {self.after_s:g} s): the fit would not see its end"
            )

    def check_in_swing(self, onset_s: float, swing_duration_s: float) -> None:
        """Refuse a window that does not lie inside the validation study's simulated swing
        ``0 .. swing_duration_s`` (s after toe-off) around the onset ``onset_s`` (s after toe-off).

        The window runs from ``onset_s - before_s`` to ``onset_s + after_s``. Outside the swing the simulated
        leg holds the toe-off or heel-strike posture, which is no swing at all, so a fit there says nothing about
        the identification. The message names the config keys (``identification.window_*``, ``validation.*``),
        the value and the limit.

        Raises
        ------
        LoperInputError
            A non-finite or non-positive swing, an onset outside ``0 .. swing_duration_s``, a window
            starting before toe-off or ending after the heel strike.
        """
        swing_duration_s = number("validation.swing_duration_s", swing_duration_s)
        onset_s = number("validation.onset_s", onset_s)
        if swing_duration_s <= 0:
            raise LoperInputError(f"validation.swing_duration_s must be positive, got {swing_duration_s:g} s")
        if not 0 <= onset_s < swing_duration_s:
            raise LoperInputError(
                f"validation.onset_s = {onset_s:g} s lies outside the simulated swing "
                f"0 .. {swing_duration_s:g} s (validation.swing_duration_s)"
            )
        room_after = swing_duration_s - onset_s
        if self.after_s > room_after + 1e-12:
            raise LoperInputError(
                f"impedance.window_after_s = {self.after_s:g} s does not fit in the simulated swing of the "
                f"validation study: the window must end by the heel strike, so it may be at most {room_after:g} s "
                f"(validation.swing_duration_s = {swing_duration_s:g} s - validation.onset_s = {onset_s:g} s)"
            )
        if self.before_s > onset_s + 1e-12:
            raise LoperInputError(
                f"impedance.window_before_s = {self.before_s:g} s does not fit in the simulated swing of the "
                f"validation study: the window must start after toe-off, so it may be at most {onset_s:g} s "
                f"(validation.onset_s)"
            )
