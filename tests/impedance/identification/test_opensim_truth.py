"""Identification against a truth from a second engine: the perturbed swing simulated by OpenSim.

Our synthetic truths use the same equations as the fit. Here the perturbed
swing comes from OpenSim (Simbody) alone (:class:`tests.opensim_swing_leg.PerturbedSwingLeg`):
the analytic unperturbed swing (hip flexion -0.16 -> 0.40 rad, knee flexion
0.65 -> 1.10 -> 0.20 rad over 450 ms), the leg's own forces from OpenSim's
inverse dynamics of it, joint impedance about it, a small residual rod force
and the pulse (40 N for 100 ms through a second-order response with 30 %
overshoot and a 10 ms rise time), perpendicular to the thigh at the brace,
integrated by OpenSim's error-controlled Runge-Kutta-Merson (accuracy 1e-8;
within 1e-7 of the response of a 100 times tighter run).

The pipeline's view of it: coordinates at 128 Hz on a grid through the onset
and the rod force at 1000 Hz. The fit must reach hip and knee K within 0.5 %
and D within 2 % of the truth for two impedance sets and two onsets when it
receives the force at its own rate; with the force resampled to the 128 Hz
frames it misses that (the pulse's 10 ms rise falls between frames).
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest

from loper_analysis.constants import PARAMETERS
from loper_analysis.impedance.identification import identify_impedance, prepare_window
from loper_analysis.impedance.responses.response_window import ResponseWindow
from tests.opensim_swing_leg import (
    A_INV,
    COORDINATES,
    A,
    OpenSimLeg,
    PerturbedSwingLeg,
    evaluate,
    feedforward_torques,
    pulse_recording,
    stepped_swing,
    swing_coordinates,
    thigh_normal,
)
from tests.parameter_sets import WINTER

# (K_hip, D_hip, K_knee, D_knee, K_ankle, D_ankle) in N·m/rad and N·m·s/rad
IMPEDANCE_SETS = {
    "soft_knee": (55.0, 3.5, 3.0, 0.1, 8.0, 0.15),
    "stiff_knee": (55.0, 3.5, 20.0, 1.0, 15.0, 0.3),
}
ONSETS_S = (0.05, 0.175)  # after toe-off
CASES = [(name, onset) for name in IMPEDANCE_SETS for onset in ONSETS_S]
# the "must reach": relative error bounds of the hip and knee estimates
K_BOUND, D_BOUND = 0.005, 0.02
HIP_KNEE = [PARAMETERS.index(p) for p in ("K_hip", "D_hip", "K_knee", "D_knee")]
BOUNDS = np.array([K_BOUND if PARAMETERS[i].startswith("K") else D_BOUND for i in HIP_KNEE])

NATIVE_RATE = "force_time_s" in inspect.signature(prepare_window).parameters
needs_native_rate = pytest.mark.skipif(
    not NATIVE_RATE, reason="prepare_window does not take the force at its own rate (force_time_s) yet"
)


@pytest.fixture(autouse=True)
def _run_in_tmp(tmp_path, monkeypatch):
    """Whatever OpenSim might write lands in pytest's tmp_path, never in the repo."""
    monkeypatch.chdir(tmp_path)


@pytest.fixture(scope="module")
def recordings() -> dict:
    return {(name, on): pulse_recording(WINTER, IMPEDANCE_SETS[name], on, on) for name, on in CASES}


def _fit(rec: dict, onset_s: float, native: bool):
    if native:
        kw = dict(
            force_unperturbed_n=rec["force_u_n"], force_perturbed_n=rec["force_p_n"], force_time_s=rec["force_time_s"]
        )
    else:  # the force resampled to the 128 Hz frames (linear interpolation, as the pipeline resamples)
        t, tf = rec["time_s"], rec["force_time_s"]
        kw = {
            key: np.stack([np.interp(t, tf, rec[src][:, j]) for j in range(2)], axis=-1)
            for key, src in (("force_unperturbed_n", "force_u_n"), ("force_perturbed_n", "force_p_n"))
        }
    window = prepare_window(
        rec["time_s"], rec["q_u"], rec["q_p"], WINTER, onset_s, window=ResponseWindow(0.025, 0.25), **kw
    )
    return identify_impedance(window)


