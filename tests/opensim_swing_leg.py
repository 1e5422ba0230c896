"""The planar swing leg built in OpenSim (Simbody), for peer-engine tests.

:class:`OpenSimLeg` is the mechanism of ``docs/swing_leg_model.md``::

    ground -SliderJoint(X)-> cart -PinJoint(Z)-> thigh -PinJoint(Z)-> shank -PinJoint(Z)-> foot

OpenSim uses relative, counter-clockwise joint angles ``phi``; our model uses
global, clockwise segment angles ``q``::

    phi_x = x,  phi_1 = -q_1,  phi_2 = -(q_2 - q_1),  phi_3 = -(q_3 - q_2)

so ``q = A phi`` with the constant matrix ``A`` below. Then ``q' = A phi'``,
``q'' = A phi''``, the generalised forces map by virtual work as
``tau_phi = A^T u`` and the mass matrices as ``M_phi = A^T M_q A``.
In joint angles (pelvis angle zero): ``phi_1 = theta_hip``,
``phi_2 = -theta_knee``, ``phi_3 = theta_ankle``.

Generalised forces enter through CoordinateActuators and the rod force
``F = (F_x, F_y)`` through two PointActuators at the body point
``(0, -attachment_m)`` of the thigh with the direction fixed in ground (and,
for parameters with a ``shank_attachment_m``, a second rod's through two more
at ``(0, -shank_attachment_m)`` of the shank); all use optimal force 1 and the
actuation override, a discrete state variable that holds the value during a
Manager integration.

:class:`PerturbedSwingLeg` (further below) is the perturbed swing with joint
impedance feedback, built from OpenSim components only.
"""

from __future__ import annotations

import numpy as np
import opensim as osim

from loper_analysis.swing_leg.dynamics import SegmentParameters

osim.Logger.setLevelString("error")
osim.Logger.removeFileSink()

# q = A phi (phi: OpenSim coordinates in mobility order slider, hip pin, knee pin, ankle pin)
A = np.array(
    [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, -1.0, 0.0, 0.0],
        [0.0, -1.0, -1.0, 0.0],
        [0.0, -1.0, -1.0, -1.0],
    ]
)
A_INV = np.linalg.inv(A)

SEGMENT_NAMES = ("thigh", "shank", "foot")


