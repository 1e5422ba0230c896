"""A synthetic subject's truth file (``data/raw/{subject}/truth.yaml``): anthropometrics and true K, D.

The document (:func:`truth_document`) holds ``subject``, ``sex``, ``age_yr``,
``height_m``, ``mass_kg`` and ``impedance``: per onset key
``onset_{ms:03d}_ms`` and joint, ``stiffness_nm_per_rad`` and
``damping_nms_per_rad``. It is written after the header line
``# {TRUTH_HEADER}`` (:func:`write_truth`); :func:`read_truth` returns the
impedance as ``{onset_ms: {joint: {"K": ..., "D": ...}}}``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import write_yaml
from loper_analysis.io.readers import read_yaml

__all__ = ["TRUTH_HEADER", "truth_document", "truth_from_document", "write_truth", "read_truth"]

#: First line of a truth file.
TRUTH_HEADER = "true impedance of a synthetic subject (loper-analysis)"


def truth_document(anthropometry: Mapping, impedance: Mapping) -> dict:
    """The contents of ``truth.yaml``: anthropometrics and K, D per onset and joint (units in the keys)."""
    return {
        "subject": anthropometry["subject"],
        "sex": anthropometry["sex"],
        "age_yr": anthropometry["age_yr"],
        "height_m": anthropometry["height_m"],
        "mass_kg": anthropometry["mass_kg"],
        "impedance": {
            f"onset_{int(onset):03d}_ms": {
                joint: {"stiffness_nm_per_rad": v["K"], "damping_nms_per_rad": v["D"]} for joint, v in joints.items()
            }
            for onset, joints in impedance.items()
        },
    }


def truth_from_document(doc, source: str = "truth file") -> dict:
    """``{onset_ms: {joint: {"K": ..., "D": ...}}}`` from the contents of a ``truth.yaml``."""
    try:
        return {
            int(key.split("_")[1]): {
                joint: {"K": float(v["stiffness_nm_per_rad"]), "D": float(v["damping_nms_per_rad"])}
                for joint, v in joints.items()
            }
            for key, joints in doc["impedance"].items()
        }
    except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
        raise LoperInputError(f"{source}: not a readable truth file ({exc})") from exc


def write_truth(path: str | os.PathLike, anthropometry: Mapping, impedance: Mapping) -> Path:
    """Write ``truth.yaml`` atomically: :data:`TRUTH_HEADER`, then :func:`truth_document`."""
    return write_yaml(path, truth_document(anthropometry, impedance), TRUTH_HEADER)


def read_truth(path: str | os.PathLike) -> dict:
    """The true impedance of a truth file, ``{onset_ms: {joint: {"K": ..., "D": ...}}}`` (LoperInputError naming
    the file when it is missing, no YAML or no truth file)."""
    return truth_from_document(read_yaml(path, "truth file"), str(path))