@pytest.fixture(scope="module")
def frame_errors(recordings) -> dict:
    return _relative_errors(recordings, native=False)


@pytest.fixture(scope="module")
def native_errors(recordings) -> dict:
    return _relative_errors(recordings, native=True)


def _relative_errors(recordings, native: bool) -> dict:
    out = {}
    for name, on in CASES:
        truth = np.array(IMPEDANCE_SETS[name])
        fit = _fit(recordings[(name, on)], on, native)
        assert fit.success, fit.message
        out[(name, on)] = (fit.estimate - truth) / truth
        print(
            f"{'1000 Hz' if native else '128 Hz'} force, {name}, onset {on * 1000:.0f} ms: "
            + ", ".join(
                f"{p} {t:g} -> {e:.4g} ({100 * r:+.3f} %)"
                for p, t, e, r in zip(PARAMETERS, truth, fit.estimate, out[(name, on)])
            )
        )
    return out


# ---------------------------------------------------------------- the OpenSim truth itself


def test_opensim_truth_is_exact_enough(recordings):
    """The OpenSim construction reproduces the unperturbed swing, the feedback laws, and is converged.

    Known answers: (1) without the pulse the leg stays on the analytic swing;
    (2) at a perturbed state its accelerations equal those of the plain OpenSim
    leg (:class:`OpenSimLeg`) driven by the own forces plus the joint torques
    ``T_j = -K_j dtheta_j - D_j dtheta_j'`` mapped by ``docs/conventions.md``
    and the rod force perpendicular to the thigh; (3) an integrator accuracy
    100 times tighter changes the response by < 1e-5 of its size.
    """
    name, on = "soft_knee", 0.175
    imp = np.array(IMPEDANCE_SETS[name])
    # (1) no pulse
    still = pulse_recording(WINTER, imp, None, on)
    drift = np.abs(still["q_p"] - still["q_u"]).max()
    print(f"unperturbed run: largest deviation from the analytic swing {drift:.2e}")
    assert drift < 1e-6

    # (2) feedback and force: accelerations at a perturbed state, t inside the pulse
    t = on + 0.04
    leg = PerturbedSwingLeg(WINTER, imp, on, (on - 0.1, on + 0.1))
    s = leg.state
    s.setTime(t)
    phi_u, phid_u, _ = swing_coordinates([t])
    psi, psid = np.array([0.03, -0.05, 0.02]), np.array([0.4, -0.7, 0.5])
    coords = leg.model.getCoordinateSet()
    coords.get("x").setValue(s, 0.01, False)
    coords.get("x").setSpeedValue(s, -0.2)
    for j, joint in enumerate(COORDINATES[1:]):
        coords.get(f"{joint}_reference").setValue(s, float(phi_u[0, j + 1]), False)
        coords.get(f"{joint}_reference").setSpeedValue(s, float(phid_u[0, j + 1]))
        coords.get(f"{joint}_deviation").setValue(s, float(psi[j]), False)
        coords.get(f"{joint}_deviation").setSpeedValue(s, float(psid[j]))
    leg.model.realizeAcceleration(s)
    phidd = np.array(
        [coords.get("x").getAccelerationValue(s)]
        + [
            coords.get(f"{j}_reference").getAccelerationValue(s) + coords.get(f"{j}_deviation").getAccelerationValue(s)
            for j in COORDINATES[1:]
        ]
    )
    q_u = A @ phi_u[0]
    q, qd = A @ leg.phi(s), A @ (phid_u[0] + np.r_[-0.2 - phid_u[0, 0], psid])

    def th(q_):  # joint angles, pelvis angle 0
        return np.array([-q_[1], q_[2] - q_[1], q_[2] - q_[3]])

    torque = -imp[0::2] * (th(q) - th(q_u)) - imp[1::2] * (th(qd) - th(A @ phid_u[0]))
    u_fb = np.array([0.0, -torque[0] - torque[1], torque[1] + torque[2], -torque[2]])
    plain = OpenSimLeg(WINTER)
    tau_own = feedforward_torques(WINTER, [t])[0]
    force = evaluate(leg.force_function, t)[0] * thigh_normal(q[1])
    assert force @ thigh_normal(q[1]) > 40.0  # inside the pulse
    plain.set_state(q, qd, A_INV.T @ tau_own + u_fb, force)
    expected = A_INV @ plain.accelerations()
    print(
        f"perturbed state: accelerations differ by {np.abs(phidd - expected).max():.2e} "
        f"(of {np.abs(expected).max():.1f})"
    )
    np.testing.assert_allclose(phidd, expected, rtol=0, atol=1e-6 * np.abs(expected).max())

    # (3) convergence of the integration
    rec = recordings[(name, on)]
    tight = pulse_recording(WINTER, imp, on, on, accuracy=1e-10)
    size = np.abs(rec["q_p"] - rec["q_u"]).max()
    change = np.abs(tight["q_p"] - rec["q_p"]).max()
    print(f"response {size:.3f} rad, change with accuracy 1e-10 instead of 1e-8: {change:.2e}")
    assert size > 0.05
    assert change < 1e-5 * size


