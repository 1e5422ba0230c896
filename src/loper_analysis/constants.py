"""Names shared by the library, the rules and the tables: sides, joints, coordinates, parameters, columns.

Sign convention (the one statement of it in the code; ``docs/conventions.md``
explains it with figures in words):

* Units are SI inside (m, rad, N, s); units appear in names (``time_s``,
  ``hip_left_rad``, ``K_nm_per_rad``).
* Swing-leg coordinates ``q = [x, q_thigh, q_shank, q_foot]``: cart
  (pelvis) position in m, forward positive, and global segment angles in
  rad, zero when the segment hangs (thigh, shank) or is in its neutral pose
  (foot), positive when the distal end moves backward.
* Joint angles are flexion positive::

      theta_hip   = theta_pelvis - q_thigh      (hip flexion)
      theta_knee  = q_shank - q_thigh           (knee flexion)
      theta_ankle = q_shank - q_foot            (ankle dorsiflexion)

  and the generalised forces of joint torques follow by virtual work::

      u_x = 0,  u_thigh = -T_hip - T_knee,  u_shank = T_knee + T_ankle,  u_foot = -T_ankle

* Forces are positive forward (walking direction) and up; the model frame
  has X forward, Y up, Z to the right (OpenSim's).
"""

from __future__ import annotations

__all__ = [
    "LOADED_THRESHOLD_N",
    "MAX_RESTING_N",
    "RESTING_BAND_N",
    "SIDES",
    "SIDE_SUFFIX",
    "JOINTS",
    "SEGMENTS",
    "PARAMETERS",
    "PARAMETER_UNITS",
    "COUPLINGS",
    "COUPLING_PARAMETERS",
    "COUPLING_UNIT",
    "UNIT_SUFFIX",
    "FLAGGED_EVENTS",
    "CONTACT_FLAGS",
    "PHASES",
    "LAB_Z_UP",
    "LAB_TO_MODEL_ROTATION_DEG",
    "GRAVITY_M_PER_S2",
    "MIN_IK_MARKERS",
    "angle_column",
    "parameter_column",
]

#: Sides of the body, as written in tables and config (one treadmill belt each).
SIDES: tuple[str, ...] = ("left", "right")
#: Suffix of each side in OpenSim body, joint and coordinate names (``thigh_l``, ``hip_flexion_r``).
SIDE_SUFFIX: dict[str, str] = {"left": "l", "right": "r"}
#: Joints of the swing leg, in model order.
JOINTS: tuple[str, ...] = ("hip", "knee", "ankle")
#: Rigid segments of the swing leg, proximal to distal.
SEGMENTS: tuple[str, ...] = ("thigh", "shank", "foot")
#: Identified parameters, in the order of every parameter vector.
PARAMETERS: tuple[str, ...] = ("K_hip", "D_hip", "K_knee", "D_knee", "K_ankle", "D_ankle")
#: Units of the identified parameters.
PARAMETER_UNITS: dict[str, str] = {p: ("N·m/rad" if p.startswith("K") else "N·m·s/rad") for p in PARAMETERS}
#: Inter-joint (bi-articular) stiffness couplings the fit may add, by the pair of neighbouring joints they link:
#: ``hip_knee`` adds ``-K_hip_knee dtheta_knee`` to the hip torque and ``-K_hip_knee dtheta_hip`` to the knee's,
#: ``knee_ankle`` the same between knee and ankle (a symmetric stiffness matrix; ``docs/identification.md``,
#: "Bi-articular stiffness").
COUPLINGS: tuple[str, ...] = ("hip_knee", "knee_ankle")
#: Their parameter names, after :data:`PARAMETERS` in a fit's parameter vector, in this order.
COUPLING_PARAMETERS: tuple[str, ...] = tuple(f"K_{c}" for c in COUPLINGS)
#: Unit of a coupling stiffness.
COUPLING_UNIT: str = "N·m/rad"
#: Unit suffix of stiffness (K) and damping (D) in column names.
UNIT_SUFFIX: dict[str, str] = {"K": "nm_per_rad", "D": "nms_per_rad"}
#: Rows of an event table that bound a flagged foot contact (no gait event; strides must not span it).
FLAGGED_EVENTS: tuple[str, ...] = ("flagged_start", "flagged_end")
#: Verdicts on a force-plate contact (``docs/events.md``): ``ok`` gives events, every other one does not.
CONTACT_FLAGS: tuple[str, ...] = ("ok", "incomplete", "heel_missing", "two_feet", "no_foot", "off_plate", "wrong_belt")
#: Normalisation phases: the whole stride (HS -> next HS), stance (HS -> TO), swing (TO -> next HS).
PHASES: tuple[str, ...] = ("stride", "stance", "swing")
GRAVITY_M_PER_S2: float = 9.81
#: Up direction of a Z-up lab (Qualisys, Vicon; what ezc3d assumes), lab frame:
#: :func:`loper_analysis.motion.markers.lab_up` of ``(-90, 0, 0)``.
LAB_Z_UP: tuple[float, float, float] = (0.0, 0.0, 1.0)
#: Lab -> model rotation (degrees about the fixed X, Y, Z axes) of a Z-up lab: Qualisys Z-up -> OpenSim Y-up
#: (config ``markers.lab_to_model_rotation_deg``).
LAB_TO_MODEL_ROTATION_DEG: tuple[float, float, float] = (-90.0, 0.0, 0.0)
#: Fewest weighted markers present in a frame for IK to solve it (three fix one rigid body).
MIN_IK_MARKERS: int = 3


#: A force plate is loaded above this vertical force over its resting level (N; config
#: ``grf.loaded_threshold_n``).
LOADED_THRESHOLD_N: float = 20.0


def angle_column(joint: str, side: str) -> str:
    """Column of a joint angle in the angle and cycle tables, e.g. ``hip_left_rad``."""
    return f"{joint}_{side}_rad"


def parameter_column(kind: str, what: str = "") -> str:
    """Column of a stiffness or damping quantity with its unit, e.g. ``K_nm_per_rad``, ``D_ci95_low_nms_per_rad``.

    ``kind`` is ``"K"`` or ``"D"``; ``what`` an optional qualifier (``ci95_low``, ``true``, ``error``, ``mean`` ...).
    """
    middle = f"_{what}" if what else ""
    return f"{kind}{middle}_{UNIT_SUFFIX[kind]}"


#: A force plate's resting level: samples within this of a plate's lowest vertical force are unloaded (N; config
#: ``grf.resting_band_n``) ...
RESTING_BAND_N: float = 10.0
#: ... and their median, the resting level, must lie within +- this (N; ``grf.max_resting_n``).
MAX_RESTING_N: float = 100.0
