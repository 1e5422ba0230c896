"""A simulated subject's session as a lab exports it (QTM C3D files and MATLAB robot logs), for the tests that
meet a lab's files: :func:`lab_export_session` with :class:`LabExportSettings` and :class:`LabExportFiles`."""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields

from loper_analysis.io.atomic import PathLike
from loper_analysis.io.c3d_writer import write_recording
from loper_analysis.stages.settings import stage_settings
from loper_analysis.swing_leg.dynamics import BRACE_ATTACHMENT_FRACTION
from loper_analysis.synthetic.lab_session import SyntheticLabSettings
from tests.qtm_export import QTMExportSettings

log = logging.getLogger(__name__)

#: K, D per joint (K_hip, D_hip, K_knee, D_knee, K_ankle, D_ankle in N·m/rad and N·m·s/rad) a subject of
#: :func:`lab_export_session` answers the pulses with: the config's group truth at 50 ms
#: (``synthetic.stiffness_nm_per_rad``, ``synthetic.damping_nms_per_rad``).
LAB_EXPORT_IMPEDANCE: tuple[float, ...] = (55.0, 3.5, 3.0, 0.1, 8.0, 0.3)


@dataclass(frozen=True)
class LabExportSettings(SyntheticLabSettings):
    """Settings of :func:`lab_export_session`: the recording (:class:`SyntheticLabSettings`; the gentle lab) and
    the export.

    Attributes
    ----------
    export : QTMExportSettings
        How the files look (first frame, label prefix, gaps, plates and channels).
    brace_fraction : float
        The brace markers' centre and the rod attachment along the left thigh (fraction of its length from the
        hip; ``model.brace_attachment_fraction``).
    """

    export: QTMExportSettings = QTMExportSettings()
    brace_fraction: float = BRACE_ATTACHMENT_FRACTION

    @classmethod
    def from_config(cls, config: Mapping) -> LabExportSettings:
        """The settings of the whole validated config: the synthetic lab's recording and the model's rod
        attachment (``export`` keeps its defaults: no config key)."""
        lab = stage_settings(config, "synthetic")
        recording = {f.name: getattr(lab, f.name) for f in fields(SyntheticLabSettings)}
        return cls(**recording, brace_fraction=stage_settings(config, "model").attachment_fraction)


@dataclass(frozen=True)
class LabExportFiles:
    """The files of :func:`lab_export_session`.

    Attributes
    ----------
    out_dir : path
        Folder of the session's files (written).
    model_osim : path
        The OpenSim model whose markers and segments the subject has (read).
    marker_set_xml : path
        The model's marker set (read).
    label_map_tsv : path
        The lab's labels of the model's markers (read; columns ``label``, ``marker``).
    """

    out_dir: PathLike
    model_osim: PathLike
    marker_set_xml: PathLike
    label_map_tsv: PathLike


