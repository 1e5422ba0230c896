"""The study's published values that the pipeline reproduces or compares with, in one place.

Where each number comes from is listed in ``docs/reference_values.md``.
Units are in the names; angles in rad, forces in N.
"""

from __future__ import annotations

__all__ = [
    "STUDY_SUBJECTS",
    "STUDY_TRANSPARENCY_RAD",
    "STUDY_INTERACTION_FORCE_N",
    "STUDY_DEVICE",
    "STUDY_VALIDATION_NO_NOISE",
    "STUDY_VALIDATION_NOISE",
    "STUDY_SWING_IMPEDANCE",
    "ANKLE_SWING_IMPEDANCE",
    "LITERATURE",
]

#: Subjects of the impedance experiment: mean and SD of age, height and mass; share of men (6 of 9).
STUDY_SUBJECTS: dict[str, tuple[float, float] | float] = {
    "age_yr": (26.1, 1.2),
    "height_m": (1.73, 0.14),
    "mass_kg": (64.9, 12.1),
    "male_fraction": 6 / 9,
}

#: Transparency of the device: (phase, joint) -> (RMSD with vs without the device, ISV_ave), rad.
STUDY_TRANSPARENCY_RAD: dict[tuple[str, str], tuple[float, float]] = {
    ("stance", "hip"): (0.024, 0.040),
    ("stance", "knee"): (0.032, 0.062),
    ("stance", "ankle"): (0.017, 0.040),
    ("swing", "hip"): (0.035, 0.059),
    ("swing", "knee"): (0.071, 0.129),
    ("swing", "ankle"): (0.035, 0.064),
}

#: Interaction force walking with the device in minimal-impedance mode, per phase:
#: (RMS mean, RMS SD, max |F| mean, max |F| SD) across subjects, N.
STUDY_INTERACTION_FORCE_N: dict[str, tuple[float, float, float, float]] = {
    "stance": (1.97, 0.21, 4.46, 0.82),
    "swing": (2.13, 0.30, 4.63, 0.79),
}

#: Device performance on a free-hanging leg: metric -> (value, unit). The rise time and overshoot
#: are the centres of the study's ranges over 20, 40 and 60 N (9.7-10.3 ms, 29-32 %).
STUDY_DEVICE: dict[str, tuple[float, str]] = {
    "bandwidth_hz": (39.0, "Hz"),
    "rise_time_ms": (10.0, "ms"),
    "overshoot_pct": (30.5, "%"),
    "steady_state_40n_n": (36.0, "N"),
}

#: Validation study without noise: (min, max) of the estimation error for K (N·m/rad) and D (N·m·s/rad),
#: the same range for every joint.
STUDY_VALIDATION_NO_NOISE: dict[str, tuple[float, float]] = {
    "K": (-0.87, 0.59),
    "D": (-0.092, 0.047),
}

#: Validation study with noise: parameter -> (min, max, SD) of the estimation error (N·m/rad or N·m·s/rad).
STUDY_VALIDATION_NOISE: dict[str, tuple[float, float, float]] = {
    "K_hip": (-6.2, 6.5, 15.0),
    "D_hip": (-0.57, 0.50, 0.12),
    "K_knee": (-2.5, 3.5, 0.53),
    "D_knee": (-0.11, 0.19, 0.030),
    "K_ankle": (-120.0, 120.0, 24.0),
    "D_ankle": (-4.0, 10.0, 1.5),
}

#: The study's swing-phase result: joint -> parameter -> (lowest, highest) across-subject mean over the three
#: onsets; K in N·m/rad, D in N·m·s/rad. The study reports no ankle values it trusted.
STUDY_SWING_IMPEDANCE: dict[str, dict[str, tuple[float, float]]] = {
    "hip": {"K": (34.0, 66.0), "D": (1.9, 4.6)},
    "knee": {"K": (0.0, 3.5), "D": (0.02, 0.14)},
}

#: Not a study value: the range of ankle K (N·m/rad) and D (N·m·s/rad) in swing this pipeline treats as
#: plausible, for the identifiability rule (``docs/identification.md``, "Fit status"): from no stiffness or
#: damping up to about 2.5 times the default synthetic ankle (8 N·m/rad, 0.3 N·m·s/rad), a little above the
#: study's knee damping and a third of its lowest hip stiffness.
ANKLE_SWING_IMPEDANCE: dict[str, tuple[float, float]] = {"K": (0.0, 20.0), "D": (0.0, 0.75)}

#: Joint impedance in the literature (relaxed conditions) and the study's own swing-phase result:
#: (source, joint, (K low, K high) N·m/rad, (D low, D high) N·m·s/rad); None where not reported.
LITERATURE: tuple[tuple[str, str, tuple[float, float], tuple[float | None, float | None]], ...] = (
    ("force perturbation, static", "hip", (50.0, 60.0), (7.0, 9.0)),
    ("force perturbation, static", "knee", (15.0, 20.0), (1.0, 2.0)),
    ("position perturbation, static", "hip", (75.0, 318.0), (2.0, 21.0)),
    ("position perturbation, static", "knee", (36.0, 75.0), (1.8, 2.2)),
    ("position perturbation, imposed motion", "knee", (25.0, 30.0), (None, None)),
    *(
        (
            "the study: swing phase, across-subject mean over onsets",
            joint,
            STUDY_SWING_IMPEDANCE[joint]["K"],
            STUDY_SWING_IMPEDANCE[joint]["D"],
        )
        for joint in ("hip", "knee")
    ),
)
