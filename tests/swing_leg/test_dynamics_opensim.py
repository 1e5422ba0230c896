"""Cross-check of the planar swing-leg model against a peer engine, OpenSim (Simbody).

The same mechanism is built with the OpenSim Python API::

    ground -SliderJoint(X)-> cart -PinJoint(Z)-> thigh -PinJoint(Z)-> shank -PinJoint(Z)-> foot

OpenSim uses relative, counter-clockwise joint angles ``phi``; our model uses
global, clockwise segment angles ``q``::

    phi_x = x,  phi_1 = -q_1,  phi_2 = -(q_2 - q_1),  phi_3 = -(q_3 - q_2)

so ``q = A phi`` with a constant matrix ``A``. Then ``q' = A phi'``,
``q'' = A phi''``, the generalised forces map by virtual work as
``tau_phi = A^T u`` and the mass matrices as ``M_phi = A^T M_q A``.

Generalised forces enter through CoordinateActuators and the rod force
``F = (F_x, F_y)`` through two PointActuators at the body point
``(0, -attachment_m)`` of the thigh with the direction fixed in ground; all six
use optimal force 1 and the actuation override, a discrete state variable that
holds the value during a Manager integration. The OpenSim model is
:class:`tests.opensim_swing_leg.OpenSimLeg`. With a second rod just above the ankle (``shank_attachment_m``),
two more PointActuators push at that point of the shank.
"""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.swing_leg.dynamics import SegmentParameters
from tests.opensim_swing_leg import SEGMENT_NAMES, OpenSimLeg
from tests.parameter_sets import ASYMMETRIC, WINTER
from tests.swing_leg.reference_dynamics import (
    attachment_jacobian,
    attachment_position,
    forward_dynamics,
    mass_matrix,
    segment_com_positions,
    shank_attachment_jacobian,
    shank_attachment_position,
    simulate,
)

PARAMETER_SETS = {"winter_1.73m_64.9kg": WINTER, "asymmetric": ASYMMETRIC}


@pytest.fixture(autouse=True)
def _run_in_tmp(tmp_path, monkeypatch):
    """Whatever OpenSim might write lands in pytest's tmp_path, never in the repo."""
    monkeypatch.chdir(tmp_path)


@pytest.fixture(params=sorted(PARAMETER_SETS))
def params(request) -> SegmentParameters:
    return PARAMETER_SETS[request.param]


def _random_states(n: int, seed: int):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        q = np.r_[rng.uniform(-0.5, 0.5), rng.uniform(-1.0, 1.0, 3)]
        qd = np.r_[rng.uniform(-2.0, 2.0), rng.uniform(-5.0, 5.0, 3)]
        u = rng.uniform(-50.0, 50.0, 4)
        force = rng.uniform(-60.0, 60.0, 2)
        yield q, qd, u, force


# ---------------------------------------------------------------- tests


def test_kinematics_and_conventions_match(params):
    """Coordinate mapping, segment frames and attachment point agree (positions and velocities)."""
    leg = OpenSimLeg(params)
    for q, qd, _, _ in _random_states(10, seed=7):
        leg.set_state(q, qd)
        com = segment_com_positions(q, params)
        for i, name in enumerate(SEGMENT_NAMES):
            got = leg.station_in_ground(name, (params.com_x_m[i], params.com_y_m[i], 0.0))
            np.testing.assert_allclose(got[:2], com[i], rtol=0, atol=1e-14)
            assert got[2] == 0.0
        att = leg.station_in_ground("thigh", (0.0, -params.attachment_m, 0.0))
        np.testing.assert_allclose(att[:2], attachment_position(q, params), rtol=0, atol=1e-14)
        v_att = leg.station_velocity_in_ground("thigh", (0.0, -params.attachment_m, 0.0))
        np.testing.assert_allclose(v_att[:2], attachment_jacobian(q, params) @ qd, rtol=0, atol=1e-13)


def test_forward_dynamics_and_mass_matrix_match_opensim(params):
    leg = OpenSimLeg(params)
    worst_acc = worst_mass = 0.0
    for q, qd, u, force in _random_states(20, seed=2024):
        leg.set_state(q, qd, u, force)
        qdd_ref = leg.accelerations()
        qdd = forward_dynamics(q, qd, u, params, force)
        err = np.linalg.norm(qdd - qdd_ref) / np.linalg.norm(qdd_ref)
        worst_acc = max(worst_acc, err)
        assert err < 1e-8, f"q={q}, qd={qd}, u={u}, F={force}: ours {qdd}, OpenSim {qdd_ref}"

        M_ref = leg.mass_matrix()
        M = mass_matrix(q, params)
        err_m = np.linalg.norm(M - M_ref) / np.linalg.norm(M_ref)
        worst_mass = max(worst_mass, err_m)
        assert err_m < 1e-10, f"q={q}: ours\n{M}\nOpenSim\n{M_ref}"
    print(f"max relative acceleration error {worst_acc:.2e}, mass matrix {worst_mass:.2e}")


def test_each_input_alone_matches_opensim(params):
    """Unit inputs one at a time (no gravity masking): each u_i and F component has the right effect."""
    p0 = params.replace(gravity_m_per_s2=0.0)
    leg = OpenSimLeg(p0)
    q = np.array([0.1, 0.3, -0.4, 0.7])
    qd = np.zeros(4)
    for k in range(6):
        e = np.zeros(6)
        e[k] = 10.0
        u, force = e[:4], e[4:]
        leg.set_state(q, qd, u, force)
        qdd_ref = leg.accelerations()
        qdd = forward_dynamics(q, qd, u, p0, force)
        np.testing.assert_allclose(qdd, qdd_ref, rtol=0, atol=1e-10 * np.linalg.norm(qdd_ref))


