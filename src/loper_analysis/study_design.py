"""The study's design: its trials, their names, their perturbation onsets and their conditions.

A subject walks a static trial (for scaling), the transparency pair (without
the robot, and with it in minimal-impedance mode), and the perturbation
trials: ``perturbation_repeats`` trials per onset, named
``pert{onset:03d}-{k}`` (``pert050-1`` is the first trial with pulses 50 ms
after toe-off). The device subject also has the device tests. The names of
the static trial and of the transparency pair come from the config
(``trials``); :class:`StudyDesign` turns them into the list of trials, and a
trial's name back into its onset and condition, so that the workflow only
wires what is decided and tested here.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from loper_analysis.errors import LoperInputError

__all__ = [
    "DEVICE_TESTS",
    "PERTURBED_SIDE",
    "PULSE_DURATION_S",
    "PULSE_FORCE_N",
    "SEED",
    "TRANSPARENCY_CONDITIONS",
    "StudyDesign",
    "perturbation_trial_name",
]

#: The leg the robot perturbs, whose swing is identified (config ``study.perturbed_side``).
PERTURBED_SIDE: str = "left"
#: The study's perturbation: a rectangular desired force along the thigh (N) ... (config
#: ``synthetic.pulse_force_n``, ``planning.pulse_force_n``, ``validation.pulse_force_n``)
PULSE_FORCE_N: float = 40.0
#: ... for this long (s; ``*.pulse_duration_s``).
PULSE_DURATION_S: float = 0.1
#: The study's random seed, from which every random number of the pipeline derives (config ``seed``).
SEED: int = 2024

#: Trials of the device tests (frequency response and steps), recorded by the device subject.
DEVICE_TESTS: tuple[str, ...] = ("device-frf", "device-steps")
#: Conditions of the transparency pair, compared by :mod:`loper_analysis.transparency`: walking without the robot,
#: and with it in minimal-impedance mode.
TRANSPARENCY_CONDITIONS: tuple[str, ...] = ("no_device", "device")
_PERTURBATION_NAME = re.compile(r"^pert(\d{3})-([1-9]\d*)$")


def perturbation_trial_name(onset_ms: int, repeat: int) -> str:
    """The name of the ``repeat``-th (1-based) perturbation trial at onset ``onset_ms`` (0..999 ms)."""
    if not 0 <= int(onset_ms) <= 999 or int(repeat) < 1:
        raise LoperInputError(
            f"perturbation trial: onset {onset_ms} ms must lie in 0 .. 999 and repeat {repeat} must be at least 1"
        )
    return f"pert{int(onset_ms):03d}-{int(repeat)}"


@dataclass(frozen=True)
class StudyDesign:
    """The trials of every subject (config ``trials``).

    Attributes
    ----------
    static, no_device, device : str
        Names of the static trial and of the transparency pair's trials.
    perturbation_onsets_ms : tuple of int
        Pulse onsets after toe-off, ms, in the config's order.
    perturbation_repeats : int
        Trials per onset.
    perturbed_side : {"left", "right"}
        The leg the robot perturbs.
    """

    static: str = "static"
    no_device: str = "walk-nodevice"
    device: str = "walk-device"
    perturbation_onsets_ms: tuple[int, ...] = (50, 175, 300)
    perturbation_repeats: int = 2
    perturbed_side: str = PERTURBED_SIDE

    def perturbation_trials(self, onset_ms: int | None = None) -> list[str]:
        """Names of the perturbation trials, onset by onset (only ``onset_ms``'s when given)."""
        onsets = self.perturbation_onsets_ms if onset_ms is None else (int(onset_ms),)
        return [perturbation_trial_name(o, k) for o in onsets for k in range(1, self.perturbation_repeats + 1)]

    def walking_trials(self) -> list[str]:
        """Every walking trial: the transparency pair, then the perturbation trials."""
        return [self.no_device, self.device, *self.perturbation_trials()]

    def trials(self) -> list[str]:
        """Every trial the design names: the static trial, the walking trials and the device tests."""
        return [self.static, *self.walking_trials(), *DEVICE_TESTS]

    def onset_ms(self, trial: str) -> int | None:
        """The perturbation onset (ms) of a perturbation trial of this design; None for any other trial."""
        match = _PERTURBATION_NAME.match(trial)
        if match is None or trial not in self.perturbation_trials():
            return None
        return int(match.group(1))

    def condition(self, trial: str) -> str:
        """The trial's condition: ``static``, ``no_device``, ``device`` (:data:`TRANSPARENCY_CONDITIONS`),
        ``perturbation`` or ``device_test``.

        Raises
        ------
        LoperInputError
            A name that is no trial of the design (naming the design's trials).
        """
        named = {
            self.static: "static",
            self.no_device: "no_device",
            self.device: "device",
            **dict.fromkeys(DEVICE_TESTS, "device_test"),
            **dict.fromkeys(self.perturbation_trials(), "perturbation"),
        }
        if trial not in named:
            raise LoperInputError(f"trial '{trial}' is no trial of the design ({', '.join(self.trials())})")
        return named[trial]

    def kind(self, trial: str) -> str:
        """``static`` for the static trial, ``walking`` for every other (the label maps' kinds)."""
        return "static" if trial == self.static else "walking"

    def with_robot(self, trial: str) -> bool:
        """Whether the trial is walked with the robot (it has a robot log)."""
        return self.condition(trial) in ("device", "perturbation", "device_test")

    def onsets_of(self, trials: Sequence[str]) -> list[int]:
        """The distinct onsets (ms) of the perturbation trials among ``trials``, in the design's order."""
        present = {self.onset_ms(t) for t in trials} - {None}
        return [o for o in self.perturbation_onsets_ms if o in present]
