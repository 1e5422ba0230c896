"""File steps of the processing chain: raw C3D and robot log to markers, events, forces and strides.

Chain: raw C3D -> :func:`markers` (model marker names, gap fill, lab -> model
frame, zero-phase low-pass, TRC) -> (model and IK: :mod:`.model`, :mod:`.ik`) ->
:func:`events` (GRF) -> :func:`loadcell` (robot log on the mocap clock) ->
:func:`strides` (strides, IQR outliers, cycles) -> :func:`strides_summary`.
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from loper_analysis.constants import MIN_IK_MARKERS, SIDES
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.outliers import IQR_WHISKER, MAX_OUTLIER_FRACTION, MIN_VALID_STRIDES
from loper_analysis.io.atomic import PathLike, write_tsv
from loper_analysis.io.readers import read_tsv

__all__ = ["markers", "events", "loadcell", "events_loadcell", "strides", "strides_summary"]

log = logging.getLogger(__name__)


def _label_map(
    label_map: Mapping[str, str] | PathLike | Sequence[Mapping[str, str] | PathLike] | None,
) -> Mapping[str, str] | None:
    """A label map given inline, read from its file (TSV with columns label, marker, or YAML), or several such
    maps merged in order (a later map's entry for a label wins): the map of every trial, then its kind's, then
    its own."""
    if label_map is None or isinstance(label_map, Mapping):
        return label_map
    if isinstance(label_map, (list, tuple)):
        merged: dict[str, str] = {}
        for part in label_map:
            merged.update(_label_map(part) or {})
        return merged
    from loper_analysis.io.readers import read_label_map

    return read_label_map(label_map)


def markers(
    c3d_path: PathLike,
    trc_out: PathLike,
    gaps_out: PathLike | None = None,
    rotation_deg: Sequence[float] = (-90.0, 0.0, 0.0),
    max_gap_frames: int = 10,
    cutoff_hz: float | None = 40.0,
    order: int = 4,
    duration_s: float | None = None,
    label_map: Mapping[str, str] | PathLike | Sequence | None = None,
    required_markers: Sequence[str] | None = None,
    summary_out: PathLike | None = None,
    extent_range_m: Sequence[float] = (0.1, 5.0),
    span_s: Sequence[float] | None = None,
    walking_direction: str = "fixed",
    min_travel_speed_m_per_s: float = 0.25,
) -> pd.DataFrame:
    """C3D markers -> model names -> gap fill -> lab-to-model rotation -> zero-phase low-pass -> TRC (mm).

    Labels lose their subject prefix (``Subject:LASI`` -> ``LASI``) and are
    renamed by ``label_map`` {lab label: model marker}, or by several maps
    merged in order (:func:`loper_analysis.motion.marker_names.model_marker_names`);
    every marker of ``required_markers`` must then be among them. Interior
    gaps of up to ``max_gap_frames`` frames are filled (0: none); longer gaps
    and gaps at the trial's ends stay NaN and are written to the TRC as
    missing. The low-pass (``cutoff_hz`` Hz, Butterworth of ``order`` run
    forward and backward; None or 0: no filter) runs over each run of present
    frames on its own (:func:`loper_analysis.motion.filtering.lowpass_finite_runs`).
    Times are the file's own, ``(first_frame + k) / rate``; ``duration_s``
    keeps the first ``duration_s`` seconds of the trial, ``span_s`` (start,
    end) the frames between two times of the file's clock (a crop set per
    trial). Markers whose spread lies outside ``extent_range_m`` (m) are
    refused as numbers in another unit than ``POINT:UNITS`` declares
    (:func:`loper_analysis.motion.plausibility.require_marker_extent`).

    ``walking_direction`` ``"auto"`` turns a trial that travels (overground)
    about the vertical so that it walks along the model's +X
    (:func:`loper_analysis.motion.heading.trial_heading`); ``"fixed"`` keeps
    ``rotation_deg``.

    Returns the table of filled gaps (written to ``gaps_out`` when given; one
    row per gap, :data:`loper_analysis.motion.markers.GAP_REPORT_COLUMNS`). The
    per-marker summary (:func:`loper_analysis.motion.markers.gap_summary`, with the
    lab ``label`` of each marker and the trial's frames with fewer than
    :data:`~loper_analysis.constants.MIN_IK_MARKERS` markers, its span,
    heading and rotation: :data:`TRIAL_MARKER_COLUMNS`) is written to
    ``summary_out`` when given and kept as a list of row dicts in
    ``.attrs["per_marker"]`` (plain values: pandas compares the attrs of frames
    it concatenates).
    """
    from loper_analysis.io.c3d import read_c3d
    from loper_analysis.io.opensim_tables import write_trc
    from loper_analysis.motion.filtering import lowpass_finite_runs
    from loper_analysis.motion.heading import trial_heading
    from loper_analysis.motion.marker_names import model_marker_names, require_model_markers
    from loper_analysis.motion.markers import fill_gaps, gap_summary, rotate_markers
    from loper_analysis.motion.plausibility import require_marker_extent

    source = str(c3d_path)
    rec = read_c3d(c3d_path)
    names = model_marker_names(rec.marker_labels, _label_map(label_map), source)
    if required_markers is not None:
        require_model_markers(names, required_markers, source, rec.marker_labels)
    time_s, raw = rec.time_s, rec.markers_m
    if duration_s is not None:
        keep = time_s < time_s[0] + duration_s - 1e-9
        time_s, raw = time_s[keep], raw[keep]
    if span_s is not None:
        time_s, raw = _cropped(time_s, raw, span_s, source)
    require_marker_extent(raw, source, extent_range_m)
    heading = trial_heading(raw, rec.point_rate_hz, rotation_deg, walking_direction, min_travel_speed_m_per_s, source)
    if heading.turn_deg:
        log.info(
            "%s: walks %.1f deg from the model's +X at %.2f m/s: turned %g deg about the vertical (rotation %s deg)",
            source,
            heading.heading_deg,
            heading.speed_m_per_s,
            heading.turn_deg,
            list(heading.rotation_deg),
        )
    filled, gaps = fill_gaps(raw, max_gap_frames, names, source=source, unfillable="keep")
    X = rotate_markers(filled, heading.rotation_deg)
    unfiltered = None
    if cutoff_hz:
        try:
            X, unfiltered = lowpass_finite_runs(
                X, rec.point_rate_hz, cutoff_hz, order, axis=0, setting="filter.cutoff_hz", rate_name="POINT:RATE"
            )
        except LoperInputError as exc:
            raise LoperInputError(f"{c3d_path}: markers: {exc}") from None
    summary = _trial_marker_summary(gap_summary(raw, X, names, unfiltered), rec.marker_labels, time_s, X, heading)
    log.info(
        "%s: %d frames at %g Hz, %d markers, %d gap(s) filled",
        c3d_path,
        len(time_s),
        rec.point_rate_hz,
        len(names),
        len(gaps),
    )
    write_trc(trc_out, time_s, X, names)
    if gaps_out is not None:
        write_tsv(gaps, gaps_out)
    if summary_out is not None:
        write_tsv(summary, summary_out)
    log.info("filled gaps:\n%s", gaps.to_string(index=False))
    left = summary[summary.n_missing_frames > 0]
    if len(left):
        log.warning(
            "%s: %d marker(s) still missing in some frames (written as NaN):\n%s",
            c3d_path,
            len(left),
            left[["label", "marker", "n_missing_frames", "longest_gap_frames"]].to_string(index=False),
        )
    n_sparse = int(summary["n_frames_too_few_markers"].iloc[0]) if len(summary) else 0
    if n_sparse:
        log.warning(
            "%s: %d of %d frames hold fewer than %d markers (outside the capture volume?): IK leaves them out",
            c3d_path,
            n_sparse,
            len(time_s),
            MIN_IK_MARKERS,
        )
    gaps.attrs["per_marker"] = summary.to_dict("records")
    return gaps


#: Columns the markers summary adds to :data:`loper_analysis.motion.markers.GAP_SUMMARY_COLUMNS`: the marker's lab
#: label, then facts of the whole trial repeated on each row (like ``n_frames``).
TRIAL_MARKER_COLUMNS: tuple[str, ...] = (
    "label",
    "n_frames_too_few_markers",
    "first_time_s",
    "last_time_s",
    "heading_deg",
    "speed_m_per_s",
    "turn_deg",
    "rotation_x_deg",
    "rotation_y_deg",
    "rotation_z_deg",
)


def _trial_marker_summary(per_marker: pd.DataFrame, labels: Sequence[str], time_s, markers_m, heading) -> pd.DataFrame:
    """The per-marker gap summary with the lab labels and the trial's facts (:data:`TRIAL_MARKER_COLUMNS`)."""
    present = np.all(np.isfinite(np.asarray(markers_m, float)), axis=2)
    out = per_marker.copy()
    out.insert(0, "label", [str(lab) for lab in labels])
    out["n_frames_too_few_markers"] = int((present.sum(axis=1) < MIN_IK_MARKERS).sum())
    out["first_time_s"] = float(time_s[0]) if len(time_s) else np.nan
    out["last_time_s"] = float(time_s[-1]) if len(time_s) else np.nan
    out["heading_deg"] = heading.heading_deg
    out["speed_m_per_s"] = heading.speed_m_per_s
    out["turn_deg"] = heading.turn_deg
    for axis, angle in zip("xyz", heading.rotation_deg):
        out[f"rotation_{axis}_deg"] = angle
    return out