class OpenSimLeg:
    """The swing-leg model built in OpenSim, with conversion to our coordinates."""

    def __init__(self, p: SegmentParameters):
        model = osim.Model()
        model.setName("swing_leg")
        model.setGravity(osim.Vec3(0.0, -p.gravity_m_per_s2, 0.0))
        # the cart only translates: its inertia is irrelevant but must be valid
        cart = osim.Body("cart", p.cart_mass_kg, osim.Vec3(0.0), osim.Inertia(1.0, 1.0, 1.0))
        model.addBody(cart)
        model.addJoint(
            osim.SliderJoint(
                "slider", model.getGround(), osim.Vec3(0.0), osim.Vec3(0.0), cart, osim.Vec3(0.0), osim.Vec3(0.0)
            )
        )
        parent, parent_loc = cart, osim.Vec3(0.0)
        for i, name in enumerate(SEGMENT_NAMES):
            body = osim.Body(
                name,
                p.mass_kg[i],
                osim.Vec3(p.com_x_m[i], p.com_y_m[i], 0.0),
                # Ixx, Iyy do not matter for planar motion about Z
                osim.Inertia(0.3, 0.2, p.inertia_kg_m2[i]),
            )
            model.addBody(body)
            model.addJoint(
                osim.PinJoint(f"{name}_pin", parent, parent_loc, osim.Vec3(0.0), body, osim.Vec3(0.0), osim.Vec3(0.0))
            )
            parent, parent_loc = body, osim.Vec3(0.0, -p.length_m[i], 0.0)

        self.coord_actuators = []
        for k in range(4):
            coord = model.getJointSet().get(k).get_coordinates(0)
            act = osim.CoordinateActuator(coord.getName())
            act.setName(f"tau_{k}")
            act.setOptimalForce(1.0)
            act.setMinControl(-np.inf)
            act.setMaxControl(np.inf)
            model.addForce(act)
            self.coord_actuators.append(act)
        self.force_actuators = []
        rods = [("thigh", "rod_force", p.attachment_m)]
        if p.shank_attachment_m is not None:
            rods.append(("shank", "shank_rod_force", p.shank_attachment_m))
        for body, name, distance in rods:
            for k, direction in enumerate(((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))):
                act = osim.PointActuator(body)
                act.setName(f"{name}_{'xy'[k]}")
                act.set_point(osim.Vec3(0.0, -distance, 0.0))
                act.set_point_is_global(False)
                act.set_direction(osim.Vec3(*direction))
                act.set_force_is_global(True)
                act.setOptimalForce(1.0)
                act.setMinControl(-np.inf)
                act.setMaxControl(np.inf)
                model.addForce(act)
                self.force_actuators.append(act)

        self.state = model.initSystem()
        self.model = model
        self.params = p
        # mobility order must be slider, hip, knee, ankle for the mapping A
        names = [model.getCoordinateSet().get(k).getName() for k in range(4)]
        assert names == [model.getJointSet().get(k).get_coordinates(0).getName() for k in range(4)]
        for act in (*self.coord_actuators, *self.force_actuators):
            act.overrideActuation(self.state, True)

    # ------------------------------------------------------------ state

    def set_state(self, q, qd, u=None, force=None, shank_force=None) -> None:
        u = np.zeros(4) if u is None else u
        force = np.zeros(2) if force is None else force
        if len(self.force_actuators) == 4:
            force = np.r_[force, np.zeros(2) if shank_force is None else shank_force]
        s = self.state
        s.setTime(0.0)
        s.setQ(osim.Vector([float(v) for v in A_INV @ q]))
        s.setU(osim.Vector([float(v) for v in A_INV @ qd]))
        tau = A.T @ np.asarray(u, dtype=float)  # virtual work: tau_phi = (dq/dphi)^T u
        for act, val in zip(self.coord_actuators, tau):
            act.setOverrideActuation(s, float(val))
        for act, val in zip(self.force_actuators, force):
            act.setOverrideActuation(s, float(val))

    def q(self, s=None) -> np.ndarray:
        s = self.state if s is None else s
        return A @ np.array([s.getQ().get(k) for k in range(4)])

    def qd(self, s=None) -> np.ndarray:
        s = self.state if s is None else s
        return A @ np.array([s.getU().get(k) for k in range(4)])

    # ------------------------------------------------------------ terms

    def accelerations(self) -> np.ndarray:
        self.model.realizeAcceleration(self.state)
        udot = self.state.getUDot()
        return A @ np.array([udot.get(k) for k in range(4)])

    def mass_matrix(self) -> np.ndarray:
        self.model.realizePosition(self.state)
        M = osim.Matrix()
        self.model.getMatterSubsystem().calcM(self.state, M)
        M_phi = np.array([[M.get(i, j) for j in range(4)] for i in range(4)])
        return A_INV.T @ M_phi @ A_INV  # M_q = A^-T M_phi A^-1

    def station_in_ground(self, body: str, point) -> np.ndarray:
        self.model.realizePosition(self.state)
        b = self.model.getBodySet().get(body)
        v = b.findStationLocationInGround(self.state, osim.Vec3(*point))
        return np.array([v.get(0), v.get(1), v.get(2)])

    def station_velocity_in_ground(self, body: str, point) -> np.ndarray:
        self.model.realizeVelocity(self.state)
        b = self.model.getBodySet().get(body)
        v = b.findStationVelocityInGround(self.state, osim.Vec3(*point))
        return np.array([v.get(0), v.get(1), v.get(2)])

    # ------------------------------------------------------------ simulation

    def simulate(self, time_s, q0, qd0, u, force, shank_force=None) -> np.ndarray:
        self.set_state(q0, qd0, u, force, shank_force)
        self.state.setTime(float(time_s[0]))
        manager = osim.Manager(self.model)
        manager.setIntegratorAccuracy(1e-12)
        manager.initialize(self.state)
        out = [self.q(self.state)]
        for t in time_s[1:]:
            s = manager.integrate(float(t))
            out.append(self.q(s))
        return np.array(out)