def test_simulation_matches_opensim_manager(params):
    q0 = np.array([0.05, 0.4, 0.1, -0.2])
    qd0 = np.array([0.3, -2.0, 1.5, 3.0])
    u = np.array([5.0, 10.0, -4.0, 1.5])
    force = np.array([20.0, -15.0])
    time_s = np.linspace(0.0, 0.3, 31)

    q_ref = OpenSimLeg(params).simulate(time_s, q0, qd0, u, force)
    q_sim, _ = simulate(
        time_s,
        q0,
        qd0,
        params,
        u_ff=np.tile(u, (len(time_s), 1)),
        force_n=np.tile(force, (len(time_s), 1)),
    )
    # the motion is not trivial
    assert np.ptp(q_sim[:, 1:], axis=0).min() > 0.05
    diff = np.abs(q_sim - q_ref)
    print(f"max simulation difference: cart {diff[:, 0].max():.2e} m, angles {diff[:, 1:].max():.2e} rad")
    np.testing.assert_allclose(q_sim[-1], q_ref[-1], rtol=0, atol=1e-6)
    np.testing.assert_allclose(q_sim[:, 0], q_ref[:, 0], rtol=0, atol=1e-6)
    np.testing.assert_allclose(q_sim[:, 1:], q_ref[:, 1:], rtol=0, atol=1e-6)


# ---------------------------------------------------------------- a second rod at the shank

#: A second rod's attachment on the shank, from the knee (m): just above the ankle of either parameter set.
SHANK_ROD_FRACTION = 0.85


def _two_rods(params: SegmentParameters) -> SegmentParameters:
    return params.replace(shank_attachment_m=SHANK_ROD_FRACTION * params.length_m[1])


def test_the_shank_rods_point_and_its_jacobian_match_opensim(params):
    """The shank rod's point (position and velocity) as OpenSim's station on the shank; the thigh rod's unchanged."""
    two = _two_rods(params)
    leg = OpenSimLeg(two)
    station = (0.0, -two.shank_attachment_m, 0.0)
    for q, qd, _, _ in _random_states(10, seed=11):
        leg.set_state(q, qd)
        np.testing.assert_allclose(
            leg.station_in_ground("shank", station)[:2], shank_attachment_position(q, two), atol=1e-14
        )
        v = leg.station_velocity_in_ground("shank", station)[:2]
        np.testing.assert_allclose(v, shank_attachment_jacobian(q, two) @ qd, rtol=0, atol=1e-13)
        np.testing.assert_array_equal(attachment_jacobian(q, two), attachment_jacobian(q, params))


def test_forward_dynamics_with_both_rods_match_opensim(params):
    """Accelerations under both rods' forces (random states, inputs and forces) as OpenSim's, and each rod's force
    component alone (no gravity masking it) moves the leg as OpenSim's does."""
    two = _two_rods(params)
    leg = OpenSimLeg(two)
    rng = np.random.default_rng(5)
    for q, qd, u, force in _random_states(20, seed=99):
        shank_force = rng.uniform(-60.0, 60.0, 2)
        leg.set_state(q, qd, u, force, shank_force)
        qdd_ref = leg.accelerations()
        qdd = forward_dynamics(q, qd, u, two, force, shank_force)
        assert np.linalg.norm(qdd - qdd_ref) / np.linalg.norm(qdd_ref) < 1e-8
    p0 = two.replace(gravity_m_per_s2=0.0)
    leg0 = OpenSimLeg(p0)
    q, qd = np.array([0.1, 0.3, -0.4, 0.7]), np.zeros(4)
    for k in range(2):
        shank_force = np.eye(2)[k] * 10.0
        leg0.set_state(q, qd, None, None, shank_force)
        qdd_ref = leg0.accelerations()
        qdd = forward_dynamics(q, qd, np.zeros(4), p0, None, shank_force)
        assert np.abs(qdd_ref).max() > 0.1  # the push moves the leg
        np.testing.assert_allclose(qdd, qdd_ref, rtol=0, atol=1e-10 * np.linalg.norm(qdd_ref))


def test_simulation_with_both_rods_matches_opensim_manager(params):
    two = _two_rods(params)
    q0 = np.array([0.05, 0.4, 0.1, -0.2])
    qd0 = np.array([0.3, -2.0, 1.5, 3.0])
    u = np.array([5.0, 10.0, -4.0, 1.5])
    force, shank_force = np.array([20.0, -15.0]), np.array([-25.0, 10.0])
    time_s = np.linspace(0.0, 0.3, 31)
    q_ref = OpenSimLeg(two).simulate(time_s, q0, qd0, u, force, shank_force)
    q_sim, _ = simulate(
        time_s,
        q0,
        qd0,
        two,
        u_ff=np.tile(u, (len(time_s), 1)),
        force_n=np.tile(force, (len(time_s), 1)),
        shank_force_n=np.tile(shank_force, (len(time_s), 1)),
    )
    q_one, _ = simulate(
        time_s, q0, qd0, two, u_ff=np.tile(u, (len(time_s), 1)), force_n=np.tile(force, (len(time_s), 1))
    )
    assert np.abs(q_sim - q_one)[-1, 1:].max() > 0.01  # the shank rod's push changes the motion
    np.testing.assert_allclose(q_sim, q_ref, rtol=0, atol=1e-6)
