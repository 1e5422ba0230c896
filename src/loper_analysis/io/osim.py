"""OpenSim files on disk (models .osim, ScaleTool setups, marker sets) and the quiet import of OpenSim itself."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import staged
from loper_analysis.timing import library_import, timed_io

__all__ = [
    "quiet_opensim",
    "read_model",
    "model_source",
    "write_model",
    "write_osim_object",
    "read_scale_setup",
    "read_marker_set",
]


def quiet_opensim():
    """Import opensim with logging at 'error' and no ``opensim.log`` file in the working directory; returns the
    module."""
    with library_import():
        import opensim

    opensim.Logger.setLevelString("error")
    opensim.Logger.removeFileSink()
    return opensim


@timed_io
def read_model(path: str | os.PathLike):
    """An ``opensim.Model`` from a .osim file.

    The file must be an XML document holding a ``<Model>`` element (an
    ``<OpenSimDocument>`` with a ``<Model>``, or a bare ``<Model>``): checked
    before OpenSim reads it, since OpenSim fails on other files with
    messages that do not name them, or not at all.

    Raises
    ------
    LoperInputError
        The file is missing, is not XML, holds no ``<Model>``, or OpenSim
        cannot read it (OpenSim's message is quoted). The message names the file.
    """
    return _read_object(path, "Model", "model file", "model", element="Model")


def model_source(model) -> str:
    """How messages name an ``opensim.Model``: its .osim file (and the model's own name), or the name alone.

    A model read from a file knows the file (``getInputFileName``); a model
    built in memory has only its name.
    """
    path = (model.getInputFileName() or "").strip()
    name = model.getName()
    if path and path != "Unassigned":
        return f"{path} (model {name})"
    return f"model {name}"


def _read_object(path: str | os.PathLike, kind: str, file_name: str, what: str, element: str | None = None):
    """``opensim.<kind>`` read from ``path``, with every failure a LoperInputError naming the file.

    ``file_name`` names a missing file (``model file not found: <path>``), ``what`` the object in the other
    messages; with ``element`` the file must be XML holding that element (:func:`_require_element`) first.
    """
    path = Path(path)
    if not path.is_file():
        raise LoperInputError(f"{file_name} not found: {path}")
    if element is not None:
        _require_element(path, element, what)
    osim = quiet_opensim()
    try:
        return getattr(osim, kind)(str(path))
    except Exception as exc:  # OpenSim raises its own exception types for unreadable files
        raise LoperInputError(f"{path}: OpenSim cannot read this {what} ({exc})") from exc


def _require_element(path: Path, element: str, what: str) -> None:
    """Refuse a file that is not XML, or whose root neither is nor holds ``<element>`` (OpenSim reads any XML)."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError, UnicodeDecodeError) as exc:
        raise LoperInputError(f"{path}: not an OpenSim {what}: not an XML file ({exc})") from None
    if root.tag != element and root.find(element) is None:
        raise LoperInputError(f"{path}: not an OpenSim {what} (its <{root.tag}> element holds no <{element}>)")


def write_model(model, path: str | os.PathLike) -> Path:
    """Print an ``opensim.Model`` to a .osim file atomically; returns the path."""
    return write_osim_object(model, path, "OpenSim model")


def write_osim_object(obj, path: str | os.PathLike, what: str) -> Path:
    """Print an OpenSim object (a model, a marker set, a ScaleTool setup) to its XML file atomically; returns
    the path."""
    with staged(path, what) as tmp:
        obj.printToXML(str(tmp))
    return Path(path)


@timed_io
def read_scale_setup(path: str | os.PathLike):
    """An ``opensim.ScaleTool`` from a ScaleTool setup XML file.

    The file must be an OpenSim document holding a ``<ScaleTool>`` element
    (checked before OpenSim reads it, since OpenSim reads any XML file
    without complaint and yields an empty tool).

    Raises
    ------
    LoperInputError
        The file is missing, is not XML, is not a ScaleTool setup, or OpenSim
        cannot read it.
    """
    return _read_object(path, "ScaleTool", "scale setup file", "ScaleTool setup", element="ScaleTool")


@timed_io
def read_marker_set(path: str | os.PathLike):
    """An ``opensim.MarkerSet`` from a marker-set XML file.

    Raises
    ------
    LoperInputError
        The file is missing or OpenSim cannot read it.
    """
    return _read_object(path, "MarkerSet", "marker set file", "marker set")