# ---------------------------------------------------------------- the perturbed swing
#
# The unperturbed swing is analytic: every OpenSim coordinate of the leg is one
# sine in time, phi(t) = a sin(w t + p) + c (osim.Sine, exact derivatives), with
# t = 0 at toe-off. Joint angles (rad): hip flexion -0.16 -> 0.40, knee flexion
# 0.65 at toe-off, 1.10 at 150 ms, 0.20 at 450 ms, ankle -0.25 .. 0.01; the
# cart sways by 15 mm.
SWING_SINES: dict[str, tuple[float, float, float, float]] = {
    # coordinate: (amplitude, omega rad/s, phase rad, offset)
    "x": (0.015, 2.0 * np.pi / 0.55, 0.3, 0.0),
    "hip": (0.28, 2.0 * np.pi / 0.8, -0.5 * np.pi, 0.12),  # phi_1 = theta_hip
    "knee": (-0.45, 2.0 * np.pi / 0.6, 0.0, -0.65),  # phi_2 = -theta_knee
    "ankle": (0.13, 2.0 * np.pi / 0.5, 2.0 * np.pi * 0.05 / 0.5 - 0.5 * np.pi, -0.12),  # phi_3 = theta_ankle
}
COORDINATES = ("x", "hip", "knee", "ankle")

# Rod force magnitude (N) along the thigh normal (forward, perpendicular to the
# thigh): the device's small residual force in minimal-impedance mode, and the
# pulse, a rectangular command of 40 N for 100 ms passed through a second-order
# response with 30 % overshoot (damping ratio 0.358) and a 10-90 % rise time of
# 10 ms (natural frequency 140 rad/s).
RESIDUAL_FORCE = "1.5 + 1.0*sin(13.962634015954636*t)"  # N, period 0.45 s
PULSE_AMPLITUDE_N = 40.0
PULSE_DURATION_S = 0.1
PULSE_ZETA = 0.3578571305033167
PULSE_OMEGA_N = 140.02


def swing_coordinates(time_s) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unperturbed ``phi``, ``phi'``, ``phi''`` (n, 4) of :data:`SWING_SINES` at ``time_s`` (s)."""
    t = np.asarray(time_s, dtype=float)[:, None]
    a, w, p, c = (np.array([SWING_SINES[k][i] for k in COORDINATES]) for i in range(4))
    arg = w * t + p
    return a * np.sin(arg) + c, a * w * np.cos(arg), -a * w * w * np.sin(arg)


def _step_response(tau: str) -> str:
    """Lepton expression of the unit second-order step response at ``tau`` (0 before)."""
    z, wn = PULSE_ZETA, PULSE_OMEGA_N
    wd = wn * float(np.sqrt(1.0 - z * z))
    return f"step({tau})*(1 - exp(-{z * wn!r}*({tau}))*(cos({wd!r}*({tau})) + {z * wn / wd!r}*sin({wd!r}*({tau}))))"


def rod_force_expression(onset_s: float | None) -> str:
    """Lepton expression of the rod force magnitude (N) in time ``t`` (s); no pulse for ``onset_s`` None."""
    if onset_s is None:
        return RESIDUAL_FORCE
    on, off = f"(t - {float(onset_s)!r})", f"(t - {float(onset_s) + PULSE_DURATION_S!r})"
    return f"{RESIDUAL_FORCE} + {PULSE_AMPLITUDE_N!r}*({_step_response(on)} - {_step_response(off)})"


def time_function(expression: str):
    """An OpenSim function of the single variable ``t``."""
    return osim.ExpressionBasedFunction(expression, osim.StdVectorString(["t"]))


def evaluate(function, time_s) -> np.ndarray:
    return np.array([function.calcValue(osim.Vector(1, float(t))) for t in np.atleast_1d(time_s)])


def thigh_normal(q_thigh) -> np.ndarray:
    """World direction (n, 2) of the thigh body's x axis: perpendicular to the thigh, forward."""
    q = np.asarray(q_thigh, dtype=float)
    return np.stack([np.cos(q), -np.sin(q)], axis=-1)


def feedforward_torques(p: SegmentParameters, time_s) -> np.ndarray:
    """The leg's own generalised forces ``tau_phi`` (n, 4) that walk the analytic swing under the residual force.

    OpenSim's inverse dynamics of :func:`swing_coordinates` with the residual rod
    force acting perpendicular to the thigh: ``M (phi'' - phi''_0)`` with
    ``phi''_0`` the accelerations without own forces.
    """
    leg = OpenSimLeg(p)
    phi, phid, phidd = swing_coordinates(time_s)
    residual = evaluate(time_function(RESIDUAL_FORCE), time_s)
    out = np.empty((len(phi), 4))
    for k in range(len(phi)):
        q, qd = A @ phi[k], A @ phid[k]
        leg.set_state(q, qd, np.zeros(4), residual[k] * thigh_normal(q[1]))
        phidd0 = A_INV @ leg.accelerations()
        out[k] = (A.T @ leg.mass_matrix() @ A) @ (phidd[k] - phidd0)
    return out


