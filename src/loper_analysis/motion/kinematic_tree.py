"""An OpenSim model's kinematic tree as arrays, for marker kinematics without a call into OpenSim per frame.

:func:`kinematic_tree` reads, once, what the markers' positions depend on: each joint's parent and child
offset frames, its six spatial-transform axes with the function of its coordinate that each follows, and
each marker's body and location. :func:`tree_markers` then gives every marker's position in ground and its
Jacobian with respect to the coordinates in one compiled pass (:mod:`loper_analysis.swing_leg.kernels`
style: numba, no Python objects), which is what the fast IK solver iterates on
(:mod:`loper_analysis.motion.tree_ik`).

What the tree holds
-------------------
* Joints: ``CustomJoint`` (OpenSim's ``SpatialTransform``: three rotations, applied one after the other
  about axes fixed in the joint's parent frame and carried by the rotations before them, then three
  translations along axes of the parent frame), ``PinJoint`` (rotation about the parent frame's z),
  ``SliderJoint`` (translation along x), ``PlanarJoint`` (rotation about z, translation along x and y),
  ``UniversalJoint`` (about x, then the turned y), ``GimbalJoint`` (about x, y, z, each turned by the ones
  before) and ``WeldJoint``.
* Constraints: ``CoordinateCouplerConstraint`` of one independent coordinate (Rajagopal2016's patellae).
* Functions of one coordinate: ``Constant``, ``LinearFunction``, ``MultiplierFunction`` of those, and
  piecewise cubic splines (``SimmSpline``, ``NaturalCubicSpline``), whose coefficients are read from
  OpenSim's own values and derivatives at the knots, extrapolated linearly beyond the ends as OpenSim does.

A model with anything else (another joint type, a function of another kind, another constraint) raises
:class:`UnsupportedModel`, and so does a model whose marker positions from the tree
differ from OpenSim's by more than :data:`CHECK_TOLERANCE_M` at the poses of :func:`check_against_opensim`;
the IK then falls back on OpenSim's solver.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import model_source, quiet_opensim

__all__ = [
    "CHECK_TOLERANCE_M",
    "UnsupportedModel",
    "KinematicTree",
    "kinematic_tree",
    "tree_markers",
    "check_against_opensim",
]

#: Largest difference (m) between a marker's position from the tree and from OpenSim that the check accepts.
CHECK_TOLERANCE_M: float = 1e-9

#: Function kinds of a transform axis.
_CONSTANT, _LINEAR, _SPLINE = 0, 1, 2


class UnsupportedModel(LoperInputError):
    """A model whose kinematics the tree does not reproduce (joint type, function, constraint)."""


@dataclass(frozen=True)
class KinematicTree:
    """Arrays of a model's kinematic tree; bodies in the order of OpenSim's joint set (parents first).

    Shapes: ``nb`` bodies (one joint each), ``nm`` markers, ``nc`` coordinates, ``nk`` spline pieces.
    ``parent`` (nb,) index of the parent body (-1: ground); ``X_PF`` (nb, 4, 4) the joint's parent frame in
    the parent body; ``X_MB`` (nb, 4, 4) the child body in the joint's child frame; ``axes`` (nb, 6, 3) unit
    axes of the three rotations and three translations; ``kind`` (nb, 6) function kind; ``coordinate``
    (nb, 6) index of the coordinate each axis follows (-1: none); ``linear`` (nb, 6, 2) constant value, or
    slope and intercept; ``piece0``/``n_pieces`` (nb, 6) the axis's spline pieces in ``knots`` (nk,) and
    ``coefficients`` (nk, 4) (value, slope, curvature/2, third derivative/6 at the piece's left knot);
    ``coupled`` (n_coupled, 2) the dependent and independent coordinate of each ``CoordinateCouplerConstraint``,
    whose function ``coupled_kind``, ``coupled_linear``, ``coupled_piece0``, ``coupled_n_pieces`` describe as
    the axes' do; ``marker_body`` (nm,), ``marker_location_m`` (nm, 3) in the body; ``coordinate_names``,
    ``marker_names``, ``body_names``; ``default_q`` (nc,), ``range_q`` (nc, 2), ``clamped``/``locked``
    (nc,) bool.
    """

    parent: np.ndarray
    X_PF: np.ndarray
    X_MB: np.ndarray
    axes: np.ndarray
    kind: np.ndarray
    coordinate: np.ndarray
    linear: np.ndarray
    piece0: np.ndarray
    n_pieces: np.ndarray
    knots: np.ndarray
    coefficients: np.ndarray
    coupled: np.ndarray
    coupled_kind: np.ndarray
    coupled_linear: np.ndarray
    coupled_piece0: np.ndarray
    coupled_n_pieces: np.ndarray
    marker_body: np.ndarray
    marker_location_m: np.ndarray
    coordinate_names: tuple[str, ...]
    marker_names: tuple[str, ...]
    body_names: tuple[str, ...]
    default_q: np.ndarray
    range_q: np.ndarray
    clamped: np.ndarray
    locked: np.ndarray

    def markers(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every marker's ground position (nm, 3) in m and its Jacobian (nm, 3, nc) at coordinates ``q`` (nc,)."""
        P = np.empty((self.marker_body.size, 3))
        J = np.zeros((self.marker_body.size, 3, len(self.coordinate_names)))
        tree_markers(self.kernel_arrays(), np.array(q, float), P, J)
        return P, J

    def positions(self, Q: np.ndarray) -> np.ndarray:
        """Every marker's ground position (n, nm, 3) in m at each row of ``Q`` (n, nc), taken as given: coupled
        coordinates where ``Q`` puts them, as OpenSim places markers for coordinates set without enforcing the
        constraints."""
        Q = np.ascontiguousarray(Q, dtype=float)
        P = np.empty((Q.shape[0], self.marker_body.size, 3))
        tree_marker_positions(self.kernel_arrays(), Q, P)
        return P

    def poses(self, values: dict[str, np.ndarray], n: int) -> np.ndarray:
        """Coordinates (n, nc) for trajectories ``values`` (name -> (n,) or (1,), rad or m), the others at their
        defaults, as OpenSim's ``Coordinate.setValue`` sets them: a locked coordinate left at its default, a
        clamped one as given (``setValue`` does not clamp)."""
        Q = np.tile(self.default_q, (n, 1))
        for name, v in values.items():
            Q[:, self.coordinate_names.index(name)] = v
        Q[:, self.locked] = self.default_q[self.locked]
        return Q

    def kernel_arrays(self) -> tuple:
        """The arrays :func:`tree_markers` takes, in its order."""
        return (
            self.parent,
            np.ascontiguousarray(self.X_PF[:, :3, :3]),
            np.ascontiguousarray(self.X_PF[:, :3, 3]),
            np.ascontiguousarray(self.X_MB[:, :3, :3]),
            np.ascontiguousarray(self.X_MB[:, :3, 3]),
            self.axes,
            self.kind,
            self.coordinate,
            self.linear,
            self.piece0,
            self.n_pieces,
            self.knots,
            self.coefficients,
            self.coupled,
            self.coupled_kind,
            self.coupled_linear,
            self.coupled_piece0,
            self.coupled_n_pieces,
            self.marker_body,
            self.marker_location_m,
        )

    @property
    def dependent(self) -> np.ndarray:
        """Whether each coordinate (nc,) follows another through a coupler constraint."""
        out = np.zeros(len(self.coordinate_names), bool)
        out[self.coupled[:, 0]] = True
        return out


def _transform(osim_transform) -> np.ndarray:
    """A SimTK ``Transform`` as a homogeneous matrix (4, 4)."""
    X = np.eye(4)
    R = osim_transform.R()
    X[:3, :3] = [[R.get(i, j) for j in range(3)] for i in range(3)]
    X[:3, 3] = osim_transform.p().to_numpy()
    return X


def _inverse(X: np.ndarray) -> np.ndarray:
    """Inverse of a rigid transform (4, 4)."""
    out = np.eye(4)
    out[:3, :3] = X[:3, :3].T
    out[:3, 3] = -X[:3, :3].T @ X[:3, 3]
    return out


def _function_spec(osim, function, source: str) -> tuple[int, tuple[float, float], list[float], list[list[float]]]:
    """(kind, (constant or slope, intercept), knots, coefficients) of an OpenSim function of one coordinate."""
    name = function.getConcreteClassName()
    if name == "Constant":
        return _CONSTANT, (osim.Constant.safeDownCast(function).getValue(), 0.0), [], []
    if name == "LinearFunction":
        f = osim.LinearFunction.safeDownCast(function)
        return _LINEAR, (f.getSlope(), f.getIntercept()), [], []
    if name == "MultiplierFunction":
        f = osim.MultiplierFunction.safeDownCast(function)
        kind, (a, b), knots, coefficients = _function_spec(osim, f.getFunction(), source)
        scale = f.getScale()
        if kind == _CONSTANT:
            return kind, (scale * a, 0.0), [], []
        return kind, (scale * a, scale * b), knots, [[scale * c for c in row] for row in coefficients]
    if name in ("SimmSpline", "NaturalCubicSpline"):
        spline = getattr(osim, name).safeDownCast(function)
        x = [spline.getX(i) for i in range(spline.getSize())]
        rows = []
        for xk in x:  # value, slope and curvature / 2 at each knot, from OpenSim
            arg = osim.Vector(1, xk)
            rows.append(
                [
                    function.calcValue(arg),
                    function.calcDerivative(osim.StdVectorInt([0]), arg),
                    function.calcDerivative(osim.StdVectorInt([0, 0]), arg) / 2.0,
                    0.0,
                ]
            )
        for k in range(len(x) - 1):  # the cubic term: the piece ends at the next knot's value
            h = x[k + 1] - x[k]
            a, b, c, _ = rows[k]
            rows[k][3] = (rows[k + 1][0] - a - b * h - c * h * h) / h**3
        return _SPLINE, (0.0, 0.0), x, rows
    raise UnsupportedModel(f"{source}: a joint follows a {name}, which the kinematic tree does not evaluate")


def _joint_axes(osim, joint, coordinate_index: dict[str, int], source: str) -> list[tuple]:
    """Six (axis, kind, coordinate, (a, b), knots, coefficients) of a joint, rotations first."""
    kind = joint.getConcreteClassName()
    coords = [joint.get_coordinates(i).getName() for i in range(joint.numCoordinates())]
    zero = (np.zeros(3), _CONSTANT, -1, (0.0, 0.0), [], [])

    def follow(axis, i):
        return (np.asarray(axis, float), _LINEAR, coordinate_index[coords[i]], (1.0, 0.0), [], [])

    unit = np.eye(3)
    if kind == "WeldJoint":
        return [zero] * 6
    if kind == "PinJoint":
        return [follow(unit[2], 0), zero, zero, zero, zero, zero]
    if kind == "SliderJoint":
        return [zero, zero, zero, follow(unit[0], 0), zero, zero]
    if kind == "UniversalJoint":
        return [follow(unit[0], 0), follow(unit[1], 1), zero, zero, zero, zero]
    if kind == "GimbalJoint":
        return [follow(unit[0], 0), follow(unit[1], 1), follow(unit[2], 2), zero, zero, zero]
    if kind == "PlanarJoint":
        return [follow(unit[2], 0), zero, zero, follow(unit[0], 1), follow(unit[1], 2), zero]
    if kind != "CustomJoint":
        raise UnsupportedModel(
            f"{source}: joint '{joint.getName()}' is a {kind}, which the kinematic tree does not hold"
        )
    transform = osim.CustomJoint.safeDownCast(joint).getSpatialTransform()
    out = []
    for i in range(6):
        axis = transform.getTransformAxis(i)
        names = axis.getCoordinateNames()
        if names.size() > 1:
            raise UnsupportedModel(f"{source}: joint '{joint.getName()}' axis {i} follows more than one coordinate")
        function_kind, ab, knots, coefficients = _function_spec(osim, axis.getFunction(), source)
        c = coordinate_index[names.getValue(0)] if names.size() else -1
        if c < 0 and function_kind != _CONSTANT:
            raise UnsupportedModel(f"{source}: joint '{joint.getName()}' axis {i} has a function but no coordinate")
        direction = axis.getAxis().to_numpy()
        out.append((direction / np.linalg.norm(direction), function_kind, c, ab, knots, coefficients))
    return out


def _couplers(osim, model, coordinate_index: dict[str, int], source: str) -> tuple[list, list]:
    """The (dependent, independent) coordinate pairs of the model's constraints and their functions' specs."""
    constraints = model.getConstraintSet()
    pairs, specs = [], []
    for i in range(constraints.getSize()):
        constraint = constraints.get(i)
        coupler = osim.CoordinateCouplerConstraint.safeDownCast(constraint)
        if coupler is None:
            raise UnsupportedModel(
                f"{source}: constraint '{constraint.getName()}' is a {constraint.getConcreteClassName()}; "
                "the kinematic tree holds coordinate couplers only"
            )
        independent = coupler.getIndependentCoordinateNames()
        if independent.getSize() != 1:
            raise UnsupportedModel(f"{source}: coupler '{constraint.getName()}' follows more than one coordinate")
        pairs.append((coordinate_index[coupler.getDependentCoordinateName()], coordinate_index[independent.get(0)]))
        specs.append(_function_spec(osim, coupler.getFunction(), source))
    if {d for d, _ in pairs} & {i for _, i in pairs}:
        raise UnsupportedModel(f"{source}: a coupled coordinate drives another coupler")
    return pairs, specs


def kinematic_tree(model) -> KinematicTree:
    """The kinematic tree of an ``opensim.Model`` (initialised), for :func:`tree_markers`.

    Raises
    ------
    UnsupportedModel
        A joint type, function or constraint the tree does not reproduce (constraints other than
        coordinate couplers of one coordinate), or a joint whose parent comes
        after it in the joint set.
    """
    osim = quiet_opensim()
    source = model_source(model)
    cs = model.getCoordinateSet()
    coordinate_names = tuple(cs.get(i).getName() for i in range(cs.getSize()))
    coordinate_index = {c: i for i, c in enumerate(coordinate_names)}
    joints = model.getJointSet()
    body_names, parent, X_PF, X_MB, rows = [], [], [], [], []
    for j in range(joints.getSize()):
        joint = joints.get(j)
        base = joint.getParentFrame().findBaseFrame().getName()
        if base != "ground" and base not in body_names:
            raise UnsupportedModel(f"{source}: joint '{joint.getName()}' comes before its parent body '{base}'")
        parent.append(-1 if base == "ground" else body_names.index(base))
        body_names.append(joint.getChildFrame().findBaseFrame().getName())
        X_PF.append(_transform(joint.getParentFrame().findTransformInBaseFrame()))
        X_MB.append(_inverse(_transform(joint.getChildFrame().findTransformInBaseFrame())))
        rows.append(_joint_axes(osim, joint, coordinate_index, source))
    nb = len(body_names)
    axes, kind, coordinate = np.zeros((nb, 6, 3)), np.zeros((nb, 6), np.int64), np.full((nb, 6), -1, np.int64)
    linear, piece0, n_pieces = np.zeros((nb, 6, 2)), np.zeros((nb, 6), np.int64), np.zeros((nb, 6), np.int64)
    knots, coefficients = [], []
    for b, row in enumerate(rows):
        for i, (axis, k, c, ab, x, coef) in enumerate(row):
            axes[b, i], kind[b, i], coordinate[b, i], linear[b, i] = axis, k, c, ab
            piece0[b, i], n_pieces[b, i] = len(knots), len(x)
            knots += x
            coefficients += coef
    coupled, coupled_specs = _couplers(osim, model, coordinate_index, source)
    coupled_piece0 = []
    for _, _, x, coef in coupled_specs:
        coupled_piece0.append(len(knots))
        knots += x
        coefficients += coef
    ms = model.getMarkerSet()
    marker_names = tuple(ms.get(i).getName() for i in range(ms.getSize()))
    marker_body, marker_location = [], []
    for i in range(ms.getSize()):
        frame = ms.get(i).getParentFrame()
        base = frame.findBaseFrame().getName()
        if base not in body_names:
            raise UnsupportedModel(f"{source}: marker '{marker_names[i]}' sits on '{base}', not a jointed body")
        marker_body.append(body_names.index(base))
        X = _transform(frame.findTransformInBaseFrame())
        marker_location.append(X[:3, :3] @ ms.get(i).get_location().to_numpy() + X[:3, 3])
    return KinematicTree(
        parent=np.asarray(parent, np.int64),
        X_PF=np.asarray(X_PF),
        X_MB=np.asarray(X_MB),
        axes=axes,
        kind=kind,
        coordinate=coordinate,
        linear=linear,
        piece0=piece0,
        n_pieces=n_pieces,
        knots=np.asarray(knots, float),
        coefficients=np.asarray(coefficients, float).reshape(-1, 4),
        coupled=np.asarray(coupled, np.int64).reshape(-1, 2),
        coupled_kind=np.array([k for k, _, _, _ in coupled_specs], np.int64),
        coupled_linear=np.array([ab for _, ab, _, _ in coupled_specs], float).reshape(-1, 2),
        coupled_piece0=np.array(coupled_piece0, np.int64),
        coupled_n_pieces=np.array([len(x) for _, _, x, _ in coupled_specs], np.int64),
        marker_body=np.asarray(marker_body, np.int64),
        marker_location_m=np.asarray(marker_location, float).reshape(-1, 3),
        coordinate_names=coordinate_names,
        marker_names=marker_names,
        body_names=tuple(body_names),
        default_q=np.array([cs.get(i).getDefaultValue() for i in range(cs.getSize())]),
        range_q=np.array([[cs.get(i).getRangeMin(), cs.get(i).getRangeMax()] for i in range(cs.getSize())]),
        clamped=np.array([cs.get(i).getDefaultClamped() for i in range(cs.getSize())], bool),
        locked=np.array([cs.get(i).getDefaultLocked() for i in range(cs.getSize())], bool),
    )


@njit(cache=True)
def _axis_value(kind, linear, piece0, n_pieces, knots, coefficients, x):  # pragma: no cover - compiled
    """Value and derivative of one transform axis's function at coordinate value ``x``."""
    if kind == _CONSTANT:
        return linear[0], 0.0
    if kind == _LINEAR:
        return linear[0] * x + linear[1], linear[0]
    first, last = piece0, piece0 + n_pieces - 1
    if x <= knots[first]:
        return coefficients[first, 0] + (x - knots[first]) * coefficients[first, 1], coefficients[first, 1]
    if x >= knots[last]:
        return coefficients[last, 0] + (x - knots[last]) * coefficients[last, 1], coefficients[last, 1]
    k = first
    while k < last - 1 and x >= knots[k + 1]:
        k += 1
    d = x - knots[k]
    a, b, c, e = coefficients[k, 0], coefficients[k, 1], coefficients[k, 2], coefficients[k, 3]
    return a + d * (b + d * (c + d * e)), b + d * (2.0 * c + 3.0 * d * e)


@njit(cache=True)
def _rotation(axis, angle, R):  # pragma: no cover - compiled
    """Rotation matrix ``R`` (3, 3), written in place, of ``angle`` rad about the unit ``axis`` (Rodrigues)."""
    c, s = np.cos(angle), np.sin(angle)
    x, y, z = axis[0], axis[1], axis[2]
    C = 1.0 - c
    R[0, 0], R[0, 1], R[0, 2] = c + x * x * C, x * y * C - z * s, x * z * C + y * s
    R[1, 0], R[1, 1], R[1, 2] = y * x * C + z * s, c + y * y * C, y * z * C - x * s
    R[2, 0], R[2, 1], R[2, 2] = z * x * C - y * s, z * y * C + x * s, c + z * z * C


# The products of 3 x 3 matrices and 3-vectors are written out: NumPy's ``@`` on arrays this small costs a
# call into BLAS each, several times the arithmetic.
@njit(cache=True)
def _times_matrix(A, B, out):  # pragma: no cover - compiled
    """``out`` = ``A`` @ ``B`` for (3, 3) matrices (``out`` distinct from both)."""
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]


