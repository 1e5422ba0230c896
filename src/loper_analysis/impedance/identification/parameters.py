"""The fit's parameter vector and its bounds: K and D per joint, then the inter-joint couplings a fit may add.

* :func:`check_couplings` and :func:`parameter_names` - which couplings, in which order, under which names;
* :func:`parameter_bounds`, :class:`FitBounds` - the bounds from one pair per kind, as the settings hold them;
* :func:`check_bounds`, :func:`fit_bounds` - bounds checked for a fit with or without couplings.

Method: ``docs/identification.md`` ("Bounds and random starts", "Bi-articular stiffness").
"""

from __future__ import annotations

import numpy as np

from loper_analysis.constants import COUPLING_PARAMETERS, COUPLINGS, PARAMETERS
from loper_analysis.errors import LoperInputError

__all__ = [
    "STIFFNESS_BOUNDS_NM_PER_RAD",
    "DAMPING_BOUNDS_NMS_PER_RAD",
    "COUPLING_BOUNDS_NM_PER_RAD",
    "DEFAULT_LOWER",
    "DEFAULT_UPPER",
    "check_couplings",
    "parameter_names",
    "parameter_bounds",
    "FitBounds",
    "check_bounds",
    "fit_bounds",
]

#: Default bounds of every K (N·m/rad; ``impedance.stiffness_bounds_nm_per_rad``) ...
STIFFNESS_BOUNDS_NM_PER_RAD: tuple[float, float] = (0.0, 200.0)
#: ... and of every D (N·m·s/rad; ``impedance.damping_bounds_nms_per_rad``).
DAMPING_BOUNDS_NMS_PER_RAD: tuple[float, float] = (0.0, 10.0)
#: ... and of every inter-joint coupling stiffness (N·m/rad; docs/identification.md, "Bi-articular stiffness"): a
#: leg whose joint stiffness is spring-like (muscles as springs across one or two joints, feedback about each
#: joint) has a positive semi-definite stiffness matrix, so |K_hip_knee| <= sqrt(K_hip K_knee), at most the
#: stiffness bound's upper end; either sign: rectus femoris and the hamstrings (each flexing one joint and
#: extending the other) give a negative coupling, sartorius and gracilis (flexing both) a positive one.
COUPLING_BOUNDS_NM_PER_RAD: tuple[float, float] = (-200.0, 200.0)
#: Default bounds (K N m/rad, D N m s/rad), order of :data:`PARAMETERS` (:func:`parameter_bounds` of the two above).
DEFAULT_LOWER = np.array([STIFFNESS_BOUNDS_NM_PER_RAD[0], DAMPING_BOUNDS_NMS_PER_RAD[0]] * 3, float)
DEFAULT_UPPER = np.array([STIFFNESS_BOUNDS_NM_PER_RAD[1], DAMPING_BOUNDS_NMS_PER_RAD[1]] * 3, float)


def check_couplings(couplings) -> tuple[str, ...]:
    """Inter-joint couplings as a tuple in the order of :data:`~loper_analysis.constants.COUPLINGS`.

    ``couplings``: an iterable of their names (``"hip_knee"``, ``"knee_ankle"``) or of their parameter names
    (``"K_hip_knee"``, ...); each at most once.

    Raises
    ------
    LoperInputError
        An unknown name, a repeated one, or a plain string instead of a collection of names.
    """
    if isinstance(couplings, str):
        raise LoperInputError(f"couplings must be a collection of names from {COUPLINGS}, got the string {couplings!r}")
    names = [c[2:] if c in COUPLING_PARAMETERS else c for c in couplings]
    unknown = [c for c in names if c not in COUPLINGS]
    if unknown:
        raise LoperInputError(f"unknown inter-joint coupling(s) {unknown}; known: {', '.join(COUPLINGS)}")
    if len(set(names)) != len(names):
        raise LoperInputError(f"an inter-joint coupling is named twice: {list(couplings)}")
    return tuple(c for c in COUPLINGS if c in names)