class PerturbedSwingLeg:
    """The swing leg with joint impedance about the analytic swing, pushed by the rod (OpenSim only).

    Each joint is split into two pin joints about the same axis through a
    link body of negligible inertia (1e-9 kg m^2, no mass)::

        parent -pin(<joint>_reference)-> <joint>_link -pin(<joint>_deviation)-> child

    The reference coordinate is prescribed to the unperturbed ``phi_j(t)``
    (:data:`SWING_SINES`), so the deviation coordinate is ``psi_j = phi_j -
    phi_j,u(t)``. By the conventions of ``docs/conventions.md`` the
    impedance feedback ``T_j = -K_j dtheta_j - D_j dtheta_j'`` is the
    generalised force ``-K_j psi_j - D_j psi_j'`` on every ``psi_j`` (an
    ExpressionBasedCoordinateForce). The leg's own forces ``tau_phi(t)``
    (:func:`feedforward_torques`, a quintic spline through 0.5 ms samples)
    act on the cart and on the deviation coordinates through a
    PrescribedController, and the rod force is a PointActuator at the brace
    whose direction is fixed in the thigh (its x axis, perpendicular to the
    thigh, forward) with the magnitude :func:`rod_force_expression`.
    The OpenSim Manager integrates the whole (Runge-Kutta-Merson, error control).
    """

    LINK_INERTIA = 1e-9

    def __init__(self, p: SegmentParameters, impedance, onset_s: float | None, span_s: tuple[float, float]):
        model = osim.Model()
        model.setName("perturbed_swing_leg")
        model.setGravity(osim.Vec3(0.0, -p.gravity_m_per_s2, 0.0))
        cart = osim.Body("cart", p.cart_mass_kg, osim.Vec3(0.0), osim.Inertia(1.0, 1.0, 1.0))
        model.addBody(cart)
        zero = osim.Vec3(0.0)
        slider = osim.SliderJoint("slider", model.getGround(), zero, zero, cart, zero, zero)
        slider.upd_coordinates(0).setName("x")
        model.addJoint(slider)
        parent, parent_loc = cart, osim.Vec3(0.0)
        eps = self.LINK_INERTIA
        for i, (name, joint) in enumerate(zip(SEGMENT_NAMES, COORDINATES[1:])):
            link = osim.Body(f"{joint}_link", eps, osim.Vec3(0.0), osim.Inertia(eps, eps, eps))
            model.addBody(link)
            ref = osim.PinJoint(
                f"{joint}_ref_pin", parent, parent_loc, osim.Vec3(0.0), link, osim.Vec3(0.0), osim.Vec3(0.0)
            )
            coord = ref.upd_coordinates(0)
            coord.setName(f"{joint}_reference")
            coord.setPrescribedFunction(osim.Sine(*SWING_SINES[joint]))
            coord.setDefaultIsPrescribed(True)
            model.addJoint(ref)
            body = osim.Body(
                name,
                p.mass_kg[i],
                osim.Vec3(p.com_x_m[i], p.com_y_m[i], 0.0),
                osim.Inertia(0.3, 0.2, p.inertia_kg_m2[i]),
            )
            model.addBody(body)
            dev = osim.PinJoint(
                f"{joint}_dev_pin", link, osim.Vec3(0.0), osim.Vec3(0.0), body, osim.Vec3(0.0), osim.Vec3(0.0)
            )
            dev.upd_coordinates(0).setName(f"{joint}_deviation")
            model.addJoint(dev)
            parent, parent_loc = body, osim.Vec3(0.0, -p.length_m[i], 0.0)

        K, D = np.asarray(impedance, dtype=float)[0::2], np.asarray(impedance, dtype=float)[1::2]
        for j, joint in enumerate(COORDINATES[1:]):
            fb = osim.ExpressionBasedCoordinateForce(
                f"{joint}_deviation", f"-({float(K[j])!r})*q - ({float(D[j])!r})*qdot"
            )
            fb.setName(f"{joint}_impedance")
            model.addForce(fb)

        controller = osim.PrescribedController()
        controller.setName("inputs")
        t0, t1 = span_s
        grid = np.arange(t0 - 0.01, t1 + 0.0105, 0.0005)
        tau = feedforward_torques(p, grid)
        actuated = ("x",) + tuple(f"{j}_deviation" for j in COORDINATES[1:])
        for k, coord_name in enumerate(actuated):
            act = osim.CoordinateActuator(coord_name)
            act.setName(f"own_{COORDINATES[k]}")
            act.setOptimalForce(1.0)
            act.setMinControl(-np.inf)
            act.setMaxControl(np.inf)
            model.addForce(act)
            controller.addActuator(act)
            spline = osim.GCVSpline()
            spline.setDegree(5)
            for a, b in zip(grid, tau[:, k]):
                spline.addPoint(float(a), float(b))
            controller.prescribeControlForActuator(act.getName(), spline)
        rod = osim.PointActuator("thigh")
        rod.setName("rod_force")
        rod.set_point(osim.Vec3(0.0, -p.attachment_m, 0.0))
        rod.set_point_is_global(False)
        rod.set_direction(osim.Vec3(1.0, 0.0, 0.0))
        rod.set_force_is_global(False)
        rod.setOptimalForce(1.0)
        rod.setMinControl(-np.inf)
        rod.setMaxControl(np.inf)
        model.addForce(rod)
        controller.addActuator(rod)
        self.force_function = time_function(rod_force_expression(onset_s))
        controller.prescribeControlForActuator("rod_force", self.force_function.clone())
        model.addController(controller)

        self.state = model.initSystem()
        self.model = model
        self.params = p
        self.span_s = (float(t0), float(t1))

    def _coordinate(self, name: str):
        return self.model.getCoordinateSet().get(name)

    def phi(self, s) -> np.ndarray:
        """OpenSim joint coordinates of the leg (4,): cart x and reference + deviation per joint."""
        v = [self._coordinate("x").getValue(s)]
        for joint in COORDINATES[1:]:
            v.append(
                self._coordinate(f"{joint}_reference").getValue(s) + self._coordinate(f"{joint}_deviation").getValue(s)
            )
        return np.array(v)

    def deviation(self, s) -> np.ndarray:
        """Deviation coordinates psi (3,) rad: hip, knee, ankle (OpenSim sense)."""
        return np.array([self._coordinate(f"{j}_deviation").getValue(s) for j in COORDINATES[1:]])

    def simulate(self, time_s, accuracy: float = 1e-8):
        """Integrate from ``span_s[0]`` on the unperturbed swing; q (n, 4) and rod force vector (n, 2) N at
        ``time_s``."""
        t0 = self.span_s[0]
        s = self.state
        s.setTime(t0)
        phi0, phid0, _ = swing_coordinates([t0])
        for k, name in enumerate(("x",) + tuple(f"{j}_reference" for j in COORDINATES[1:])):
            self._coordinate(name).setValue(s, float(phi0[0, k]), False)
            self._coordinate(name).setSpeedValue(s, float(phid0[0, k]))
        for j in COORDINATES[1:]:
            self._coordinate(f"{j}_deviation").setValue(s, 0.0, False)
            self._coordinate(f"{j}_deviation").setSpeedValue(s, 0.0)
        manager = osim.Manager(self.model)
        manager.setIntegratorAccuracy(accuracy)
        manager.initialize(s)
        q, force = [], []
        for t in np.asarray(time_s, dtype=float):
            if t < t0 - 1e-12:
                raise ValueError(f"output time {t} before the simulation start {t0}")
            st = manager.integrate(float(t)) if t > t0 else s
            qk = A @ self.phi(st)
            q.append(qk)
            force.append(evaluate(self.force_function, t)[0] * thigh_normal(qk[1]))
        return np.array(q), np.array(force)


