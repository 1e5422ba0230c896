"""The ``dynamics`` step: a trial's hip, knee and ankle moments and powers, over time and per gait cycle.

:func:`inverse_dynamics` reads the scaled model, the IK coordinates, the ground reactions, the contacts, the
events and the strides of one trial (:class:`DynamicsFiles`), builds each foot's load from the plates of its
``ok`` contacts (:func:`loper_analysis.dynamics.foot_loads.foot_loads`), solves the model's inverse dynamics as
OpenSim's ``InverseDynamicsTool`` does (:func:`loper_analysis.dynamics.inverse_dynamics.generalized_forces`),
signs the moments as our angles and cuts the strides that lie in their leg's valid times
(:mod:`loper_analysis.dynamics.joint_cycles`). It writes (:class:`DynamicsOutputs`) the moments over time, the
normalised cycles and, when asked, their mean ± SD and a figure; nothing when it fails. The settings are
:class:`DynamicsSettings`.
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, SIDES
from loper_analysis.dynamics.foot_loads import FOOT_BODIES, counted_contacts, foot_loads, valid_intervals, valid_mask
from loper_analysis.dynamics.inverse_dynamics import coordinate_speeds, generalized_forces
from loper_analysis.dynamics.joint_cycles import (
    N_POINTS,
    cycle_summary,
    joint_coordinates,
    joint_cycles,
    leg_moments,
)
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike, write_figure, write_tsv
from loper_analysis.motion.ik import DEFAULT_COORDINATE_MAP
from loper_analysis.stages.dynamics.files import DynamicsFiles

__all__ = [
    "CUTOFF_HZ",
    "DynamicsOutputs",
    "DynamicsSettings",
    "NoKnownLoadWarning",
    "inverse_dynamics",
    "trial_table",
]

#: Columns of the study's table of trials (:func:`trial_table`).
TRIAL_COLUMNS: tuple[str, ...] = ("subject", "trial", "inverse_dynamics", "n_cycles_left", "n_cycles_right", "reason")

log = logging.getLogger(__name__)

#: Low-pass cut-off (Hz) of the coordinates before inverse dynamics, as in OpenSim's gait tutorials.
CUTOFF_HZ: float = 6.0


class NoKnownLoadWarning(UserWarning):
    """A trial in which a leg's foot load is never known: no ``ok`` contact of that side, no cycles."""


@dataclass(frozen=True)
class DynamicsOutputs:
    """The files one trial's inverse dynamics writes.

    Attributes
    ----------
    moments : path-like
        TSV over the IK frames: ``time_s``, per side and joint ``<joint>_<side>_moment_nm`` (N·m),
        ``_moment_nm_per_kg`` (N·m/kg), ``_power_w_per_kg`` (W/kg), and ``valid_<side>`` (True/False).
    cycles : path-like
        TSV of the normalised strides (:data:`loper_analysis.dynamics.joint_cycles.CYCLE_COLUMNS`).
    summary : path-like, optional
        TSV of their mean ± SD (:data:`loper_analysis.dynamics.joint_cycles.SUMMARY_COLUMNS`).
    figure : path-like, optional
        PNG of the mean ± SD moment (N·m/kg) and power (W/kg) per joint and side.
    """

    moments: PathLike
    cycles: PathLike
    summary: PathLike | None = None
    figure: PathLike | None = None


@dataclass(frozen=True)
class DynamicsSettings:
    """How a trial's inverse dynamics is computed.

    Attributes
    ----------
    cutoff_hz : float or None
        Low-pass cut-off (Hz) of the coordinates (OpenSim's ``lowpass_cutoff_frequency_for_coordinates``); None:
        no filter.
    foot_bodies : mapping of str to str
        Side -> the model body the foot's ground load acts on.
    coordinate_map : mapping, optional
        Our angles -> model coordinate and sign (``ik.coordinate_map``); None:
        :data:`loper_analysis.motion.ik.DEFAULT_COORDINATE_MAP`.
    n_points : int
        Points per normalised gait cycle (0 .. 100 %).
    """

    cutoff_hz: float | None = CUTOFF_HZ
    foot_bodies: Mapping[str, str] = field(default_factory=lambda: dict(FOOT_BODIES))
    coordinate_map: Mapping | None = None
    n_points: int = N_POINTS


@dataclass(frozen=True)
class _Trial:
    """One trial's inputs in memory."""

    model: object
    coordinates: pd.DataFrame
    grf: pd.DataFrame
    contacts: pd.DataFrame
    events: pd.DataFrame
    strides: pd.DataFrame


def _read(files: DynamicsFiles) -> _Trial:
    """The trial's inputs, read through :mod:`loper_analysis.io`."""
    from loper_analysis.io.opensim_tables import read_mot
    from loper_analysis.io.osim import read_model
    from loper_analysis.io.readers import read_tsv

    return _Trial(
        model=read_model(files.model_osim),
        coordinates=read_mot(files.ik_mot),
        grf=read_mot(files.grf_mot),
        contacts=read_tsv(files.contacts_tsv, "contact table", ("plate", "side", "flag", "start_s", "end_s")),
        events=read_tsv(files.events_tsv, "event table", ("side", "event", "time_s")),
        strides=read_tsv(files.strides_tsv, "stride table", ("stride", "side", "heel_strike_s", "end_s")),
    )


