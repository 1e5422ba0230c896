"""OpenSim's own InverseDynamicsTool, run as a lab would run it, for the tests that hold the package's inverse
dynamics against it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from loper_analysis.io.osim import quiet_opensim


def opensim_inverse_dynamics(
    model_osim: Path, coordinates_mot: Path, loads_xml: Path, out: Path, times, cutoff_hz: float
) -> pd.DataFrame:
    """OpenSim's ``InverseDynamicsTool`` on ``coordinates_mot`` from ``times[0]`` to ``times[-1]`` (s) with the
    ExternalLoads file ``loads_xml``, the coordinates low-passed at ``cutoff_hz`` (Hz), every model force excluded;
    its generalised forces (``time_s`` and the columns as OpenSim names them), written under ``out``."""
    osim = quiet_opensim()
    model = osim.Model(str(model_osim))  # kept alive while the tool runs
    tool = osim.InverseDynamicsTool()
    tool.setModel(model)
    tool.setCoordinatesFileName(str(coordinates_mot))
    tool.setLowpassCutoffFrequency(cutoff_hz)
    tool.setExternalLoadsFileName(str(loads_xml))
    tool.setStartTime(times[0])
    tool.setEndTime(times[-1])
    excluded = osim.ArrayStr()
    excluded.append("All")
    tool.setExcludedForces(excluded)
    tool.setResultsDir(str(out))
    tool.setOutputGenForceFileName("opensim_id.sto")
    assert tool.run()
    table = osim.TimeSeriesTable(str(Path(out) / "opensim_id.sto"))
    names = list(table.getColumnLabels())
    time_s = np.array(table.getIndependentColumn())
    values = table.getMatrix().to_numpy().reshape(time_s.size, len(names))
    return pd.DataFrame({"time_s": time_s, **{name: values[:, j] for j, name in enumerate(names)}})