def pulse_recording(
    p: SegmentParameters,
    impedance,
    onset_s: float | None,
    reference_onset_s: float,
    rate_hz: float = 128.0,
    force_rate_hz: float = 1000.0,
    before_s: float = 0.13,
    after_s: float = 0.255,
    accuracy: float = 1e-8,
) -> dict[str, np.ndarray]:
    """What the pipeline would record of one perturbed stride and its matched unperturbed stride.

    Coordinates ``q_u`` (analytic) and ``q_p`` (OpenSim) at ``rate_hz`` on a grid
    with a sample at ``reference_onset_s`` covering ``before_s`` before to
    ``after_s`` after it (``time_s``); the rod force vectors ``force_u_n`` and
    ``force_p_n`` (N, world x/y) at ``force_rate_hz`` on a grid through the
    onset (``force_time_s``). ``onset_s`` is the pulse onset (None: no pulse).
    """
    on = float(reference_onset_s)
    k = np.arange(-int(np.ceil(before_s * rate_hz)), int(np.ceil(after_s * rate_hz)) + 1)
    time_s = on + k / rate_hz
    kf = np.arange(-int(np.ceil(before_s * force_rate_hz)), int(np.ceil(after_s * force_rate_hz)) + 1)
    force_time_s = on + kf / force_rate_hz
    every = np.unique(np.round(np.r_[time_s, force_time_s], 12))
    leg = PerturbedSwingLeg(p, impedance, onset_s, (every[0] - 0.005, every[-1]))
    q_p, f_p = leg.simulate(every, accuracy)
    phi, _, _ = swing_coordinates(every)
    q_u = phi @ A.T
    f_u = evaluate(time_function(RESIDUAL_FORCE), every)[:, None] * thigh_normal(q_u[:, 1])
    i = np.searchsorted(every, np.round(time_s, 12))
    j = np.searchsorted(every, np.round(force_time_s, 12))
    return {
        "time_s": time_s,
        "q_u": q_u[i],
        "q_p": q_p[i],
        "force_time_s": force_time_s,
        "force_u_n": f_u[j],
        "force_p_n": f_p[j],
    }


