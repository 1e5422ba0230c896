"""OpenSim models on disk (.osim) and the quiet import of OpenSim itself."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import LoperInputError
from .atomic import staged

__all__ = ["quiet_opensim", "read_model", "write_model"]


def quiet_opensim():
    """Import opensim with logging at 'error' and no ``opensim.log`` file in the working directory; returns the module."""
    import opensim

    opensim.Logger.setLevelString("error")
    opensim.Logger.removeFileSink()
    return opensim


def read_model(path: str | os.PathLike):
    """An ``opensim.Model`` from a .osim file.

    Raises
    ------
    LoperInputError
        The file is missing or OpenSim cannot read it (OpenSim's message is quoted).
    """
    path = Path(path)
    if not path.is_file():
        raise LoperInputError(f"model file not found: {path}")
    osim = quiet_opensim()
    try:
        return osim.Model(str(path))
    except Exception as exc:  # OpenSim raises its own exception types for unreadable models
        raise LoperInputError(f"{path}: OpenSim cannot read this model ({exc})") from exc


def write_model(model, path: str | os.PathLike) -> Path:
    """Print an ``opensim.Model`` to a .osim file atomically; returns the path."""
    with staged(path, "OpenSim model") as tmp:
        model.printToXML(str(tmp))
    return Path(path)