def _cropped(time_s, markers_m, span_s: Sequence[float], source: str):
    """Frames of a trial between ``span_s`` = (start, end) in s on the file's clock; an empty crop is refused."""
    start, end = (float(v) for v in span_s)
    keep = (time_s >= start - 1e-9) & (time_s <= end + 1e-9)
    if end <= start or not keep.any():
        raise LoperInputError(
            f"{source}: the trial's span {start:g} .. {end:g} s (markers.trial_spans_s) holds no frame of the file "
            f"({time_s[0]:.4f} .. {time_s[-1]:.4f} s)"
        )
    return time_s[keep], markers_m[keep]


def events(
    c3d_path: PathLike,
    out_tsv: PathLike,
    grf_channels: Mapping[str, str] | None = None,
    threshold_on_n: float = 50.0,
    threshold_off_n: float = 20.0,
    min_stance_s: float = 0.2,
    min_swing_s: float = 0.2,
    cutoff_hz: float | None = None,
    order: int = 4,
    foot_markers: Mapping[str, str] | None = None,
    plate_sides: Mapping[str, int] | None = None,
    label_map: Mapping[str, str] | PathLike | None = None,
    rotation_deg: Sequence[float] = (-90.0, 0.0, 0.0),
    band_n: float = 10.0,
    max_rest_n: float = 100.0,
    contacts_out: PathLike | None = None,
) -> pd.DataFrame:
    """Heel strikes and toe-offs of both legs, on the mocap clock (the file's own time base).

    A file with force platforms (``FORCE_PLATFORM:USED`` > 0): each plate's
    contacts from its vertical force above the resting level, each assigned to
    a foot by the heel markers ``foot_markers`` {side: model marker, after
    ``label_map``} over the plate (:func:`loper_analysis.gait.contacts.foot_contacts`;
    ``plate_sides`` {side: plate number} is a check); flagged contacts give no
    heel strike or toe-off but a ``flagged_start``/``flagged_end`` pair that
    keeps strides from spanning them. The contact table goes to
    ``contacts_out`` when given. ``attrs["n_contacts_flagged"]`` counts them
    (:func:`loper_analysis.gait.contacts.count_flagged`).

    A file without platforms: the vertical force of each belt from the
    analog channel ``grf_channels[side]`` (N), as recorded; ``cutoff_hz``
    low-passes it first (zero-phase Butterworth; None thresholds the raw
    force: a 40 Hz filter moves a 20 N toe-off threshold by about 4.5 ms).
    """
    from loper_analysis.io.c3d import read_c3d

    table, contacts = _events_of(
        read_c3d(c3d_path),
        grf_channels,
        threshold_on_n,
        threshold_off_n,
        min_stance_s,
        min_swing_s,
        cutoff_hz,
        order,
        foot_markers,
        plate_sides,
        label_map,
        rotation_deg,
        band_n,
        max_rest_n,
    )
    return _write_events(table, contacts, out_tsv, contacts_out)


