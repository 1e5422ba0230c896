"""OpenSim external loads: the ground-reaction ``.mot`` and the ``ExternalLoads`` setup that applies it.

The ground-reaction table (force in N, point in m, torque in N·m, all in
ground) is written with ``STOFileAdapter`` (``inDegrees=no``), which
OpenSim's ``Storage``, ``ExternalLoads`` and ``ExternalForce`` read; the
ExternalLoads ``.xml`` names one ``ExternalForce`` per plate with the
identifiers ``{n}_ground_force_v``, ``{n}_ground_force_p`` and
``{n}_ground_torque_``, force and point expressed in ground. Vectors go to
OpenSim as plain Python lists (see :mod:`loper_analysis.io.opensim_tables`);
writers go through the atomic writer. Every problem raises
:class:`~loper_analysis.errors.LoperInputError` naming the file.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import staged
from loper_analysis.io.opensim_tables import storage_columns, write_storage
from loper_analysis.io.osim import quiet_opensim

__all__ = ["write_external_loads_mot", "write_external_loads_xml"]


def write_external_loads_mot(path: str | os.PathLike, frame: pd.DataFrame) -> Path:
    """Write a ground-reaction table to an OpenSim external-loads ``.mot``, atomically; returns ``path``.

    Parameters
    ----------
    path : str or path-like
        Target ``.mot`` or ``.sto`` file (a missing directory is created).
    frame : pandas.DataFrame
        Column ``time_s`` (s, finite, strictly increasing, >= 1 row) and the
        load columns, written as they are (no unit conversion): force in N,
        point in m, torque in N·m, e.g. ``1_ground_force_vx`` ...
        ``1_ground_torque_z`` (:func:`loper_analysis.gait.grf.external_loads_table`).
        The file's time column is named ``time``; NaN is written as ``nan``.

    Raises
    ------
    LoperInputError
        Wrong suffix, no ``time_s`` or no load column, bad names,
        non-numeric or infinite values, bad times, a failed write.
    """
    path = Path(path)
    t, names, values = storage_columns(path, frame, "load columns")
    return write_storage(path, t, values, names, "ExternalLoads", False, "external-loads file")


def write_external_loads_xml(
    path: str | os.PathLike, bodies: Mapping[int, str], datafile: str, name: str = "ground_reactions"
) -> Path:
    """Write an OpenSim ``ExternalLoads`` file applying plate n's loads to a body, atomically; returns ``path``.

    Parameters
    ----------
    path : str or path-like
        Target ``.xml`` file.
    bodies : mapping of int to str
        Plate number (1-based) -> name of the model body the load acts on
        (e.g. ``{1: "calcn_r", 2: "calcn_l"}``); plates left out are not applied.
    datafile : str
        The external-loads ``.mot``, as OpenSim should find it (relative
        paths are relative to the ``.xml``'s directory).
    name : str
        Name of the ExternalLoads object.

    Raises
    ------
    LoperInputError
        No plates, a plate number < 1, an empty or blank body name, a failed write.
    """
    path = Path(path)
    source = str(path)
    if not bodies:
        raise LoperInputError(f"{source}: bodies must map at least one plate number to a body")
    osim = quiet_opensim()
    loads = osim.ExternalLoads()
    loads.setName(name)
    loads.setDataFileName(str(datafile))
    for number, body in sorted(bodies.items()):
        if isinstance(number, bool) or not isinstance(number, (int, np.integer)) or number < 1:
            raise LoperInputError(f"{source}: plate numbers must be integers >= 1, got {number!r}")
        if not isinstance(body, str) or not body.strip() or body != body.strip():
            raise LoperInputError(f"{source}: plate {number}: body name must be a non-empty name, got {body!r}")
        force = osim.ExternalForce()
        force.setName(f"plate{int(number)}")
        force.set_applied_to_body(body)
        force.set_force_expressed_in_body("ground")
        force.set_point_expressed_in_body("ground")
        force.set_force_identifier(f"{int(number)}_ground_force_v")
        force.set_point_identifier(f"{int(number)}_ground_force_p")
        force.set_torque_identifier(f"{int(number)}_ground_torque_")
        force.set_data_source_name(str(datafile))
        loads.cloneAndAppend(force)
    with staged(path, "external-loads setup") as tmp:
        try:
            ok = loads.printToXML(str(tmp))
        except Exception as exc:
            raise LoperInputError(f"{source}: OpenSim could not write the external-loads setup: {exc}") from exc
        if ok is False:
            raise LoperInputError(f"{source}: OpenSim could not write the external-loads setup")
    return path