@njit(cache=True)
def _times_vector(A, v, out):  # pragma: no cover - compiled
    """``out`` = ``A`` @ ``v`` for a (3, 3) matrix and a 3-vector (``out`` distinct from ``v``)."""
    for i in range(3):
        out[i] = A[i, 0] * v[0] + A[i, 1] * v[1] + A[i, 2] * v[2]


@njit(cache=True)
def _body_frames(arrays, q):  # pragma: no cover - compiled
    """Each body's orientation (nb, 3, 3) and origin (nb, 3) in ground, its joint axes' directions in ground
    (nb, 6, 3; a rotation's after the rotations before it), the point its rotations turn about (nb, 3: the
    origin of the joint's child frame) and each axis function's derivative (nb, 6), at coordinates ``q``."""
    parent, R_PF, p_PF, R_MB, p_MB, axes, kind, coordinate, linear, piece0, n_pieces, knots, coefficients = arrays[:13]
    nb = parent.size
    R_G, o_G = np.empty((nb, 3, 3)), np.empty((nb, 3))
    w_G, c_G, slope = np.zeros((nb, 6, 3)), np.empty((nb, 3)), np.zeros((nb, 6))
    R_F, R, R_turned, turn, R_M = (
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty((3, 3)),
    )
    o_F, p, v, u = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    for b in range(nb):
        if parent[b] < 0:
            R_F[:] = R_PF[b]
            o_F[:] = p_PF[b]
        else:
            _times_matrix(R_G[parent[b]], R_PF[b], R_F)
            _times_vector(R_G[parent[b]], p_PF[b], v)
            o_F[:] = o_G[parent[b]] + v
        R[:] = 0.0
        R[0, 0] = R[1, 1] = R[2, 2] = 1.0
        p[:] = 0.0
        for i in range(6):
            x = q[coordinate[b, i]] if coordinate[b, i] >= 0 else 0.0
            value, slope[b, i] = _axis_value(
                kind[b, i], linear[b, i], piece0[b, i], n_pieces[b, i], knots, coefficients, x
            )
            if i < 3:  # rotations, each about its axis as the ones before have turned it
                _times_vector(R, axes[b, i], u)
                _times_vector(R_F, u, w_G[b, i])
                _rotation(axes[b, i], value, turn)
                _times_matrix(R, turn, R_turned)
                R[:] = R_turned
            else:  # translations along the parent frame's axes
                p += value * axes[b, i]
                _times_vector(R_F, axes[b, i], w_G[b, i])
        _times_matrix(R_F, R, R_M)
        _times_vector(R_F, p, v)
        c_G[b] = o_F + v
        _times_matrix(R_M, R_MB[b], R_G[b])
        _times_vector(R_M, p_MB[b], v)
        o_G[b] = c_G[b] + v
    return R_G, o_G, w_G, c_G, slope