def _events_of(
    rec,
    grf_channels,
    threshold_on_n,
    threshold_off_n,
    min_stance_s,
    min_swing_s,
    cutoff_hz,
    order,
    foot_markers,
    plate_sides,
    label_map,
    rotation_deg,
    band_n,
    max_rest_n,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The event table and the contact table (empty without force platforms) of a C3D already read."""
    from loper_analysis.gait.contacts import count_flagged

    if rec.n_force_platforms:
        table, contacts = _plate_events(
            rec,
            foot_markers,
            plate_sides,
            label_map,
            rotation_deg,
            threshold_on_n,
            threshold_off_n,
            min_stance_s,
            min_swing_s,
            band_n,
            max_rest_n,
        )
        log.info("contacts:\n%s", contacts.to_string(index=False))
        table.attrs["n_contacts_flagged"] = count_flagged(contacts["flag"])
        return table, contacts
    if not grf_channels:
        raise LoperInputError(
            f"{rec.source}: no force platforms (FORCE_PLATFORM:USED is 0 or absent) and no GRF channel configured "
            "(events.grf_channels); cannot detect gait events"
        )
    table = _channel_events(
        rec, grf_channels, threshold_on_n, threshold_off_n, min_stance_s, min_swing_s, cutoff_hz, order
    )
    _check_belt_feet(rec, table, grf_channels, foot_markers, label_map, rotation_deg)
    table.attrs["n_contacts_flagged"] = 0
    return table, pd.DataFrame(columns=["plate", "contact", "side", "flag"])


def _write_events(
    table: pd.DataFrame, contacts: pd.DataFrame, out_tsv: PathLike, contacts_out: PathLike | None
) -> pd.DataFrame:
    """Write the event table (and the contact table when asked); returns the event table."""
    if contacts_out is not None:
        write_tsv(contacts, contacts_out)
    write_tsv(table, out_tsv)
    log.info("events per side and kind:\n%s", table.groupby(["side", "event"]).size().to_string())
    return table


def _channel_events(
    rec, grf_channels, threshold_on_n, threshold_off_n, min_stance_s, min_swing_s, cutoff_hz, order
) -> pd.DataFrame:
    """Events from one named vertical-GRF analog channel per belt of a read C3D."""
    from loper_analysis.gait.events import gait_events
    from loper_analysis.motion.filtering import lowpass

    c3d_path = rec.source
    tables = []
    for side in SIDES:
        fz = rec.analog(grf_channels[side])
        if cutoff_hz is not None:
            fz = lowpass(
                fz,
                rec.analog_rate_hz,
                cutoff_hz,
                order,
                setting="events.grf_cutoff_hz",
                rate_name="ANALOG:RATE",
                source=f"{c3d_path} (analog channel {grf_channels[side]})",
            )
        tables.append(
            gait_events(
                rec.analog_time_s,
                fz,
                side,
                threshold_on_n,
                threshold_off_n,
                min_stance_s,
                min_swing_s,
                source=f"{c3d_path} ({grf_channels[side]})",
            )
        )
    return pd.concat(tables, ignore_index=True).sort_values(["time_s", "side"], kind="stable", ignore_index=True)


#: Fewest stances of a belt, with both heels seen at mid-stance, that can confirm the belt's foot.
MIN_JUDGED_STANCES = 3
#: A belt is taken for the other foot's when its own heel was the lower in at most this fraction of its
#: stances; between it and 1 - it the belt's foot is unclear (a warning).
SWAPPED_BELT_FRACTION = 0.25


def _check_belt_feet(rec, table: pd.DataFrame, grf_channels, foot_markers, label_map, rotation_deg) -> None:
    """Confirm from the heel markers that each belt channel carries the foot it is named for.

    Stops when a belt's stances are the other foot's (channels swapped, or both naming one belt); warns when
    the heel markers cannot tell (missing markers, too few stances, a mixed verdict).
    """
    from loper_analysis.gait.events import stance_heels
    from loper_analysis.motion.marker_names import model_marker_names
    from loper_analysis.motion.markers import lab_up

    source = rec.source
    keys = {s: f"events.grf_channels.{s}" for s in SIDES}
    if not foot_markers or not rec.marker_labels:
        warnings.warn(
            f"{source}: the belts' feet ({', '.join(f'{keys[s]} {grf_channels[s]}' for s in SIDES)}) "
            "could not be confirmed: no heel markers (events.foot_markers) in the file",
            stacklevel=2,
        )
        return
    names = model_marker_names(rec.marker_labels, _label_map(label_map), source)
    missing = [foot_markers[s] for s in SIDES if foot_markers[s] not in names]
    if missing:
        warnings.warn(
            f"{source}: the belts' feet could not be confirmed: heel marker(s) {', '.join(missing)} "
            "(events.foot_markers) not in the file",
            stacklevel=2,
        )
        return
    up = lab_up(rotation_deg)
    heights = {s: rec.markers_m[:, names.index(foot_markers[s]), :] @ up for s in SIDES}
    table.attrs["source"] = source
    stances = stance_heels(table, rec.time_s, heights)
    judged = stances[np.isfinite(stances["own_heel_lower_m"])]
    for side in SIDES:
        other = "right" if side == "left" else "left"
        mine = judged[judged["side"] == side]
        n, own = len(mine), int(mine["own_heel_lower"].sum())
        if n < MIN_JUDGED_STANCES:
            warnings.warn(
                f"{source}: the {side} belt's foot ({keys[side]} {grf_channels[side]}) could not be "
                f"confirmed: {n} stance(s) with both heels seen at mid-stance (at least "
                f"{MIN_JUDGED_STANCES} needed)",
                stacklevel=2,
            )
        elif own <= SWAPPED_BELT_FRACTION * n:
            raise LoperInputError(
                f"{source}: {keys[side]}: channel {grf_channels[side]} does not carry the {side} foot: in "
                f"{n - own} of its {n} stances the {other} heel ({foot_markers[other]}) was the lower at "
                f"mid-stance (by {mine['own_heel_lower_m'].median() * -1000:.0f} mm, median); are the belts' "
                f"channels swapped (events.grf_channels: {{left: {grf_channels['left']}, "
                f"right: {grf_channels['right']}}})?"
            )
        elif own < (1 - SWAPPED_BELT_FRACTION) * n:
            warnings.warn(
                f"{source}: the {side} belt's foot ({keys[side]} {grf_channels[side]}) is unclear: its "
                f"own heel ({foot_markers[side]}) was the lower at mid-stance in {own} of {n} stances",
                stacklevel=2,
            )
    log.info(
        "belts' feet: own heel the lower at mid-stance in %s",
        ", ".join(
            f"{int(judged.loc[judged['side'] == s, 'own_heel_lower'].sum())} of {int((judged['side'] == s).sum())} "
            f"{s} stances"
            for s in SIDES
        ),
    )


def _plate_events(
    rec,
    foot_markers,
    plate_sides,
    label_map,
    rotation_deg,
    threshold_on_n,
    threshold_off_n,
    min_stance_s,
    min_swing_s,
    band_n,
    max_rest_n,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Events and the contact table from the force platforms and the heel markers of a read C3D.

    The vertical is the lab's up direction that ``rotation_deg`` turns into the model's +Y
    (:func:`loper_analysis.motion.markers.lab_up`: lab +Z for the default -90 deg about X, +Y for a Y-up lab
    with no rotation); plates whose corners run either way round are accepted, a plate more than 45 deg
    from level is refused naming the file, the plate and ``markers.lab_to_model_rotation_deg``.
    """
    from loper_analysis.gait.contacts import PlateForce, contact_events, foot_contacts
    from loper_analysis.gait.grf import plate_vertical_loads
    from loper_analysis.motion.marker_names import model_marker_names, require_model_markers
    from loper_analysis.motion.markers import MODEL_UP, lab_up, rotate_markers

    source = c3d_path = rec.source
    if not foot_markers:
        raise LoperInputError(f"{source}: force platforms need the heel marker of each foot (events.foot_markers)")
    names = model_marker_names(rec.marker_labels, _label_map(label_map), source)
    require_model_markers(names, [foot_markers[s] for s in SIDES], source, rec.marker_labels)
    loads = plate_vertical_loads(c3d_path, rotation_deg, band_n, max_rest_n, up=lab_up(rotation_deg))
    plates = [
        PlateForce(n, loads.time_s, loads.vertical_n[:, i], loads.corners_m[i]) for i, n in enumerate(loads.numbers)
    ]
    heels = {s: rotate_markers(rec.markers_m[:, names.index(foot_markers[s]), :], rotation_deg) for s in SIDES}
    # corners and heels are in the model frame, whose up is +Y
    contacts = foot_contacts(
        plates,
        rec.time_s,
        heels,
        plate_sides,
        threshold_on_n,
        threshold_off_n,
        min_stance_s,
        min_swing_s,
        source=source,
        up=MODEL_UP,
    )
    return contact_events(contacts), contacts


#: Significant digits of the robot-rate force table: its times need microseconds over long trials.
NATIVE_FLOAT_FORMAT = "%.12g"


def loadcell(
    c3d_path: PathLike,
    log_path: PathLike,
    out_tsv: PathLike,
    sync_channel: str = "sync",
    cutoff_hz: float = 40.0,
    order: int = 4,
    native_out: PathLike | None = None,
) -> pd.DataFrame:
    """The robot log's forces on the mocap frames (sync-pulse clock map, 40 Hz low-pass, 128 Hz).

    ``native_out``: also the same filtered forces at the robot log's own rate, on the mocap clock.
    Nothing is written when the records are refused, among others for sync pulses whose high times
    disagree between the robot log and the C3D (an inverted sync) or force pulses without perturbation
    flags (:func:`loper_analysis.device.loadcell.robot_log_frames_and_native`).
    """
    from loper_analysis.io.c3d import read_c3d

    out, native = _loadcell_of(read_c3d(c3d_path), log_path, sync_channel, cutoff_hz, order)
    return _write_loadcell(out, native, out_tsv, native_out)


def _loadcell_of(rec, log_path, sync_channel, cutoff_hz, order) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The forces on the mocap frames and at the robot rate, of a C3D already read and a robot log."""
    from loper_analysis.device.loadcell import robot_log_frames_and_native
    from loper_analysis.io.robot_log import read_robot_log

    c3d_path = rec.source
    frame, meta = read_robot_log(log_path)
    rate = float(meta["sample_rate_hz"])
    from loper_analysis.motion.filtering import check_cutoff  # the robot log's forces are low-passed at its own rate

    check_cutoff(
        rate, cutoff_hz, order, setting="filter.cutoff_hz", rate_name="the log's sample_rate_hz", source=str(log_path)
    )
    out, native = robot_log_frames_and_native(
        frame,
        rate,
        rec.analog(sync_channel),
        rec.analog_rate_hz,
        rec.time_s,
        cutoff_hz=cutoff_hz,
        order=order,
        source=f"{log_path} / {c3d_path}",
        sync_channel=sync_channel,
    )
    cm = out.attrs.get("clock_map")
    if cm is not None:
        log.info("%s: clock map %s", log_path, cm)
    return out, native


def _write_loadcell(
    out: pd.DataFrame, native: pd.DataFrame, out_tsv: PathLike, native_out: PathLike | None
) -> pd.DataFrame:
    """Write the forces on the mocap frames (and at the robot rate when asked); returns the former."""
    write_tsv(out, out_tsv)
    log.info("%d frames on the mocap clock", len(out))
    if native_out is not None:
        write_tsv(native, native_out, NATIVE_FLOAT_FORMAT)
        log.info("%d robot samples on the mocap clock", len(native))
    return out


def events_loadcell(
    c3d_path: PathLike,
    log_path: PathLike,
    events_out: PathLike,
    contacts_out: PathLike,
    force_out: PathLike,
    native_out: PathLike,
    events_settings: Mapping | None = None,
    loadcell_settings: Mapping | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """:func:`events` and :func:`loadcell` of one trial with the device, from one reading of its C3D.

    ``events_settings`` and ``loadcell_settings`` are the keyword arguments of
    :func:`events` and :func:`loadcell` (without paths). Nothing is written
    unless both succeed. Returns the event table and the force table on the
    mocap frames.
    """
    from loper_analysis.io.c3d import read_c3d

    e, f = dict(events_settings or {}), dict(loadcell_settings or {})
    for given, func in ((e, events), (f, loadcell)):
        unknown = set(given) - set(_keyword_defaults(func)) - {"contacts_out", "native_out"}
        if unknown:
            raise TypeError(f"{func.__name__}: unknown setting(s) {sorted(unknown)}")
    e = {k: v for k, v in {**_keyword_defaults(events), **e}.items() if k != "contacts_out"}
    f = {k: v for k, v in {**_keyword_defaults(loadcell), **f}.items() if k != "native_out"}
    rec = read_c3d(c3d_path)
    table, contacts = _events_of(rec, **e)
    forces = _loadcell_of(rec, log_path, **f)  # both computed before anything is written
    _write_events(table, contacts, events_out, contacts_out)
    return table, _write_loadcell(*forces, force_out, native_out)


def _keyword_defaults(func) -> dict:
    """Keyword defaults of a step function."""
    import inspect

    return {
        k: v.default for k, v in inspect.signature(func).parameters.items() if v.default is not inspect.Parameter.empty
    }


def strides(
    angles_tsv: PathLike,
    events_tsv: PathLike,
    strides_out: PathLike,
    cycles_out: PathLike,
    force_tsv: PathLike | None = None,
    side: str = "left",
    n_points: int = 101,
    whisker: float = IQR_WHISKER,
    max_fraction: float = MAX_OUTLIER_FRACTION,
    min_valid: int = MIN_VALID_STRIDES,
):
    """Strides of one leg, their outlier verdicts and the time-normalised cycles of one trial.

    Writes the stride table and the cycles (:func:`loper_analysis.gait.strides.stride_tables`);
    returns the :class:`~loper_analysis.gait.strides.StrideTables`. A trial with 0
    or 1 strides of ``side`` is written like any other (the stride table with
    all its columns, without rows for 0 strides) and flagged ``too_few_strides``.
    """
    from loper_analysis.gait.strides import stride_tables

    sources = {"angles": str(angles_tsv), "events": str(events_tsv), "force": str(force_tsv)}
    force = None if force_tsv is None else read_tsv(force_tsv, "force table", ("time_s", "force_measured_n"))
    tables = stride_tables(
        read_tsv(angles_tsv, "angle table"),
        read_tsv(events_tsv, "event table"),
        force,
        side,
        n_points,
        whisker,
        max_fraction,
        min_valid,
        sources,
    )
    write_tsv(tables.cycles, cycles_out)
    write_tsv(tables.strides, strides_out)
    s = tables.strides
    log.info("%d strides, %d kept", len(s), int((~s["removed"]).sum()))
    return tables


def strides_summary(
    subject_trials: Sequence[tuple[str, str]],
    strides_tsvs: Sequence[PathLike],
    out_tsv: PathLike,
    min_valid: int = MIN_VALID_STRIDES,
    contacts_tsvs: Sequence[PathLike] | None = None,
    ik_tsvs: Sequence[PathLike] | None = None,
    markers_tsvs: Sequence[PathLike] | None = None,
) -> pd.DataFrame:
    """One row per subject x trial of the stride tables (:func:`loper_analysis.gait.strides.stride_summary`).

    ``strides_tsvs`` holds one stride table per ``(subject, trial)`` of
    ``subject_trials``, in order; ``contacts_tsvs`` (optional, same order) the
    force-plate contact tables written by :func:`events`, whose flagged
    contacts are counted. A stride table of a trial with 0 strides (its
    header only, as :func:`strides` writes it) gives ``n_strides`` 0 and the
    status ``too_few_strides``. ``ik_tsvs`` (the IK summaries of
    :func:`loper_analysis.steps.ik.ik_trial`) add the frames and those left
    out of IK, ``markers_tsvs`` (the markers summaries of :func:`markers`) the
    trial's walking direction and the turn that made it walk along +X.

    Raises
    ------
    LoperInputError
        A stride table without the columns
        :data:`loper_analysis.gait.strides.SUMMARY_COLUMNS` (naming the file).
    """
    from loper_analysis.checks import require_columns
    from loper_analysis.gait.strides import SUMMARY_COLUMNS, stride_summary

    keys = [tuple(key) for key in subject_trials]
    tables = {
        key: require_columns(
            read_tsv(path, "stride table", keep_default_na=False, na_values=[""]),
            SUMMARY_COLUMNS,
            str(path),
            "stride table",
        )
        for key, path in zip(keys, strides_tsvs, strict=True)
    }
    contacts = None
    if contacts_tsvs is not None:
        contacts = {
            key: read_tsv(path, "contact table", ("flag",), keep_default_na=False)
            for key, path in zip(keys, contacts_tsvs, strict=True)
        }
    table = stride_summary(tables, min_valid, contacts)
    extra = []
    if ik_tsvs is not None:
        ik = [read_tsv(path, "IK summary", ("n_frames", "n_frames_left_out")).iloc[0] for path in ik_tsvs]
        extra.append(
            pd.DataFrame(
                {"n_frames": [int(r.n_frames) for r in ik], "n_frames_left_out": [int(r.n_frames_left_out) for r in ik]}
            )
        )
    if markers_tsvs is not None:
        marks = [
            read_tsv(path, "markers summary", ("heading_deg", "speed_m_per_s", "turn_deg")).iloc[0]
            for path in markers_tsvs
        ]
        extra.append(
            pd.DataFrame(
                {
                    "heading_deg": [float(r.heading_deg) for r in marks],
                    "speed_m_per_s": [float(r.speed_m_per_s) for r in marks],
                    "turn_deg": [float(r.turn_deg) for r in marks],
                }
            )
        )
    if extra:
        table = pd.concat([table, *extra], axis=1)
    write_tsv(table, out_tsv)
    for row in table[table.status != "ok"].itertuples():
        log.warning("%s %s: only %d valid strides (minimum %d)", row.subject, row.trial, row.n_kept, min_valid)
    log.info("strides:\n%s", table.to_string(index=False))
    return table
