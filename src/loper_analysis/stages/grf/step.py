"""File step: ground reaction forces of a C3D's force platforms -> OpenSim external-loads ``.mot``.

C3D (ezc3d's platform extraction, :mod:`loper_analysis.io.force_platforms`)
-> resting level removed, COP, free moment, lab -> model rotation
(:mod:`loper_analysis.gait.grf`) -> ``.mot`` at the analog rate
(:func:`loper_analysis.io.external_loads.write_external_loads_mot`), columns
``{n}_ground_force_v{x,y,z}`` (N), ``{n}_ground_force_p{x,y,z}`` (m),
``{n}_ground_torque_{x,y,z}`` (N·m) for plate n = 1, 2, ...

The vertical is the lab's up direction ``up`` (lab frame): lab +Z unless
given. A lab that is not Z-up (BTS: Y-up) passes
``up=loper_analysis.motion.markers.lab_up(rotation_deg)``, the direction its
lab-to-model rotation turns into the model's +Y. The settings are
:class:`loper_analysis.gait.grf_settings.GRFSettings` (config ``grf.*``).
"""

from __future__ import annotations

import dataclasses
import logging
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.grf_settings import GRFSettings
from loper_analysis.io.atomic import PathLike

__all__ = ["grf", "trial_grf"]

log = logging.getLogger(__name__)


def grf(
    c3d_path: PathLike,
    out_mot: PathLike,
    settings: GRFSettings = GRFSettings(),
    xml_out: PathLike | None = None,
    bodies: Mapping[int, str] | None = None,
    up: Sequence[float] | None = None,
) -> pd.DataFrame:
    """C3D force platforms -> ground reaction on the body in the model frame -> external-loads ``.mot``.

    ``settings`` (:class:`GRFSettings`): ``rotation_deg`` turns the lab frame into the model frame;
    ``threshold_n`` is the vertical force above the resting level from which
    a plate counts as loaded (below it force and torque are written as 0 and
    the COP is held, see :mod:`loper_analysis.gait.grf`); ``band_n``
    and ``max_rest_n`` set the resting-level rule. With ``xml_out`` and
    ``bodies`` (plate number -> body name) an OpenSim ExternalLoads ``.xml``
    pointing at ``out_mot`` (path relative to the ``.xml``) is written too. ``up`` is the lab's up
    direction (lab frame; None: lab +Z), which the vertical force and the plates' facing are taken
    along; for a lab that is not Z-up pass ``loper_analysis.motion.markers.lab_up(rotation_deg)``. A plate
    more than 45 deg from level is refused, naming the file, the plate, its normal and ``up``.
    Returns the table written (``time_s`` plus nine columns per plate).
    """
    from loper_analysis.gait.grf import external_loads_table, plates_loads, up_vector
    from loper_analysis.io.external_loads import write_external_loads_mot, write_external_loads_xml
    from loper_analysis.io.force_platforms import read_force_platforms

    s = settings
    lab_up = None if up is None else up_vector(up, str(c3d_path))
    plates = read_force_platforms(c3d_path, lab_up)
    loads = plates_loads(plates, s.threshold_n, s.band_n, s.max_rest_n, up, str(c3d_path))
    table = external_loads_table(loads, s.rotation_deg)
    write_external_loads_mot(out_mot, table)
    if xml_out is not None and bodies:
        datafile = os.path.relpath(Path(out_mot).resolve(), Path(xml_out).resolve().parent)
        write_external_loads_xml(xml_out, bodies, datafile)
    for p in loads:
        log.info(
            "%s: plate %d: resting level %.1f N vertical, loaded %.1f %% of %d samples",
            c3d_path,
            p.number,
            p.rest_force_n @ p.up,
            100.0 * p.loaded.mean(),
            p.loaded.size,
        )
    return table


def trial_grf(
    c3d_path: PathLike,
    out_mot: PathLike,
    markers_summary_tsv: PathLike,
    settings: GRFSettings = GRFSettings(),
) -> pd.DataFrame:
    """:func:`grf` of a trial in the frame its markers were turned into: the trial's rotation is read from its
    markers summary (columns ``rotation_{x,y,z}_deg`` written by the ``markers`` step,
    the configured rotation plus the quarter turn that makes an overground trial walk along +X), so that the
    ground reactions and the inverse kinematics share one frame. The lab's up direction comes from the configured
    ``settings.rotation_deg`` (:func:`loper_analysis.motion.markers.lab_up`)."""
    from loper_analysis.io.readers import read_tsv
    from loper_analysis.motion.markers import lab_up

    columns = [f"rotation_{axis}_deg" for axis in "xyz"]
    summary = read_tsv(markers_summary_tsv, "markers summary", columns)
    if summary.empty:
        raise LoperInputError(f"{markers_summary_tsv}: the markers summary holds no row (no marker in the trial)")
    rotation = tuple(float(v) for v in summary[columns].iloc[0])
    log.info("%s: rotation %s deg (from %s)", c3d_path, list(rotation), markers_summary_tsv)
    trial = dataclasses.replace(settings, rotation_deg=rotation)
    return grf(c3d_path, out_mot, trial, up=lab_up(settings.rotation_deg))


def grf_figure(grf_mot: PathLike, events_tsv: PathLike, out_png: PathLike, title: str | None = None) -> None:
    """The trial's force plates over time with its heel strikes and toe-offs
    (:func:`loper_analysis.report.figures.gait.ground_reaction_figure`), as a PNG."""
    from loper_analysis.io.atomic import write_figure
    from loper_analysis.io.opensim_tables import read_mot
    from loper_analysis.io.readers import read_tsv
    from loper_analysis.report.figures.gait import ground_reaction_figure

    events = read_tsv(events_tsv, "event table", ("side", "event", "time_s"))
    write_figure(ground_reaction_figure(read_mot(grf_mot), events, title), out_png)
