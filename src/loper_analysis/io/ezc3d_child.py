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
        if "first_frame" in d.files:
            _write_with_extras(d, out_path)
            return
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


def _write_with_extras(d, out_path: str) -> None:
    """Build the file with ezc3d's low-level API: first frame, per-channel SCALE and OFFSET, platforms, events.

    ezc3d's Python ``write`` drops ``ANALOG:OFFSET``; its C++ writer stores
    each analog value as ``value / SCALE + OFFSET`` (float32).
    """
    from ezc3d import ezc3d as low

    c3d = low.c3d()

    def put(group: str, name: str, values, dims=None) -> None:
        values = np.asarray(values)
        flat = values.ravel(order="F")
        shape = [int(n) for n in (values.shape if dims is None else dims)]
        param = low.Parameter(name)
        if values.dtype.kind in "US":
            param.set(low.VecString([str(v) for v in flat]), shape)
        elif values.dtype.kind in "iub":
            param.set(low.VecInt([int(v) for v in flat]), shape)
        else:
            param.set(low.VecDouble([float(v) for v in flat]), shape)
        c3d.parameter(group, param)

    c3d.header().firstFrame(int(d["first_frame"]))
    for label in d["marker_labels"]:
        c3d.point(str(label))
    for label in d["analog_labels"]:
        c3d.analog(str(label))
    put("POINT", "RATE", [float(d["point_rate_hz"])])
    put("POINT", "UNITS", np.array([str(d["point_unit"])]))
    n_ch = len(d["analog_labels"])
    if n_ch:
        put("ANALOG", "RATE", [float(d["analog_rate_hz"])])
        put("ANALOG", "UNITS", d["analog_units"])
        put("ANALOG", "SCALE", d["analog_scales"].astype(float))
        put("ANALOG", "OFFSET", d["analog_offsets"].astype(np.int64))
        put("ANALOG", "GEN_SCALE", [1.0])
    n_plates = len(d["fp_type"])
    if n_plates:
        put("FORCE_PLATFORM", "USED", np.array([n_plates]))
        put("FORCE_PLATFORM", "TYPE", d["fp_type"])
        put("FORCE_PLATFORM", "ZERO", np.array([0, 0]))
        put("FORCE_PLATFORM", "CORNERS", d["fp_corners"])
        put("FORCE_PLATFORM", "ORIGIN", d["fp_origin"])
        put("FORCE_PLATFORM", "CHANNEL", d["fp_channel"])
        put("FORCE_PLATFORM", "CAL_MATRIX", d["fp_cal"])
    n_events = len(d["event_labels"])
    if n_events:
        put("EVENT", "USED", np.array([n_events]))
        put("EVENT", "CONTEXTS", d["event_contexts"])
        put("EVENT", "LABELS", d["event_labels"])
        put("EVENT", "DESCRIPTIONS", np.array([""] * n_events))
        put("EVENT", "SUBJECTS", np.array([""] * n_events))
        put("EVENT", "ICON_IDS", np.zeros(n_events, dtype=np.int64))
        put("EVENT", "GENERIC_FLAGS", np.zeros(n_events, dtype=np.int64))
        put("EVENT", "TIMES", d["event_times"])
    residuals = d["residuals"]
    masks = np.zeros((7, *residuals.shape[1:]), dtype=bool)
    c3d.import_numpy_data(d["points"], residuals, masks, d["analogs"], None)
    c3d.write(out_path, low.WriteOptions(True, False))


if __name__ == "__main__":
    write_payload(sys.argv[1], sys.argv[2])