def test_two_opensim_constructions_agree(recordings):
    """The plain OpenSim leg with the feedback applied step by step (98 us steps) follows the same perturbed swing.

    Known answer: :class:`PerturbedSwingLeg`'s response (the impedance as
    OpenSim forces on split joints) within 1e-5 of its size (measured 8e-7;
    halving the step changes the stepped response by 6e-7 of it).
    """
    name, on = "soft_knee", 0.175
    rec = recordings[(name, on)]
    first = int(np.argmin(np.abs(rec["time_s"] - (on - 0.025))))  # from the window start on
    stepped = stepped_swing(WINTER, IMPEDANCE_SETS[name], on, rec["time_s"][first:], steps_per_sample=80)
    size = np.abs(rec["q_p"] - rec["q_u"]).max()
    diff = np.abs(stepped - rec["q_p"][first:]).max()
    print(f"stepped vs split-joint construction: {diff:.2e} rad of a {size:.3f} rad response")
    assert size > 0.05
    assert diff < 1e-5 * size


# ---------------------------------------------------------------- identification


@needs_native_rate
def test_native_rate_force_reaches_the_bounds(native_errors):
    """With the force at 1000 Hz: hip and knee K within 0.5 %, D within 2 % of the OpenSim truth.

    In fact every parameter, the ankle's too, lands within 0.05 % (measured
    0.002 % at most): the fit reproduces the second engine's truth.
    """
    for case, rel in native_errors.items():
        assert np.all(np.abs(rel[HIP_KNEE]) < BOUNDS), f"{case}: {dict(zip(PARAMETERS, 100 * rel))} %"
        assert np.all(np.abs(rel) < 5e-4), f"{case}: {dict(zip(PARAMETERS, 100 * rel))} %"


def _worst_fraction(errors: dict) -> dict:
    """Per case the largest hip/knee error as a fraction of its bound (1 = on the bound)."""
    return {case: float(np.max(np.abs(rel[HIP_KNEE]) / BOUNDS)) for case, rel in errors.items()}


def test_128hz_force_path_misses_the_bounds(frame_errors):
    """With the force resampled to 128 Hz the fit misses the bounds: K_knee of the soft knee at 175 ms is -0.74 %.

    Every case uses more than a fifth of its error budget (measured 0.30-1.47
    of it), the worst case more than all of it.
    """
    worst = _worst_fraction(frame_errors)
    print(
        "128 Hz force, largest hip/knee error / bound:",
        {f"{n} {o * 1000:.0f} ms": round(v, 4) for (n, o), v in worst.items()},
    )
    assert max(worst.values()) > 1.2
    assert min(worst.values()) > 0.2


@needs_native_rate
def test_128hz_force_path_is_worse_than_native_rate(native_errors, frame_errors):
    """On the same data, the 128 Hz force path's worst hip/knee error is at least 10x that of the 1000 Hz path, per
    case.

    Measured: 0.30-1.47 of the error budget against 0.002 at most.
    """
    native = _worst_fraction(native_errors)
    frames = _worst_fraction(frame_errors)
    print(
        "largest hip/knee error / bound, 128 Hz and 1000 Hz force:",
        [(round(frames[c], 4), round(native[c], 5)) for c in CASES],
    )
    for case in CASES:
        assert frames[case] > 10.0 * native[case], f"{case}: 128 Hz {frames[case]:.3f}, 1000 Hz {native[case]:.3f}"