def _model_mass_kg(model) -> float:
    """The model's total mass (kg): the sum of its bodies' masses."""
    bodies = model.getBodySet()
    return float(sum(bodies.get(i).getMass() for i in range(bodies.getSize())))


def _frames_in_loads(coordinates: pd.DataFrame, grf: pd.DataFrame, source: str) -> pd.DataFrame:
    """The IK frames inside the ground reactions' time span (the loads must cover the frames)."""
    t = coordinates["time_s"].to_numpy(dtype=float)
    g = grf["time_s"].to_numpy(dtype=float)
    keep = (t >= g[0] - 1e-9) & (t <= g[-1] + 1e-9)
    if keep.sum() < 10:
        raise LoperInputError(
            f"{source}: only {int(keep.sum())} IK frames within the ground reactions' {g[0]:g} .. {g[-1]:g} s"
        )
    if not keep.all():
        log.warning("%s: %d IK frames outside the ground reactions' time span left out", source, int((~keep).sum()))
    return coordinates[keep].reset_index(drop=True)


def _solved_coordinates(coordinates: pd.DataFrame, source: str) -> pd.DataFrame:
    """The IK coordinates without the columns IK left undetermined (NaN throughout: they stay at the model's
    default, as in OpenSim's tool) and restricted to the longest run of frames where all others are finite."""
    values = coordinates.drop(columns="time_s")
    unsolved = [c for c in values.columns if values[c].isna().all()]
    if unsolved:
        log.info("%s: coordinates %s not determined by IK (NaN): left at the model's default", source, unsolved)
    finite = np.isfinite(values.drop(columns=unsolved).to_numpy(dtype=float)).all(axis=1)
    kept = coordinates.drop(columns=unsolved)
    if finite.all():
        return kept
    edges = np.flatnonzero(np.diff(np.concatenate([[0], finite.astype(int), [0]])))
    starts, ends = edges[0::2], edges[1::2]
    if starts.size == 0:
        raise LoperInputError(f"{source}: no IK frame with every coordinate finite")
    k = int(np.argmax(ends - starts))
    log.warning(
        "%s: %d IK frame(s) with non-finite coordinates; the longest finite run, frames %d .. %d, is used",
        source,
        int((~finite).sum()),
        starts[k],
        ends[k] - 1,
    )
    return kept.iloc[starts[k] : ends[k]].reset_index(drop=True)


def _check_heel_strikes(contacts: pd.DataFrame, events: pd.DataFrame, source: str) -> None:
    """Warn when a counted contact's start is not a heel strike of its side in the event table."""
    for side in SIDES:
        starts = counted_contacts(contacts, side).groupby("foot_contact")["start_s"].min().to_numpy(dtype=float)
        strikes = events.loc[(events["side"] == side) & (events["event"] == "heel_strike"), "time_s"]
        strikes = strikes.to_numpy(dtype=float)
        unmatched = [s for s in starts if not np.any(np.isclose(strikes, s, atol=1e-6))]
        if unmatched:
            log.warning("%s: %s contact(s) at %s s are no heel strike of the event table", source, side, unmatched)


def _moments(trial: _Trial, settings: DynamicsSettings, source: str) -> tuple[pd.DataFrame, dict]:
    """The moments' time series (with ``valid_<side>``) and each side's valid intervals (k, 2), s."""
    cmap = DEFAULT_COORDINATE_MAP if settings.coordinate_map is None else settings.coordinate_map
    frames = _frames_in_loads(_solved_coordinates(trial.coordinates, source), trial.grf, source)
    t = frames["time_s"].to_numpy(dtype=float)
    coordinates = frames.drop(columns="time_s")
    loads = foot_loads(trial.grf, trial.contacts, settings.foot_bodies)
    forces = generalized_forces(trial.model, t, coordinates, list(loads.values()), cutoff_hz=settings.cutoff_hz)
    mapped = sorted({c for c, _ in joint_coordinates(cmap).values()})
    absent = [c for c in mapped if c not in coordinates.columns]
    if absent:
        raise LoperInputError(f"{source}: the IK coordinates lack {absent} (the coordinate map's)")
    speeds = coordinate_speeds(trial.model, t, coordinates[mapped], cutoff_hz=settings.cutoff_hz)
    intervals = {side: valid_intervals(trial.contacts, side) for side in settings.foot_bodies}
    valid = {side: valid_mask(t, iv) for side, iv in intervals.items()}
    table = leg_moments(forces, speeds, cmap, _model_mass_kg(trial.model), valid)
    return table, intervals