def lab_export_session(
    files: LabExportFiles,
    subject: str,
    trials: Sequence[str],
    height_m: float,
    mass_kg: float,
    settings: LabExportSettings,
    impedance: Sequence[float] = LAB_EXPORT_IMPEDANCE,
) -> dict:
    """One subject's session as the lab exports it (QTM C3D + MATLAB robot logs), into ``files.out_dir``.

    Writes ``{static}.c3d`` (the static trial of ``settings.design``) and per
    trial of ``trials`` ``{trial}.c3d``, plus ``{trial}.mat`` for every trial
    but the design's ``no_device``
    (:func:`tests.qtm_export.qtm_walking_export`, variables
    :data:`~tests.qtm_export.ROBOT_LOG_MAT_VARIABLES`, time
    in s). The markers are those of ``files.label_map_tsv`` (columns ``label``,
    ``marker``) on the model ``files.model_osim`` with the marker set
    ``files.marker_set_xml``, plus the two brace markers ``LBRA_P`` and ``LBRA_D``
    on the left thigh (:func:`tests.qtm_export.add_brace_markers`,
    centred at ``settings.brace_fraction`` of the thigh length; their labels are their
    names unless the map lists them); the kinematics are simulated for a
    subject of ``height_m`` and ``mass_kg``, and the perturbation responses
    with the swing-leg segment table of the model itself
    (:func:`loper_analysis.motion.segments.segments_from_model`, left leg,
    rod attachment at ``settings.brace_fraction``), so that a fit with the table of the
    same model scaled by factors of 1 meets the exact truth. A trial's pulses
    start at its onset in ``settings.design`` (ms after left toe-off; none for
    walking without pulses) and are answered with ``impedance`` (K_hip, D_hip,
    K_knee, D_knee, K_ankle, D_ankle in N·m/rad and N·m·s/rad). Seeded by
    ``settings.seed``, subject and trial: the same arguments give the same files.

    Returns
    -------
    dict
        ``{static: LabExport, trial: (WalkingTrial, LabExport), ...}``:
        the truth behind the files (coordinates, forces, events, perturbations).
    """
    import zlib
    from pathlib import Path

    import numpy as np

    from loper_analysis.io.osim import quiet_opensim, read_model
    from loper_analysis.io.readers import read_tsv
    from loper_analysis.motion.segments import segments_from_model
    from loper_analysis.synthetic.trials import simulate_walking_trial
    from tests.io.robot_log_mat_files import write_robot_log_mat
    from tests.qtm_export import ROBOT_LOG_MAT_VARIABLES, add_brace_markers, qtm_static_export, qtm_walking_export

    def seeded(*names: str) -> np.random.SeedSequence:
        return np.random.SeedSequence([int(settings.seed), *(zlib.crc32(n.encode()) for n in (subject, *names))])

    out = Path(files.out_dir)
    lab_settings, export = settings.lab, settings.export
    static_name = settings.design.static
    model = read_model(files.model_osim)
    model.updateMarkerSet(quiet_opensim().MarkerSet(str(files.marker_set_xml)))
    table = read_tsv(files.label_map_tsv, "label map", ("label", "marker"), dtype=str)
    label_map = dict(zip(table["marker"], table["label"]))
    params = segments_from_model(model, "l", attachment_fraction=settings.brace_fraction, source=str(files.model_osim))
    add_brace_markers(model, params.attachment_m)
    label_map = {**label_map, **{m: m for m in ("LBRA_P", "LBRA_D") if m not in label_map}}
    results: dict = {}
    static = qtm_static_export(
        model,
        label_map,
        mass_kg,
        settings.static_duration_s,
        lab_settings,
        seeded("qtm", static_name),
        settings=export,
        source=f"{subject} {static_name}",
    )
    write_recording(out / f"{static_name}.c3d", static.recording, **static.writer_extras())
    results[static_name] = static
    for trial in trials:
        perturbation = settings.perturbation(settings.design.onset_ms(trial), impedance)
        device_parameters = None if trial == settings.design.no_device else settings.device
        sim_seed, file_seed = seeded("qtm", trial).spawn(2)
        walk = simulate_walking_trial(
            settings.walking_duration_s,
            lab_settings,
            sim_seed,
            height_m,
            params,
            timing_cv=settings.timing_cv,
            amplitude_cv=settings.amplitude_cv,
            device=device_parameters,
            perturbation=perturbation,
        )
        exported = qtm_walking_export(
            model, walk, label_map, mass_kg, lab_settings, file_seed, export, f"{subject} {trial}"
        )
        write_recording(out / f"{trial}.c3d", exported.recording, **exported.writer_extras())
        if walk.robot is not None:
            write_robot_log_mat(out / f"{trial}.mat", walk.robot, lab_settings.robot_rate_hz, ROBOT_LOG_MAT_VARIABLES)
        log.info("%s %s: lab export in %s (first frame %d)", subject, trial, out, export.first_frame)
        results[trial] = (walk, exported)
    return results
