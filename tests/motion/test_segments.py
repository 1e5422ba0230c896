"""The segment table from any OpenSim model (loper_analysis.motion.segments) against a hand computation.

The reference reads the scaled gait2392 ``.osim`` with ``xml.etree`` only:
body masses, mass centres and inertias, the joints' offset frames and the
knee's coupled translations (cubic splines, scaled by multipliers)
evaluated at the default knee angle with a spline written here from its
definition (end conditions: the third derivative of the cubic through the
first and last four knots), and the parallel-axis theorem for the foot.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import quiet_opensim, read_model, write_model
from loper_analysis.io.segment_table import read_segments, write_segments
from loper_analysis.motion.model import build_lower_body_model, segment_parameters_from_model
from loper_analysis.motion.segments import segments_from_model
from loper_analysis.stages.model.step import ModelSettings, segments_from_model_file
from tests.gait2392_models import scaled_gait2392

DATA = Path(__file__).parents[2] / "examples" / "gait2392"
GAIT2392 = DATA / "gait2392_simbody.osim"
#: Known scale factors (uniform per body) of the scaled gait2392.
FACTORS = {"pelvis": 1.05, "torso": 1.02, "femur": 1.10, "tibia": 0.95, "talus": 1.08, "calcn": 1.08, "toes": 1.08}
MASS_KG = 80.0


@pytest.fixture(scope="module")
def scaled_model_file(tmp_path_factory):
    """gait2392 scaled with OpenSim's Model.scale by :data:`FACTORS` to 80 kg, printed to a file."""
    model = scaled_gait2392(FACTORS, MASS_KG)
    return write_model(model, tmp_path_factory.mktemp("scaled") / "gait2392_scaled.osim")


# ---------------------------------------------------------------- the hand computation


def _vec(element, tag: str) -> np.ndarray:
    return np.array(element.find(tag).text.split(), dtype=float)


def _fmm_spline(x: np.ndarray, y: np.ndarray, at: float) -> float:
    """Cubic spline through (x, y) whose end third derivatives equal those of the cubics through 4 end knots."""
    n, h = x.size, np.diff(x)
    slope = np.diff(y) / h

    def third_difference(i):  # f[x_i .. x_i+3]
        d2 = np.diff(slope[i : i + 3]) / (x[i + 2 : i + 4] - x[i : i + 2])
        return (d2[1] - d2[0]) / (x[i + 3] - x[i])

    A, b = np.zeros((n, n)), np.zeros(n)
    A[0, :2] = [-1 / h[0], 1 / h[0]]
    b[0] = 6 * third_difference(0)
    A[-1, -2:] = [-1 / h[-1], 1 / h[-1]]
    b[-1] = 6 * third_difference(n - 4)
    for i in range(1, n - 1):
        A[i, i - 1 : i + 2] = [h[i - 1], 2 * (h[i - 1] + h[i]), h[i]]
        b[i] = 6 * (slope[i] - slope[i - 1])
    M = np.linalg.solve(A, b)
    i = int(np.clip(np.searchsorted(x, at) - 1, 0, n - 2))
    a, c = x[i + 1] - at, at - x[i]
    return float(
        M[i] * a**3 / (6 * h[i])
        + M[i + 1] * c**3 / (6 * h[i])
        + (y[i] / h[i] - M[i] * h[i] / 6) * a
        + (y[i + 1] / h[i] - M[i + 1] * h[i] / 6) * c
    )


def _function(element, q: float) -> float:
    """Value of an OpenSim function element at q (Constant, LinearFunction, SimmSpline, MultiplierFunction)."""
    kind = element.tag
    if kind == "Constant":
        return float(element.find("value").text)
    if kind == "LinearFunction":
        a, b = _vec(element, "coefficients")
        return a * q + b
    if kind == "SimmSpline":
        return _fmm_spline(_vec(element, "x"), _vec(element, "y"), q)
    if kind == "MultiplierFunction":
        return float(element.find("scale").text) * _function(next(iter(element.find("function"))), q)
    raise AssertionError(f"function {kind} not handled here")


