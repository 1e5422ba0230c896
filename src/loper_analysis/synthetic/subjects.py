"""Synthetic subjects: anthropometrics and the true impedance they walk with.

A row of ``config/subjects.tsv`` with ``source = synthetic`` may leave
``sex``, ``age_yr``, ``height_m`` and ``mass_kg`` empty: they are drawn from
the study's impedance-experiment subjects
(:data:`loper_analysis.reference.STUDY_SUBJECTS`; normal distributions
clipped to ± 2 SD), seeded by the master seed and the subject ID, so adding a
subject never changes the others. The true stiffness and damping per joint
and onset are the config's group values times a per-subject factor
(log-normal with the configured between-subject CV, one factor per joint,
parameter and onset); ``data/raw/{subject}/truth.yaml`` holds both
(:mod:`loper_analysis.io.truth`).
"""

from __future__ import annotations

import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError
from loper_analysis.reference import STUDY_SUBJECTS

__all__ = ["ImpedanceTruth", "subject_anthropometry", "true_impedance"]


def _rng(seed: int, subject: str, what: str) -> np.random.Generator:
    return np.random.default_rng([int(seed), zlib.crc32(subject.encode()), zlib.crc32(what.encode())])


def subject_anthropometry(row: Mapping, seed: int) -> dict:
    """The row's anthropometrics with missing values drawn from the study's subjects.

    Returns ``subject``, ``sex``, ``age_yr``, ``height_m``, ``mass_kg``.
    Raises LoperInputError for a height outside 1 .. 2.5 m or a mass outside
    (0, 300] kg (naming the subject and the value).
    """
    subject = str(row["subject"])
    rng = _rng(seed, subject, "anthropometry")
    draws = {k: rng.standard_normal() for k in ("age_yr", "height_m", "mass_kg")}
    male = rng.uniform() < STUDY_SUBJECTS["male_fraction"]
    out = {"subject": subject}

    def given(key):
        value = row.get(key)
        return None if value is None or (isinstance(value, float) and np.isnan(value)) or value == "" else value

    out["sex"] = given("sex") or ("male" if male else "female")
    for key in ("age_yr", "height_m", "mass_kg"):
        value = given(key)
        if value is None:
            mean, sd = STUDY_SUBJECTS[key]
            value = round(float(mean + sd * np.clip(draws[key], -2.0, 2.0)), 2)
        out[key] = float(value)
    if not 1.0 <= out["height_m"] <= 2.5:
        raise LoperInputError(f"subject {subject}: height_m = {out['height_m']} m is outside 1 .. 2.5 m")
    if not 0.0 < out["mass_kg"] <= 300.0:
        raise LoperInputError(f"subject {subject}: mass_kg = {out['mass_kg']} kg is outside (0, 300] kg")
    return out


@dataclass(frozen=True)
class ImpedanceTruth:
    """The synthetic subjects' true impedance: the group values per onset (ms) ``[hip, knee, ankle]`` in
    N·m/rad (``stiffness_nm_per_rad``) and N·m·s/rad (``damping_nms_per_rad``), a subject's log-normal spread
    around them (``between_subject_cv``), and the identification's bounds a true value must lie inside."""

    stiffness_nm_per_rad: Mapping[str, Sequence[float]]
    damping_nms_per_rad: Mapping[str, Sequence[float]]
    between_subject_cv: float
    stiffness_bounds_nm_per_rad: tuple[float, float] = (0.0, 200.0)
    damping_bounds_nms_per_rad: tuple[float, float] = (0.0, 10.0)

    def of(self, subject: str, seed: int) -> dict:
        """True K, D per onset and joint of ``subject`` (:func:`true_impedance`)."""
        return true_impedance(
            subject,
            seed,
            self.stiffness_nm_per_rad,
            self.damping_nms_per_rad,
            self.between_subject_cv,
            self.stiffness_bounds_nm_per_rad,
            self.damping_bounds_nms_per_rad,
        )


def true_impedance(
    subject: str,
    seed: int,
    stiffness_nm_per_rad: Mapping,
    damping_nms_per_rad: Mapping,
    between_subject_cv: float,
    stiffness_bounds: Sequence[float] = (0.0, 200.0),
    damping_bounds: Sequence[float] = (0.0, 10.0),
) -> dict:
    """True K, D per onset and joint: ``{onset_ms: {joint: {"K": N·m/rad, "D": N·m·s/rad}}}``.

    ``stiffness_nm_per_rad`` / ``damping_nms_per_rad`` map an onset (ms, int
    or str) to the group values ``[hip, knee, ankle]``. Raises LoperInputError
    when a value falls outside the identification bounds (naming subject,
    onset, joint and value).
    """
    if set(map(int, stiffness_nm_per_rad)) != set(map(int, damping_nms_per_rad)):
        raise LoperInputError("synthetic.truth: stiffness and damping must list the same onsets")
    if not 0.0 <= between_subject_cv < 1.0:
        raise LoperInputError(f"synthetic.truth.between_subject_cv must lie in [0, 1), got {between_subject_cv}")
    rng = _rng(seed, subject, "impedance")
    sigma = np.sqrt(np.log1p(between_subject_cv**2))
    out: dict = {}
    for onset in sorted(stiffness_nm_per_rad, key=int):
        k_group, d_group = stiffness_nm_per_rad[onset], damping_nms_per_rad[onset]
        if len(k_group) != len(JOINTS) or len(d_group) != len(JOINTS):
            raise LoperInputError(f"synthetic.truth, onset {onset}: give one value per joint {JOINTS}")
        entry = {}
        for j, joint in enumerate(JOINTS):
            factors = np.exp(sigma * rng.standard_normal(2) - 0.5 * sigma**2)
            k, d = float(k_group[j]) * factors[0], float(d_group[j]) * factors[1]
            for name, value, (lo, hi), unit in (
                ("K", k, stiffness_bounds, "N·m/rad"),
                ("D", d, damping_bounds, "N·m·s/rad"),
            ):
                if not lo <= value <= hi:
                    raise LoperInputError(
                        f"subject {subject}, onset {onset} ms, {joint}: true {name} = {value:.4g} {unit} lies outside "
                        f"the identification bounds [{lo}, {hi}]"
                    )
            entry[joint] = {"K": round(float(k), 6), "D": round(float(d), 6)}
        out[int(onset)] = entry
    return out
