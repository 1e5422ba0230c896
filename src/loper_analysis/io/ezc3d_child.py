"""The child process that writes a C3D file with ezc3d: ``python -m loper_analysis.io.ezc3d_child PAYLOAD OUT``.

:func:`loper_analysis.io.c3d_writer.write_c3d` runs ezc3d's writer here, in
a fresh Python process that never loads OpenSim: in one process the two
libraries' SWIG wrappers share the converters of ``std::vector`` and break
each other's vector arguments. This module imports only NumPy and ezc3d,
so the child starts fast.
"""

from __future__ import annotations

import sys

import numpy as np

__all__ = ["write_payload"]


def write_payload(payload_path: str, out_path: str) -> None:
    """Build the ezc3d object from the payload (.npz of :func:`loper_analysis.io.c3d_writer.write_c3d`) and write it."""
    import ezc3d

    with np.load(payload_path, allow_pickle=False) as d:
        c3d = ezc3d.c3d()
        P = c3d["parameters"]["POINT"]
        P["RATE"]["value"] = [float(d["point_rate_hz"])]
        P["LABELS"]["value"] = [str(v) for v in d["marker_labels"]]
        P["UNITS"]["value"] = [str(d["point_unit"])]
        residuals = d["residuals"]
        c3d["data"]["meta_points"] = {
            "residuals": residuals,
            "camera_masks": np.zeros((7, *residuals.shape[1:]), dtype=bool),
        }
        c3d["data"]["points"] = d["points"]
        n_ch = len(d["analog_labels"])
        if n_ch:
            A = c3d["parameters"]["ANALOG"]
            A["RATE"]["value"] = [float(d["analog_rate_hz"])]
            A["LABELS"]["value"] = [str(v) for v in d["analog_labels"]]
            A["UNITS"]["value"] = [str(v) for v in d["analog_units"]]
            A["SCALE"]["value"] = [1.0] * n_ch
            A["OFFSET"]["value"] = [0] * n_ch
            A["GEN_SCALE"]["value"] = [1.0]
            c3d["data"]["analogs"] = d["analogs"]
    c3d.write(out_path)


if __name__ == "__main__":
    write_payload(sys.argv[1], sys.argv[2])