class HandModel:
    """Bodies and joints of a gait2392-like .osim (no rotation in any offset frame or at the default pose)."""

    def __init__(self, path: Path):
        root = ET.parse(path).getroot().find("Model")
        self.bodies = {}
        for b in root.iter("Body"):
            I6 = _vec(b, "inertia")
            self.bodies[b.get("name")] = {
                "mass": float(b.find("mass").text),
                "com": _vec(b, "mass_center"),
                "izz": I6[2],
            }
        defaults = {c.get("name"): float(c.find("default_value").text) for c in root.iter("Coordinate")}
        self.joints = {}  # child body -> (parent body, child-frame origin in the parent body, its offset in the child)
        for j in root.find("JointSet").find("objects"):
            frames = {f.get("name"): f for f in j.find("frames")}
            parent = frames[j.find("socket_parent_frame").text.strip()]
            child = frames[j.find("socket_child_frame").text.strip()]
            for f in (parent, child):
                assert np.all(_vec(f, "orientation") == 0)
            shift = np.zeros(3)
            for axis in j.iter("TransformAxis"):
                names = (axis.find("coordinates").text or "").split()
                q = defaults[names[0]] if names else 0.0
                value = _function(list(axis)[-1], q)
                if axis.get("name").startswith("rotation"):
                    assert value == 0.0
                else:
                    shift += value * _vec(axis, "axis")

            def body(f):
                return f.find("socket_parent").text.strip().split("/")[-1]

            self.joints[body(child)] = (body(parent), _vec(parent, "translation") + shift, _vec(child, "translation"))

    def centre(self, body: str) -> np.ndarray:
        """The proximal joint centre of ``body`` in its own frame."""
        return self.joints[body][2]

    def origin_in(self, body: str, ancestor: str) -> np.ndarray:
        """Origin of ``body`` in the frame of ``ancestor`` (all rotations zero)."""
        p = np.zeros(3)
        while body != ancestor:
            parent, centre_in_parent, centre_in_child = self.joints[body]
            p += centre_in_parent - centre_in_child
            body = parent
        return p


def _turn(d):
    L = np.hypot(d[0], d[1])
    c, s = -d[1] / L, d[0] / L
    return np.array([[c, s], [-s, c]]), L


def hand_segment_table(path: Path, side: str = "l", attachment_fraction: float = 0.8) -> dict:
    h = HandModel(path)
    femur, tibia = f"femur_{side}", f"tibia_{side}"
    foot = [f"talus_{side}", f"calcn_{side}", f"toes_{side}"]
    hip = h.centre(femur)
    knee_in_femur = h.origin_in(tibia, femur) + h.centre(tibia)
    A_t, L_t = _turn((knee_in_femur - hip)[:2])
    knee = h.centre(tibia)
    ankle = h.origin_in(foot[0], tibia) + h.centre(foot[0])
    A_s, L_s = _turn((ankle - knee)[:2])
    m = np.array([h.bodies[b]["mass"] for b in foot])
    r = np.array([A_s @ (h.origin_in(b, tibia) + h.bodies[b]["com"] - ankle)[:2] for b in foot])
    c_f = (m[:, None] * r).sum(axis=0) / m.sum()
    I_f = sum(h.bodies[b]["izz"] for b in foot) + float(np.sum(m * np.sum((r - c_f) ** 2, axis=1)))
    mtp = A_s @ (h.origin_in(foot[2], tibia) + h.centre(foot[2]) - ankle)[:2]
    c_t = A_t @ (h.bodies[femur]["com"] - hip)[:2]
    c_s = A_s @ (h.bodies[tibia]["com"] - knee)[:2]
    leg = h.bodies[femur]["mass"] + h.bodies[tibia]["mass"] + m.sum()
    return {
        "cart_mass_kg": sum(b["mass"] for b in h.bodies.values()) - leg,
        "mass_kg": (h.bodies[femur]["mass"], h.bodies[tibia]["mass"], m.sum()),
        "inertia_kg_m2": (h.bodies[femur]["izz"], h.bodies[tibia]["izz"], I_f),
        "length_m": (L_t, L_s, np.hypot(*mtp)),
        "com_x_m": (c_t[0], c_s[0], c_f[0]),
        "com_y_m": (c_t[1], c_s[1], c_f[1]),
        "attachment_m": attachment_fraction * L_t,
    }


# ---------------------------------------------------------------- tests


@pytest.mark.parametrize("side", ["l", "r"])
def test_scaled_gait2392_table_equals_the_hand_computation_from_the_xml(scaled_model_file, side):
    p = segments_from_model(read_model(scaled_model_file), side)
    ref = hand_segment_table(scaled_model_file, side)
    for name, value in ref.items():
        np.testing.assert_allclose(getattr(p, name), value, rtol=1e-6, atol=1e-12, err_msg=name)
    # the scaling shows: thigh length and mass of the 80 kg subject against the generic model's
    generic = segments_from_model(read_model(GAIT2392), side)
    np.testing.assert_allclose(p.length_m[0] / generic.length_m[0], 1.10, rtol=1e-12)
    np.testing.assert_allclose(p.mass_kg[0], 9.3014 * MASS_KG / 75.1646, rtol=1e-4)