@njit(cache=True)
def tree_markers(arrays, q, P, J):  # pragma: no cover - compiled
    """Marker positions ``P`` (nm, 3) in m and Jacobian ``J`` (nm, 3, nc), written in place, at ``q`` (nc,).

    ``arrays`` is :meth:`KinematicTree.kernel_arrays`. ``J`` must hold zeros on entry. The coupled coordinates
    of ``q`` are set from their independent ones, and their Jacobian columns folded into those.
    """
    parent, coordinate, knots, coefficients = arrays[0], arrays[7], arrays[11], arrays[12]
    coupled, coupled_kind, coupled_linear, coupled_piece0, coupled_n_pieces, marker_body, marker_location = arrays[13:]
    coupled_slope = np.empty(coupled.shape[0])
    for k in range(coupled.shape[0]):  # a coupled coordinate follows its independent one (q changes in place)
        q[coupled[k, 0]], coupled_slope[k] = _axis_value(
            coupled_kind[k],
            coupled_linear[k],
            coupled_piece0[k],
            coupled_n_pieces[k],
            knots,
            coefficients,
            q[coupled[k, 1]],
        )
    R_G, o_G, w_G, c_G, slope = _body_frames(arrays, q)
    for m in range(marker_body.size):
        b = marker_body[m]
        _times_vector(R_G[b], marker_location[m], P[m])
        P[m] += o_G[b]
        while b >= 0:
            for i in range(6):
                c = coordinate[b, i]
                if c < 0 or slope[b, i] == 0.0:
                    continue
                if i < 3:  # d/da of a rotation about w through c_G: w x (P - c_G)
                    r = P[m] - c_G[b]
                    w = w_G[b, i]
                    J[m, 0, c] += slope[b, i] * (w[1] * r[2] - w[2] * r[1])
                    J[m, 1, c] += slope[b, i] * (w[2] * r[0] - w[0] * r[2])
                    J[m, 2, c] += slope[b, i] * (w[0] * r[1] - w[1] * r[0])
                else:
                    J[m, :, c] += slope[b, i] * w_G[b, i]
            b = parent[b]
        for k in range(coupled.shape[0]):  # the chain rule through the couplers
            J[m, :, coupled[k, 1]] += coupled_slope[k] * J[m, :, coupled[k, 0]]
            J[m, :, coupled[k, 0]] = 0.0