def parameter_names(couplings=()) -> tuple[str, ...]:
    """Names of a parameter vector's entries: :data:`PARAMETERS`, then ``K_<coupling>`` per coupling (in the order
    of :data:`~loper_analysis.constants.COUPLINGS`)."""
    return PARAMETERS + tuple(f"K_{c}" for c in check_couplings(couplings))


def parameter_bounds(
    stiffness_bounds, damping_bounds, couplings=(), coupling_bounds=COUPLING_BOUNDS_NM_PER_RAD
) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds (p,) in the order of :data:`PARAMETERS` from one (low, high) pair for every K
    (N·m/rad) and one for every D (N·m·s/rad), then ``coupling_bounds`` (low, high; N·m/rad) for each of the
    inter-joint ``couplings`` (p = 6 + their number)."""
    k, d = tuple(stiffness_bounds), tuple(damping_bounds)
    n = len(check_couplings(couplings))
    c = tuple(coupling_bounds)
    return np.array([k[0], d[0]] * 3 + [c[0]] * n, float), np.array([k[1], d[1]] * 3 + [c[1]] * n, float)


class FitBounds:
    """Base of a settings dataclass that holds the fit's bounds: its K and D bound vectors.

    The subclass has the fields ``stiffness_bounds_nm_per_rad`` (low, high; N·m/rad, every K) and
    ``damping_bounds_nms_per_rad`` (low, high; N·m·s/rad, every D), and may have ``couplings`` (inter-joint
    couplings fitted besides them) and ``coupling_bounds_nm_per_rad`` (low, high; N·m/rad, default
    :data:`COUPLING_BOUNDS_NM_PER_RAD`); :attr:`lower` and :attr:`upper` are the bounds (p,) in the order of
    :data:`PARAMETERS`, then the couplings' (:func:`parameter_bounds`).
    """

    stiffness_bounds_nm_per_rad: tuple[float, float]
    damping_bounds_nms_per_rad: tuple[float, float]

    def _bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return parameter_bounds(
            self.stiffness_bounds_nm_per_rad,
            self.damping_bounds_nms_per_rad,
            getattr(self, "couplings", ()),
            getattr(self, "coupling_bounds_nm_per_rad", COUPLING_BOUNDS_NM_PER_RAD),
        )

    @property
    def lower(self) -> np.ndarray:
        return self._bounds()[0]

    @property
    def upper(self) -> np.ndarray:
        return self._bounds()[1]


def check_bounds(lower, upper, parameters: tuple[str, ...] = PARAMETERS) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds as (p,) arrays, p = ``len(parameters)`` (names for the messages), each finite and
    lower below upper."""
    lb = np.asarray(lower, dtype=float)
    ub = np.asarray(upper, dtype=float)
    n = len(parameters)
    for name, b in (("lower", lb), ("upper", ub)):
        if b.shape != (n,) or not np.all(np.isfinite(b)):
            raise LoperInputError(f"{name} bounds must be {n} finite values ({', '.join(parameters)}), got {b}")
    bad = np.flatnonzero(lb >= ub)
    if bad.size:
        i = bad[0]
        raise LoperInputError(f"bounds of {parameters[i]}: lower {lb[i]} must be below upper {ub[i]}")
    return lb, ub


def fit_bounds(lower, upper, couplings=()) -> tuple[np.ndarray, np.ndarray]:
    """The bounds (p,) of a fit with the inter-joint ``couplings``, checked (:func:`check_bounds`).

    ``lower``, ``upper``: (6 + number of couplings,) values, or the six of K and D alone, to which each
    coupling's :data:`COUPLING_BOUNDS_NM_PER_RAD` is appended.
    """
    couplings = check_couplings(couplings)
    names = parameter_names(couplings)
    lb = np.asarray(lower, dtype=float)
    ub = np.asarray(upper, dtype=float)
    if couplings and lb.shape == (len(PARAMETERS),) and ub.shape == (len(PARAMETERS),):
        lb = np.concatenate([lb, np.full(len(couplings), COUPLING_BOUNDS_NM_PER_RAD[0])])
        ub = np.concatenate([ub, np.full(len(couplings), COUPLING_BOUNDS_NM_PER_RAD[1])])
    return check_bounds(lb, ub, names)
