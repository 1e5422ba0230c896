"""Planar swing-leg model: a cart (pelvis translation) carrying thigh, shank and foot.

Equations of motion (``docs/swing_leg_model.md``)::

    M(q) q'' = -C(q, q') + G(q) + u + Ja(q)^T F

* ``q = [x, q_thigh, q_shank, q_foot]``, joint angles and the generalised
  forces of joint torques as stated in :mod:`loper_analysis.constants`
  (flexion and dorsiflexion positive).
* ``Ja`` is the Jacobian (2 x 4) of the rod attachment point on the thigh, at
  ``attachment_m`` from the hip along the thigh axis; ``F = (F_x, F_y)`` in N,
  world frame (x forward, y up). A second rod may push on the shank, at
  ``shank_attachment_m`` from the knee along the shank axis: its point's
  Jacobian and force enter the same way (``+ Js(q)^T F_s``).

Segment parameters come from :class:`SegmentParameters` (SI units). The heavy
lifting is compiled in :mod:`loper_analysis.swing_leg.kernels`; this module offers the
checked, vectorised NumPy API the library calls (inverse dynamics, joint angles and
back). The terms one by one and a reference forward simulation on SciPy's ``solve_ivp``,
which check the kernels against OpenSim, are the tests' (``tests/swing_leg/reference_dynamics.py``).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np
import pandas as pd

from loper_analysis.checks import finite_rows
from loper_analysis.constants import GRAVITY_M_PER_S2, SEGMENTS
from loper_analysis.errors import LoperInputError
from loper_analysis.swing_leg import kernels
from loper_analysis.swing_leg.anthropometry import (
    ANKLE_HEIGHT_FRACTION,
    HEEL_BEHIND_ANKLE_FRACTION,
    WINTER_SEGMENTS,
)

__all__ = [
    "BRACE_ATTACHMENT_FRACTION",
    "SegmentParameters",
    "segment_parameters_from_anthropometry",
    "inverse_dynamics",
    "joint_angles",
    "segment_coordinates",
]

#: Where the robot's brace sits along the thigh, as a fraction of its length from the hip (config
#: ``model.brace_attachment_fraction``); a model's brace markers win.
BRACE_ATTACHMENT_FRACTION: float = 0.8

_SEGMENT_COLUMNS = ("mass_kg", "inertia_kg_m2", "length_m", "com_x_m", "com_y_m")


def _triple(name: str, value) -> tuple[float, float, float]:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (3,):
        raise LoperInputError(f"{name} must have one value per segment {SEGMENTS}, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise LoperInputError(f"{name} must be finite, got {arr.tolist()}")
    return tuple(float(v) for v in arr)


@dataclass(frozen=True)
class SegmentParameters:
    """Inertial and geometric parameters of the swing-leg model (SI units).

    Per-segment tuples are ordered thigh, shank, foot. COM positions are in the
    segment frame: origin at the proximal joint, x forward, y up in the neutral
    pose (so a thigh COM 0.18 m below the hip is ``com_y_m = -0.18``). The
    distal joint of thigh and shank lies at ``(0, -length_m)``. ``attachment_m``: the thigh rod's point, from the
    hip along the thigh (m); ``shank_attachment_m``: a second rod's point on the shank, from the knee along the
    shank (m), or None without one.
    """

    cart_mass_kg: float
    mass_kg: tuple[float, float, float]
    inertia_kg_m2: tuple[float, float, float]
    length_m: tuple[float, float, float]
    com_x_m: tuple[float, float, float]
    com_y_m: tuple[float, float, float]
    attachment_m: float
    gravity_m_per_s2: float = GRAVITY_M_PER_S2
    shank_attachment_m: float | None = None
    _packed: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in _SEGMENT_COLUMNS:
            object.__setattr__(self, name, _triple(name, getattr(self, name)))
        for name in ("cart_mass_kg", "attachment_m", "gravity_m_per_s2"):
            v = float(getattr(self, name))
            if not np.isfinite(v):
                raise LoperInputError(f"{name} must be finite, got {v}")
            object.__setattr__(self, name, v)
        for name in ("mass_kg", "inertia_kg_m2", "length_m"):
            vals = getattr(self, name)
            for seg, v in zip(SEGMENTS, vals):
                if v <= 0:
                    raise LoperInputError(f"{name} of the {seg} must be positive, got {v}")
        if self.cart_mass_kg <= 0:
            raise LoperInputError(f"cart_mass_kg must be positive, got {self.cart_mass_kg}")
        if not 0 <= self.attachment_m <= self.length_m[0]:
            raise LoperInputError(
                f"attachment_m must lie on the thigh (0 .. {self.length_m[0]} m), got {self.attachment_m}"
            )
        if self.shank_attachment_m is not None:
            ds = float(self.shank_attachment_m)
            if not (np.isfinite(ds) and 0 <= ds <= self.length_m[1]):
                raise LoperInputError(
                    f"shank_attachment_m must lie on the shank (0 .. {self.length_m[1]} m from the knee), got {ds}"
                )
            object.__setattr__(self, "shank_attachment_m", ds)
        if self.gravity_m_per_s2 < 0:
            raise LoperInputError(f"gravity_m_per_s2 must be >= 0, got {self.gravity_m_per_s2}")
        packed = np.empty(kernels.N_PACKED)
        packed[kernels.CART_MASS] = self.cart_mass_kg
        for i in range(3):
            packed[kernels.segment_slot(i) : kernels.segment_slot(i) + 5] = [
                self.mass_kg[i],
                self.inertia_kg_m2[i],
                self.length_m[i],
                self.com_x_m[i],
                self.com_y_m[i],
            ]
        packed[kernels.ATTACHMENT] = self.attachment_m
        packed[kernels.GRAVITY] = self.gravity_m_per_s2
        packed[kernels.SHANK_ATTACHMENT] = 0.0 if self.shank_attachment_m is None else self.shank_attachment_m
        packed.setflags(write=False)
        object.__setattr__(self, "_packed", packed)

    @property
    def packed(self) -> np.ndarray:
        """Parameter vector (19,) in the layout of :mod:`loper_analysis.swing_leg.kernels`."""
        return self._packed

    @property
    def leg_mass_kg(self) -> float:
        return float(sum(self.mass_kg))

    def replace(self, **changes) -> SegmentParameters:
        """A copy with some fields changed."""
        values = {k: v for k, v in asdict(self).items() if k != "_packed"}
        values.update(changes)
        return SegmentParameters(**values)

    def to_frame(self) -> pd.DataFrame:
        """Tidy table: one row per segment (cart, thigh, shank, foot)."""
        rows = [
            {"segment": "cart", "mass_kg": self.cart_mass_kg}
            | {c: np.nan for c in _SEGMENT_COLUMNS[1:]}
            | {"attachment_m": np.nan, "gravity_m_per_s2": self.gravity_m_per_s2}
        ]
        for i, seg in enumerate(SEGMENTS):
            row = {"segment": seg} | {c: getattr(self, c)[i] for c in _SEGMENT_COLUMNS}
            row["attachment_m"] = {"thigh": self.attachment_m, "shank": self.shank_attachment_m}.get(seg)
            row["attachment_m"] = np.nan if row["attachment_m"] is None else row["attachment_m"]
            row["gravity_m_per_s2"] = np.nan
            rows.append(row)
        return pd.DataFrame(rows)

    @classmethod
    def from_frame(cls, df: pd.DataFrame, source: str = "segment table") -> SegmentParameters:
        """Parameters from the table of :meth:`to_frame` (rows cart, thigh, shank, foot); ``source`` names it in
        errors."""
        need = {"segment", *_SEGMENT_COLUMNS, "attachment_m"}
        missing = need - set(df.columns)
        if missing:
            raise LoperInputError(f"{source}: missing column(s) {sorted(missing)}")
        df = df.set_index("segment")
        for seg in ("cart", *SEGMENTS):
            if seg not in df.index:
                raise LoperInputError(f"{source}: missing row for segment '{seg}'")

        def number(seg: str, col: str) -> float:
            raw = df.loc[seg, col]
            value = pd.to_numeric(pd.Series([raw]), errors="coerce").iloc[0]
            if pd.isna(value):
                shown = "an empty cell" if pd.isna(raw) else f"value {raw!r}"
                raise LoperInputError(f"{source}: column {col}, segment {seg}: {shown} is not a number")
            return float(value)

        values = {c: tuple(number(seg, c) for seg in SEGMENTS) for c in _SEGMENT_COLUMNS}
        gravity = GRAVITY_M_PER_S2
        if "gravity_m_per_s2" in df.columns and pd.notna(df.loc["cart", "gravity_m_per_s2"]):
            gravity = number("cart", "gravity_m_per_s2")
        shank = None if pd.isna(df.loc["shank", "attachment_m"]) else number("shank", "attachment_m")
        try:
            return cls(
                cart_mass_kg=number("cart", "mass_kg"),
                attachment_m=number("thigh", "attachment_m"),
                gravity_m_per_s2=gravity,
                shank_attachment_m=shank,
                **values,
            )
        except LoperInputError as exc:
            raise LoperInputError(f"{source}: {exc}") from exc


def segment_parameters_from_anthropometry(
    height_m: float, body_mass_kg: float, attachment_fraction: float = BRACE_ATTACHMENT_FRACTION
) -> SegmentParameters:
    """Segment parameters from height and body mass with Winter's table (:mod:`loper_analysis.swing_leg.anthropometry`).

    Masses, lengths, COM positions and radii of gyration are the table's
    fractions of body mass and height; the foot COM lies half a foot length
    from the heel, the heel :data:`~loper_analysis.swing_leg.anthropometry.HEEL_BEHIND_ANKLE_FRACTION`
    foot lengths behind the ankle, half the ankle height below the ankle.
    The cart carries the rest of the body. The brace sits at
    ``attachment_fraction`` of the thigh length from the hip.
    """
    if not 1.0 <= height_m <= 2.5:
        raise LoperInputError(f"height_m must lie in 1 .. 2.5 m, got {height_m}")
    if not body_mass_kg > 0:
        raise LoperInputError(f"body_mass_kg must be positive, got {body_mass_kg}")
    H, Mb = float(height_m), float(body_mass_kg)
    thigh, shank, foot = (WINTER_SEGMENTS[s] for s in SEGMENTS)
    m = (thigh.mass * Mb, shank.mass * Mb, foot.mass * Mb)
    L = (thigh.length * H, shank.length * H, foot.length * H)
    k = (thigh.gyration * L[0], shank.gyration * L[1], foot.gyration * L[2])
    inertia = tuple(mi * ki**2 for mi, ki in zip(m, k))
    ankle_height = ANKLE_HEIGHT_FRACTION * H
    com_x = (0.0, 0.0, foot.com * L[2] - HEEL_BEHIND_ANKLE_FRACTION * L[2])
    com_y = (-thigh.com * L[0], -shank.com * L[1], -0.5 * ankle_height)
    return SegmentParameters(
        cart_mass_kg=Mb - sum(m),
        mass_kg=m,
        inertia_kg_m2=inertia,
        length_m=L,
        com_x_m=com_x,
        com_y_m=com_y,
        attachment_m=attachment_fraction * L[0],
    )


# ---------------------------------------------------------------- checks


def _same_rows(*arrays: tuple[str, np.ndarray]) -> None:
    n = arrays[0][1].shape[0]
    for name, a in arrays[1:]:
        if a.shape[0] != n:
            raise LoperInputError(f"{name} has {a.shape[0]} rows, expected {n} like {arrays[0][0]}")


def _force(force_n, n: int) -> np.ndarray:
    if force_n is None:
        return np.zeros((n, 2))
    f, _ = finite_rows("force_n", force_n, 2)
    if f.shape[0] == 1 and n > 1:
        f = np.repeat(f, n, axis=0)
    _same_rows(("q", np.empty((n, 0))), ("force_n", f))
    return f


def _out(a: np.ndarray, single: bool) -> np.ndarray:
    return a[0] if single else a


# ---------------------------------------------------------------- dynamics


def _checked_terms(q, qd, name: str, values, params: SegmentParameters, force_n):
    """Checked (n, 4) ``values`` and force (n, 2), the terms M, h, Ja (n, 4, 4: thigh rod, shank rod) at (q, q'),
    and whether q was one state."""
    q2, single = finite_rows("q", q, 4)
    qd2, _ = finite_rows("qd", qd, 4)
    v2, _ = finite_rows(name, values, 4)
    _same_rows(("q", q2), ("qd", qd2), (name, v2))
    M, h, Ja = kernels.terms_batch(q2, qd2, params.packed)
    return v2, _force(force_n, len(q2)), M, h, Ja, single


def inverse_dynamics(q, qd, qdd, params: SegmentParameters, force_n=None, shank_force_n=None) -> np.ndarray:
    """Generalised forces u (n, 4) that produce q'' at (q, q') under the rods' forces.

    ``u = M q'' + C - G - Ja^T F - Js^T F_s``; units N (cart) and N m (segments). ``force_n``: the thigh rod's
    force (n, 2) or (2,), N, world x/y; ``shank_force_n``: the shank rod's, for parameters with a
    ``shank_attachment_m`` (None: no shank rod).
    """
    qdd2, F, M, h, Ja, single = _checked_terms(q, qd, "qdd", qdd, params, force_n)
    u = np.einsum("nij,nj->ni", M, qdd2) - h - np.einsum("nji,nj->ni", np.ascontiguousarray(Ja[:, :2]), F)
    if shank_force_n is not None:
        if params.shank_attachment_m is None:
            raise LoperInputError("shank_force_n given, but the segment parameters have no shank_attachment_m")
        u = u - np.einsum("nji,nj->ni", np.ascontiguousarray(Ja[:, 2:]), _force(shank_force_n, len(qdd2)))
    return _out(u, single)


def joint_angles(q, pelvis_angle_rad) -> np.ndarray:
    """Hip flexion, knee flexion, ankle dorsiflexion (n, 3) in rad from segment angles."""
    q2, single = finite_rows("q", q, 4)
    pel = np.broadcast_to(np.asarray(pelvis_angle_rad, dtype=float), (len(q2),))
    th = np.stack([pel - q2[:, 1], q2[:, 2] - q2[:, 1], q2[:, 2] - q2[:, 3]], axis=-1)
    return _out(th, single)


def segment_coordinates(joint_angles_rad, pelvis_angle_rad, pelvis_x_m) -> np.ndarray:
    """Inverse of :func:`joint_angles`: q (n, 4) from joint angles, pelvis angle and cart x."""
    th, single = finite_rows("joint_angles_rad", joint_angles_rad, 3)
    n = len(th)
    pel = np.broadcast_to(np.asarray(pelvis_angle_rad, dtype=float), (n,))
    x = np.broadcast_to(np.asarray(pelvis_x_m, dtype=float), (n,))
    thigh = pel - th[:, 0]
    shank = thigh + th[:, 1]
    foot = shank - th[:, 2]
    return _out(np.stack([x, thigh, shank, foot], axis=-1), single)