def test_generic_gait2392_numbers():
    """Spot values of the generic model (the knee lies 4.5 mm behind the femur's y axis at knee angle 0)."""
    p = segments_from_model(read_model(GAIT2392), "l")
    np.testing.assert_allclose(p.mass_kg, (9.3014, 3.7075, 0.1 + 1.25 + 0.2166), rtol=1e-12)
    np.testing.assert_allclose(p.length_m[1], 0.43, rtol=1e-12)  # ankle 0.43 m below the knee in the tibia
    np.testing.assert_allclose(p.inertia_kg_m2[:2], (0.1412, 0.0511), rtol=1e-12)
    np.testing.assert_allclose(p.cart_mass_kg, 75.1646 - 14.5755, rtol=1e-12)
    ref = hand_segment_table(GAIT2392, "l")
    np.testing.assert_allclose(p.length_m[0], ref["length_m"][0], rtol=1e-9)
    assert 0.395 < p.length_m[0] < 0.397
    np.testing.assert_allclose(p.com_x_m[0], 0.17 * 0.00449986 / p.length_m[0], rtol=1e-5)  # the turned femur COM


def test_brace_markers_give_the_attachment(tmp_path):
    osim = quiet_opensim()
    model = read_model(GAIT2392)
    femur = model.getBodySet().get("femur_l")
    model.addMarker(osim.Marker("LBRA_P", femur, osim.Vec3(0.07, -0.28, -0.06)))
    model.addMarker(osim.Marker("LBRA_D", femur, osim.Vec3(0.07, -0.34, -0.06)))
    model.finalizeConnections()
    p = segments_from_model(model, "l")
    h = HandModel(GAIT2392)
    A, _ = _turn((h.origin_in("tibia_l", "femur_l") + h.centre("tibia_l") - h.centre("femur_l"))[:2])
    np.testing.assert_allclose(p.attachment_m, -(A @ np.array([0.07, -0.31]))[1], rtol=1e-12)
    assert p.attachment_m != pytest.approx(0.8 * p.length_m[0])
    q = segments_from_model(model, "l", brace_markers=("NONE_1", "NONE_2"), attachment_fraction=0.6)
    np.testing.assert_allclose(q.attachment_m, 0.6 * q.length_m[0], rtol=1e-15)


def test_generated_model_table_is_unchanged(tmp_path):
    model = build_lower_body_model(1.73, 64.9)
    a, b = tmp_path / "legacy.tsv", tmp_path / "new.tsv"
    write_segments(segment_parameters_from_model(model), a)
    path = write_model(model, tmp_path / "generated.osim")
    segments_from_model_file(path, b, ModelSettings(side="left"))
    assert a.read_bytes() == b.read_bytes()


def test_segment_table_file_of_a_user_model(scaled_model_file, tmp_path):
    out = tmp_path / "segments.tsv"
    returned = segments_from_model_file(scaled_model_file, out, ModelSettings(side="right", attachment_fraction=0.7))
    ref = hand_segment_table(scaled_model_file, "r", 0.7)
    np.testing.assert_allclose(read_segments(out).packed, returned.packed, rtol=1e-9)
    np.testing.assert_allclose(returned.attachment_m, ref["attachment_m"], rtol=1e-9)


def test_missing_body_names_file_setting_and_body(tmp_path):
    bodies = {"thigh": ["femur_{s}"], "shank": ["shin_{s}"], "foot": ["talus_{s}", "calcn_{s}"]}
    with pytest.raises(
        LoperInputError,
        match=r"gait2392_simbody\.osim: model\.segment_bodies: shank body 'shin_l' "
        r"is not in the model \(its bodies: pelvis, femur_r",
    ):
        segments_from_model_file(GAIT2392, tmp_path / "never.tsv", ModelSettings(side="left", segment_bodies=bodies))
    assert not (tmp_path / "never.tsv").exists()
    with pytest.raises(LoperInputError, match=r"gait2392_simbody\.osim: model\.segment_bodies: thigh body 'thigh_l'"):
        segments_from_model(
            read_model(GAIT2392), "l", {"thigh": ["thigh_{s}"], "shank": ["tibia_{s}"], "foot": ["toes_{s}"]}
        )