def _figure(summary: pd.DataFrame, title: str):
    """Mean ± SD moment (N·m/kg, top) and power (W/kg, bottom) per joint (columns), one colour per side."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, len(JOINTS), figsize=(11, 6), sharex=True, squeeze=False)
    colours = {"left": "tab:blue", "right": "tab:red"}
    rows = (("moment_nm_per_kg", "moment (N·m/kg)"), ("power_w_per_kg", "power (W/kg)"))
    for j, joint in enumerate(JOINTS):
        for i, (quantity, label) in enumerate(rows):
            ax = axes[i, j]
            for side, part in summary[summary["joint"] == joint].groupby("side"):
                x, m = part["percent_cycle"].to_numpy(float), part[f"{quantity}_mean"].to_numpy(float)
                sd = np.nan_to_num(part[f"{quantity}_sd"].to_numpy(float))
                n = int(part["n_strides"].max())
                ax.plot(x, m, color=colours.get(str(side)), label=f"{side} (n = {n})")
                ax.fill_between(x, m - sd, m + sd, color=colours.get(str(side)), alpha=0.2, lw=0)
            ax.axhline(0.0, color="0.6", lw=0.5)
            ax.set_title(joint if i == 0 else "")
            ax.set_ylabel(label if j == 0 else "")
            ax.set_xlabel("gait cycle (%)" if i == 1 else "")
    if summary.empty:
        axes[0, 0].text(0.5, 0.5, "no stride in its leg's valid times", transform=axes[0, 0].transAxes, ha="center")
    else:
        axes[0, 0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def inverse_dynamics(
    files: DynamicsFiles, outputs: DynamicsOutputs, settings: DynamicsSettings = DynamicsSettings()
) -> pd.DataFrame:
    """One trial's joint moments and powers: over time, per gait cycle and (optionally) their mean ± SD.

    Parameters
    ----------
    files : DynamicsFiles
        The model, IK coordinates, ground reactions, contacts, events and strides of the trial.
    outputs : DynamicsOutputs
        Where the moments, the cycles and (when given) the summary and the figure go.
    settings : DynamicsSettings
        Cut-off (Hz), foot bodies, coordinate map and points per cycle.

    Returns
    -------
    pandas.DataFrame
        The cycles written (:data:`loper_analysis.dynamics.joint_cycles.CYCLE_COLUMNS`); empty when no stride
        lies in its leg's valid times. A side without any ``ok`` contact is warned about
        (:class:`NoKnownLoadWarning`): its moments are written, all ``valid_<side>`` False, and it has no cycle.

    Raises
    ------
    LoperInputError
        Unreadable or inconsistent inputs (through the readers and the dynamics functions); nothing is written.
    """
    source = str(files.ik_mot)
    trial = _read(files)
    _check_heel_strikes(trial.contacts, trial.events, source)
    for side in settings.foot_bodies:
        if counted_contacts(trial.contacts, side).empty:
            message = (
                f"{files.contacts_tsv}: no ok contact of the {side} foot: its load is never known, no {side} cycle"
            )
            log.warning(message)
            warnings.warn(message, NoKnownLoadWarning, stacklevel=2)
    moments, intervals = _moments(trial, settings, source)
    cycles = joint_cycles(moments, trial.strides, intervals, settings.n_points)
    summary = cycle_summary(cycles)
    figure = None if outputs.figure is None else _figure(summary, str(files.ik_mot))
    write_tsv(moments, outputs.moments)
    write_tsv(cycles, outputs.cycles)
    if outputs.summary is not None:
        write_tsv(summary, outputs.summary)
    if figure is not None:
        write_figure(figure, outputs.figure)
    log.info(
        "%s: %d normalised stride(s) per side %s",
        source,
        cycles[["side", "stride"]].drop_duplicates().shape[0],
        cycles.groupby("side")["stride"].nunique().to_dict(),
    )
    return cycles


def trial_table(
    cycles: Mapping[tuple[str, str], PathLike], without: Sequence[tuple[str, str, str]], out: PathLike
) -> pd.DataFrame:
    """The study's processed trials and their inverse dynamics: ``computed`` with the normalised cycles per side,
    or ``none`` with the reason.

    Parameters
    ----------
    cycles : mapping
        (subject, trial) -> the cycles TSV of a trial with inverse dynamics.
    without : sequence of (str, str, str)
        Subject, trial and the reason of every trial without.
    out : path-like
        The table (:data:`TRIAL_COLUMNS`), one row per trial, subjects and trials in the given order.
    """
    from loper_analysis.io.readers import read_tsv

    rows = []
    for (subject, trial), path in cycles.items():
        table = read_tsv(path, "cycle table", ("stride", "side"))
        counts = table.groupby("side")["stride"].nunique() if len(table) else pd.Series(dtype=int)
        n = {side: int(counts.get(side, 0)) for side in SIDES}
        rows.append((subject, trial, "computed", n["left"], n["right"], ""))
    rows += [(subject, trial, "none", 0, 0, reason) for subject, trial, reason in without]
    table = pd.DataFrame(rows, columns=list(TRIAL_COLUMNS))
    write_tsv(table, out)
    return table