def stepped_swing(p: SegmentParameters, impedance, onset_s: float, time_s, steps_per_sample: int) -> np.ndarray:
    """The perturbed swing by the plain :class:`OpenSimLeg`, inputs held over small steps; q (n, 4) at ``time_s``.

    A second construction of :class:`PerturbedSwingLeg`'s motion: ``time_s``
    uniform, the leg starts on the analytic swing at ``time_s[0]``; each step
    (``steps_per_sample`` per sample) the Manager integrates with the
    actuator overrides fixed at their values at mid-step: own forces, joint
    torques ``T_j = -K_j dtheta_j - D_j dtheta_j'`` (``docs/conventions.md``)
    from the state extrapolated to mid-step with the last step's mean
    acceleration, and the rod force perpendicular to the thigh.
    """
    imp = np.asarray(impedance, dtype=float)
    t = np.asarray(time_s, dtype=float)
    h = (t[1] - t[0]) / steps_per_sample
    n = (len(t) - 1) * steps_per_sample
    grid = t[0] + h * np.arange(n + 1)
    mid = grid[:-1] + 0.5 * h
    tau = feedforward_torques(p, mid)
    magnitude = evaluate(time_function(rod_force_expression(onset_s)), mid)
    phi_u, phid_u, _ = swing_coordinates(mid)
    phi0, phid0, _ = swing_coordinates(t[:1])

    def theta(q):  # hip, knee, ankle angles, pelvis angle 0
        return np.array([-q[1], q[2] - q[1], q[2] - q[3]])

    leg = OpenSimLeg(p)
    q, qd, qdd = A @ phi0[0], A @ phid0[0], np.zeros(4)
    out = [q]
    for k in range(n):
        qm, qdm = q + 0.5 * h * qd + 0.125 * h * h * qdd, qd + 0.5 * h * qdd
        torque = -imp[0::2] * (theta(qm) - theta(A @ phi_u[k])) - imp[1::2] * (theta(qdm) - theta(A @ phid_u[k]))
        u_fb = np.array([0.0, -torque[0] - torque[1], torque[1] + torque[2], -torque[2]])
        leg.set_state(q, qd, A_INV.T @ tau[k] + u_fb, magnitude[k] * thigh_normal(qm[1]))
        leg.state.setTime(float(grid[k]))
        manager = osim.Manager(leg.model)
        manager.setIntegratorAccuracy(1e-12)
        manager.initialize(leg.state)
        s = manager.integrate(float(grid[k + 1]))
        q_new, qd_new = leg.q(s), leg.qd(s)
        qdd = (qd_new - qd) / h
        q, qd = q_new, qd_new
        if (k + 1) % steps_per_sample == 0:
            out.append(q)
    return np.array(out)