@njit(cache=True)
def tree_marker_positions(arrays, Q, P):  # pragma: no cover - compiled
    """Marker positions ``P`` (n, nm, 3) in m, written in place, at each row of ``Q`` (n, nc) as given.

    ``arrays`` is :meth:`KinematicTree.kernel_arrays`.
    """
    marker_body, marker_location = arrays[18], arrays[19]
    for k in range(Q.shape[0]):
        R_G, o_G, _, _, _ = _body_frames(arrays, Q[k])
        for m in range(marker_body.size):
            b = marker_body[m]
            _times_vector(R_G[b], marker_location[m], P[k, m])
            P[k, m] += o_G[b]


def _coupled_values(tree: KinematicTree, q: np.ndarray) -> list[tuple[int, int, float]]:
    """(dependent, independent, value) of each coupler at coordinates ``q`` (nc,)."""
    out = []
    for k, (dependent, independent) in enumerate(tree.coupled):
        value, _ = _axis_value(
            tree.coupled_kind[k],
            tree.coupled_linear[k],
            tree.coupled_piece0[k],
            tree.coupled_n_pieces[k],
            tree.knots,
            tree.coefficients,
            q[independent],
        )
        out.append((int(dependent), int(independent), float(value)))
    return out


def check_against_opensim(model, tree: KinematicTree, n_poses: int = 8, seed: int = 0) -> float:
    """Largest distance (m) between the tree's marker positions and OpenSim's at ``n_poses`` poses.

    The poses are the default pose and poses drawn uniformly within each coordinate's range (reproducibly,
    from ``seed``), locked coordinates at their defaults and coupled ones following their couplers. Raises
    :class:`UnsupportedModel` when the distance exceeds :data:`CHECK_TOLERANCE_M`.
    """
    from loper_analysis.motion.opensim_ik import opensim_marker_positions

    rng = np.random.default_rng(seed)
    lo, hi = tree.range_q[:, 0], tree.range_q[:, 1]
    poses = [tree.default_q] + [lo + (hi - lo) * rng.random(lo.size) for _ in range(n_poses - 1)]
    Q = np.asarray(poses)
    Q[:, tree.locked] = tree.default_q[tree.locked]  # OpenSim keeps a locked coordinate where it is
    for q in Q:  # coupled coordinates follow their independent ones
        for dependent, _, value in _coupled_values(tree, q):
            q[dependent] = value
    expected = opensim_marker_positions(model, dict(zip(tree.coordinate_names, Q.T)), list(tree.marker_names))
    worst = max(float(np.abs(tree.markers(q)[0] - e).max()) for q, e in zip(Q, expected))
    if not worst <= CHECK_TOLERANCE_M:
        raise UnsupportedModel(
            f"{model_source(model)}: the kinematic tree places markers up to {worst:.3g} m from OpenSim's"
        )
    return worst
