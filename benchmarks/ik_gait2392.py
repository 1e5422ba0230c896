"""IK time per frame and agreement with OpenSim: gait2392, Rajagopal2016 and the generated model, same walking.

Usage: python benchmarks/ik_gait2392.py [duration_s] [--models generated,gait2392,rajagopal2016]
                                        [--variants "opensim 1e-5,opensim held,tree 1e-6"]
                                        (default 240 s: a 4-minute trial at 128 Hz; every variant)

One simulated walking trial (the synthetic lab's gait) drives each model: the generated sagittal model with
its 36 markers, gait2392 (23 coordinates) with its 39 scale markers and Rajagopal2016 (39 coordinates, its
own markers), the last two with their coordinates mapped from ours
(:data:`loper_analysis.synthetic.gait2392_coordinates.GAIT2392_COORDINATES`; Rajagopal2016's arms at their defaults).
Markers get 0.5 mm noise. Each model is solved, on one core, by:

* ``opensim 1e-6``: OpenSim's ``InverseKinematicsSolver`` at the pipeline's accuracy (``ik.opensim_accuracy``),
  every coordinate solved: the reference (``ik.ik_solver: opensim``);
* ``opensim 1e-5``: the same at OpenSim's default accuracy;
* ``opensim held``: the same at 1e-6 with the coordinates no marker determines (gait2392's mtp angles)
  held at their defaults instead of solved;
* ``tree 1e-6``: Gauss-Newton on the model's kinematic tree (``ik.ik_solver: tree``, the default) at the
  pipeline's step tolerance (``ik.tree_step_tolerance``, rad or m).

``--variants`` names the rows to solve besides the reference, which is always solved.

Printed per row: the solve time, the time per frame of the trial, and the largest RMS difference (deg) of
hip, knee and ankle flexion (both sides) and pelvis tilt from the reference. The time includes building the
tree and checking it against OpenSim (``tree``), not reading files.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from loper_analysis.io.osim import read_marker_set, read_model
from loper_analysis.motion.ik import inverse_kinematics, marker_positions
from loper_analysis.motion.ik_determinacy import model_tree, undetermined_coordinates
from loper_analysis.motion.model import build_lower_body_model
from loper_analysis.synthetic.gait2392_coordinates import gait2392_coordinates
from loper_analysis.synthetic.gait_curves import NominalGait
from loper_analysis.synthetic.walking import leg_length_from_height, walking_kinematics

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "gait2392"
RAJAGOPAL = ROOT / "tests" / "data" / "rajagopal2016" / "Rajagopal2016.osim"
RATE_HZ = 128.0
HEIGHT_M, MASS_KG = 1.80, 75.0
#: The angles compared, per model: ours -> (model coordinate).
STUDY_ANGLES = {
    "generated": (
        "hip_flexion_l",
        "knee_flexion_l",
        "ankle_dorsiflexion_l",
        "hip_flexion_r",
        "knee_flexion_r",
        "ankle_dorsiflexion_r",
        "pelvis_tilt",
    ),
    "gait2392": (
        "hip_flexion_l",
        "knee_angle_l",
        "ankle_angle_l",
        "hip_flexion_r",
        "knee_angle_r",
        "ankle_angle_r",
        "pelvis_tilt",
    ),
}
STUDY_ANGLES["rajagopal2016"] = STUDY_ANGLES["gait2392"]


def _models() -> dict:
    gait2392 = read_model(EXAMPLE / "gait2392_simbody.osim")
    gait2392.updateMarkerSet(read_marker_set(EXAMPLE / "gait2392_Scale_MarkerSet.xml"))
    rajagopal = read_model(RAJAGOPAL)
    models = {"generated": build_lower_body_model(HEIGHT_M, MASS_KG), "gait2392": gait2392, "rajagopal2016": rajagopal}
    for model in models.values():
        model.initSystem()
    return models


def _held(model, X: np.ndarray, labels: list[str]) -> dict:
    """Coordinate tasks holding, at its default, each coordinate that no marker determines in any frame."""
    tree = model_tree(model)
    free = undetermined_coordinates(tree, X, labels, None)
    return {c: (1.0, None) for c, never in zip(tree.coordinates, free.all(axis=0)) if never}


REFERENCE = "opensim 1e-6"
VARIANTS = ("opensim 1e-5", "opensim held", "tree 1e-6")


def _rows(name: str, model, coordinates, rng, wanted=VARIANTS) -> list[tuple]:
    markers = model.getMarkerSet()
    labels = [markers.get(i).getName() for i in range(markers.getSize())]
    cs = model.getCoordinateSet()
    names = {cs.get(i).getName() for i in range(cs.getSize())}
    values = {c: coordinates[c].to_numpy(float) for c in coordinates.columns if c in names}
    X = marker_positions(model, values, labels) + rng.normal(0.0, 0.5e-3, (len(coordinates), len(labels), 3))
    t = coordinates["time_s"].to_numpy(float)
    variants = {
        "opensim 1e-6": {"solver": "opensim", "opensim_accuracy": 1e-6},
        "opensim 1e-5": {"solver": "opensim", "opensim_accuracy": 1e-5},
        "opensim held": {"solver": "opensim", "opensim_accuracy": 1e-6, "coordinate_tasks": _held(model, X, labels)},
        "tree 1e-6": {"solver": "tree", "tree_step_tolerance": 1e-6},
    }
    if not variants["opensim held"]["coordinate_tasks"]:
        del variants["opensim held"]
    variants = {k: v for k, v in variants.items() if k == REFERENCE or k in wanted}
    rows, reference = [], None
    for variant, options in variants.items():
        t0 = time.perf_counter()
        frame = inverse_kinematics(model, t, X, labels, **options).frame()
        seconds = time.perf_counter() - t0
        reference = frame if reference is None else reference
        rms = max(float(np.degrees(np.sqrt(np.nanmean((frame[c] - reference[c]) ** 2)))) for c in STUDY_ANGLES[name])
        rows.append((name, variant, len(t), seconds, 1e3 * seconds / len(t), rms))
    return rows


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("duration_s", nargs="?", type=float, default=240.0)
    parser.add_argument("--models", default="generated,gait2392,rajagopal2016")
    parser.add_argument("--variants", default=",".join(VARIANTS), help="rows besides the reference, comma-separated")
    args = parser.parse_args(argv)
    wanted = [v.strip() for v in args.variants.split(",") if v.strip()]
    unknown = sorted(set(wanted) - set(VARIANTS))
    if unknown:
        parser.error(f"unknown variant(s) {unknown}; choose from {', '.join(VARIANTS)}")
    rng = np.random.default_rng(2024)
    coordinates, _ = walking_kinematics(
        args.duration_s,
        RATE_HZ,
        NominalGait(),
        rng,
        timing_cv=0.03,
        amplitude_cv=0.05,
        leg_length_m=leg_length_from_height(HEIGHT_M),
    )
    mapped = gait2392_coordinates(coordinates, 0.05)
    models = _models()
    rows = []
    for name in args.models.split(","):
        rows += _rows(name, models[name], coordinates if name == "generated" else mapped, rng, wanted)
    print(f"IK of {args.duration_s:g} s of walking at {RATE_HZ:g} Hz, one core")
    print("| model | solver | frames | s | ms per frame | largest RMS from opensim 1e-6 (deg) |")
    print("|---|---|---|---|---|---|")
    for name, variant, n, seconds, per_frame, rms in rows:
        print(f"| {name} | {variant} | {n} | {seconds:.1f} | {per_frame:.3f} | {rms:.4f} |")
    command = f"python benchmarks/ik_gait2392.py {args.duration_s:g} --models {args.models}"
    print(f"command: {command} --variants '{args.variants}'")


if __name__ == "__main__":
    main()
