# Processing: raw C3D + robot log -> markers (TRC) -> scaled OpenSim model -> IK (chunked) -> events -> forces.
import re


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    transparency,
    strides_summary,
    model_generic,
    model_segments,


TRIALS = config["trials"]
FILTER = config["filter"]
OPENSIM = config["opensim"]
EVENTS = config["events"]
IK_CHUNKS = [f"{i:03d}" for i in range(OPENSIM["ik_chunks"])]


def subject_model(wildcards):
    """The subject's OpenSim model: user-supplied (subjects.tsv column model_osim) or scaled from the static trial."""
    user = SUBJECT_ROWS[wildcards.subject].get("model_osim")
    return user if user else f"results/model/{wildcards.subject}/scaled.osim"


MARKERS = config["markers"]


def trial_group(wildcards) -> str:
    """Cluster job group (ignored locally): a walking trial's markers, IK, events and strides run as one SLURM
    job ("trial"); the static trial's markers join the subject's scaling ("model")."""
    return "model" if wildcards.trial == TRIALS["static"] else "trial"


rule markers:
    """Markers of a C3D in the model's names and frame (each trial turned to walk along +X), gaps filled or left
    missing, low-passed: a TRC (mm), and per marker its lab label, gaps and the trial's frames, span and rotation."""
    input:
        c3d="data/raw/{subject}/{trial}.c3d",
        label_map=label_map_files,
    output:
        trc="results/markers/{subject}/{trial}.trc",
        gaps="results/markers/{subject}/{trial}.gaps.tsv",
        summary="results/markers/{subject}/{trial}.markers.tsv",
    log:
        "results/logs/markers/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/markers/{subject}/{trial}.tsv"
    group:
        trial_group
    params:
        rotation_deg=MARKERS["lab_to_model_rotation_deg"],
        walking_direction=MARKERS["walking_direction"],
        min_travel_speed_m_per_s=MARKERS["min_travel_speed_m_per_s"],
        # the static trial is averaged over the scaling window, each marker over the frames it is present in:
        # neither filled nor filtered (as OpenSim's ScaleTool reads a lab's static trial)
        max_gap_frames=lambda wc: 0 if wc.trial == TRIALS["static"] else MARKERS["max_gap_frames"],
        cutoff_hz=lambda wc: None if wc.trial == TRIALS["static"] else FILTER["cutoff_hz"],
        order=FILTER["order"],
        span_s=lambda wc: trial_span_s(wc.subject, wc.trial),
        label_maps=lambda wc: trial_label_maps(wc.trial),
        extent_range_m=MARKERS["extent_range_m"],
    script:
        "../scripts/markers.py"


def generic_model(wildcards):
    """The model scaled per subject: opensim.generic_model, or the generated model for the subject."""
    return OPENSIM["generic_model"] or f"results/model/{wildcards.subject}/generic.osim"


def static_c3d_for_mass(wildcards) -> list[str]:
    """The static trial's C3D when the subject sheet gives no mass (the mass comes from its force plates)."""
    if "mass_kg" in SUBJECT_ROWS[wildcards.subject]:
        return []
    return [f"data/raw/{wildcards.subject}/{TRIALS['static']}.c3d"]


STATIC_SETTINGS = dict(duration_s=MARKERS["static_duration_s"], rotation_deg=MARKERS["lab_to_model_rotation_deg"])


rule model_generic:
    """The generated sagittal model (used when opensim.generic_model is null)."""
    input:
        static_c3d=static_c3d_for_mass,
    output:
        "results/model/{subject}/generic.osim",
    log:
        "results/logs/model_generic/{subject}.log",
    benchmark:
        "results/benchmarks/model_generic/{subject}.tsv"
    params:
        height_m=lambda wc: SUBJECT_ROWS[wc.subject]["height_m"],
        mass_kg=lambda wc: SUBJECT_ROWS[wc.subject].get("mass_kg"),
        static=STATIC_SETTINGS,
    script:
        "../scripts/model_generic.py"


rule model_scaled:
    """The generic model scaled to the static trial (OpenSim's ScaleTool, with opensim.scale_setup when given), and
    the scale report: scale factors per body, marker errors after scaling, the mass and height used."""
    input:
        generic=generic_model,
        static=f"results/markers/{{subject}}/{TRIALS['static']}.trc",
        static_summary=f"results/markers/{{subject}}/{TRIALS['static']}.markers.tsv",
        static_c3d=static_c3d_for_mass,
        setup=[OPENSIM["scale_setup"]] if OPENSIM["scale_setup"] else [],
    output:
        model="results/model/{subject}/scaled.osim",
        report=report(
            "results/model/{subject}/scale.tsv",
            caption="../report/scale_report.rst",
            category="Model",
            subcategory="{subject}",
            labels={"subject": "{subject}", "table": "scaling"},
        ),
    log:
        "results/logs/model_scaled/{subject}.log",
    benchmark:
        "results/benchmarks/model_scaled/{subject}.tsv"
    group:
        "model"
    params:
        mass_kg=lambda wc: SUBJECT_ROWS[wc.subject].get("mass_kg"),
        height_m=lambda wc: SUBJECT_ROWS[wc.subject].get("height_m"),
        scale_setup=OPENSIM["scale_setup"],
        segment_bodies=OPENSIM["segment_bodies"],
        factor_range=OPENSIM["scale_factor_range"],
        static={**STATIC_SETTINGS, "max_motion_rms_m": MARKERS["static_max_motion_rms_m"]},
    script:
        "../scripts/model_scaled.py"


rule model_segments:
    """The swing leg's segment table, exported from the subject's model (opensim.segment_bodies)."""
    input:
        subject_model,
    output:
        "results/model/{subject}/segments.tsv",
    log:
        "results/logs/model_segments/{subject}.log",
    benchmark:
        "results/benchmarks/model_segments/{subject}.tsv"
    params:
        side=TRIALS["perturbed_side"],
        segment_bodies=OPENSIM["segment_bodies"],
        attachment_fraction=OPENSIM["brace_attachment_fraction"],
    script:
        "../scripts/model_segments.py"


IK_SETTINGS = dict(
    tasks_file=OPENSIM["ik_tasks"],
    default_weight=OPENSIM["default_marker_weight"],
    marker_weights=OPENSIM["marker_weights"],
    coordinate_tasks=OPENSIM["coordinate_tasks"],
    accuracy=OPENSIM["accuracy"],
    max_marker_rms_m=OPENSIM["max_marker_rms_m"],
    warn_marker_rms_m=OPENSIM["warn_marker_rms_m"],
    max_rms_fraction=OPENSIM["max_rms_fraction"],
)

if OPENSIM["ik_chunks"] == 1:

    rule ik:
        """The whole trial in one job (the default): IK, .mot and angle table."""
        input:
            model=subject_model,
            trc="results/markers/{subject}/{trial}.trc",
        output:
            mot="results/ik/{subject}/{trial}.mot",
            angles="results/ik/{subject}/{trial}.angles.tsv",
            summary="results/ik/{subject}/{trial}.ik.tsv",
        log:
            "results/logs/ik/{subject}/{trial}.log",
        benchmark:
            "results/benchmarks/ik/{subject}/{trial}.tsv"
        group:
            "trial"
        params:
            coordinate_map=OPENSIM["coordinate_map"],
            settings=IK_SETTINGS,
        script:
            "../scripts/ik.py"

else:

    rule ik_chunk:
        """One of opensim.ik_chunks time chunks of a trial (long trials, many cores)."""
        input:
            model=subject_model,
            trc="results/markers/{subject}/{trial}.trc",
        output:
            temp("results/ik/{subject}/{trial}.chunk{chunk}.mot"),
        log:
            "results/logs/ik_chunk/{subject}/{trial}.{chunk}.log",
        benchmark:
            "results/benchmarks/ik_chunk/{subject}/{trial}.{chunk}.tsv"
        group:
            "trial"
        params:
            n_chunks=OPENSIM["ik_chunks"],
            settings=IK_SETTINGS,
        script:
            "../scripts/ik_chunk.py"

    rule ik_join:
        input:
            expand("results/ik/{{subject}}/{{trial}}.chunk{chunk}.mot", chunk=IK_CHUNKS),
        output:
            mot="results/ik/{subject}/{trial}.mot",
            angles="results/ik/{subject}/{trial}.angles.tsv",
            summary="results/ik/{subject}/{trial}.ik.tsv",
        log:
            "results/logs/ik_join/{subject}/{trial}.log",
        benchmark:
            "results/benchmarks/ik_join/{subject}/{trial}.tsv"
        group:
            "trial"
        params:
            coordinate_map=OPENSIM["coordinate_map"],
        script:
            "../scripts/ik_join.py"


rule grf:
    """Ground reaction forces of the C3D's force platforms as an OpenSim external-loads .mot, in the frame the
    trial's markers were turned into (its markers summary)."""
    input:
        c3d="data/raw/{subject}/{trial}.c3d",
        markers="results/markers/{subject}/{trial}.markers.tsv",
    output:
        "results/grf/{subject}/{trial}.grf.mot",
    log:
        "results/logs/grf/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/grf/{subject}/{trial}.tsv"
    params:
        rotation_deg=config["markers"]["lab_to_model_rotation_deg"],
        threshold_n=config["grf"]["loaded_threshold_n"],
        band_n=config["grf"]["resting_band_n"],
        max_rest_n=config["grf"]["max_resting_n"],
    script:
        "../scripts/grf.py"


def robot_log(wildcards):
    """A trial's robot log: data/raw/{subject}/{trial}.loper.tsv, or converted from the MATLAB export {trial}.mat."""
    raw = Path("data/raw") / wildcards.subject
    if (
        SUBJECT_SOURCE[wildcards.subject] == "recorded"
        and not (raw / f"{wildcards.trial}.loper.tsv").exists()
        and (raw / f"{wildcards.trial}.mat").exists()
    ):
        return f"results/device/{wildcards.subject}/{wildcards.trial}.loper.tsv"
    return str(raw / f"{wildcards.trial}.loper.tsv")


EVENT_SETTINGS = dict(
    grf_channels=EVENTS["grf_channels"],
    threshold_on_n=EVENTS["threshold_on_n"],
    threshold_off_n=EVENTS["threshold_off_n"],
    min_stance_s=EVENTS["min_stance_s"],
    min_swing_s=EVENTS["min_swing_s"],
    cutoff_hz=EVENTS["grf_cutoff_hz"],
    order=FILTER["order"],
    foot_markers=EVENTS["foot_markers"],
    plate_sides=EVENTS["plate_sides"],
    rotation_deg=config["markers"]["lab_to_model_rotation_deg"],
    band_n=config["grf"]["resting_band_n"],
    max_rest_n=config["grf"]["max_resting_n"],
)
LOADCELL_SETTINGS = dict(sync_channel=EVENTS["sync_channel"], cutoff_hz=FILTER["cutoff_hz"], order=FILTER["order"])


rule events:
    """Heel strikes and toe-offs of the trial without the device: force platforms with the heel markers, or the
    named GRF channels of each belt."""
    input:
        c3d="data/raw/{subject}/{trial}.c3d",
        label_map=label_map_files,
    output:
        events="results/events/{subject}/{trial}.events.tsv",
        contacts="results/events/{subject}/{trial}.contacts.tsv",
    log:
        "results/logs/events/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/events/{subject}/{trial}.tsv"
    wildcard_constraints:
        trial=TRIALS["no_device"],
    group:
        "trial"
    params:
        settings=lambda wc: {**EVENT_SETTINGS, "label_map": trial_label_maps(wc.trial) or None},
    script:
        "../scripts/events.py"


rule events_loadcell:
    """Gait events and the load cell of a trial with the device, in one process that reads the C3D once: the
    heel strikes and toe-offs (as rule events), and the robot log's force on the mocap frames and at its own
    rate. Both feed only the stride table, so a change of either's settings reruns a cheap sibling at most."""
    input:
        c3d="data/raw/{subject}/{trial}.c3d",
        label_map=label_map_files,
        log=robot_log,
    output:
        events="results/events/{subject}/{trial}.events.tsv",
        contacts="results/events/{subject}/{trial}.contacts.tsv",
        force="results/loadcell/{subject}/{trial}.force.tsv",
        native="results/loadcell/{subject}/{trial}.force_native.tsv",
    log:
        "results/logs/events_loadcell/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/events_loadcell/{subject}/{trial}.tsv"
    wildcard_constraints:
        # any trial but the one without the device (the lookahead ends at the wildcard's end, not the path's)
        trial=f"(?!{re.escape(TRIALS['no_device'])}(?![A-Za-z0-9-]))[A-Za-z0-9-]+",
    group:
        "trial"
    params:
        events=lambda wc: {**EVENT_SETTINGS, "label_map": trial_label_maps(wc.trial) or None},
        loadcell=LOADCELL_SETTINGS,
    script:
        "../scripts/events_loadcell.py"


def stride_force(wildcards):
    """The interaction force of a trial walked with the device (none without it)."""
    if wildcards.trial == TRIALS["no_device"]:
        return []
    return f"results/loadcell/{wildcards.subject}/{wildcards.trial}.force.tsv"


rule strides:
    input:
        angles="results/ik/{subject}/{trial}.angles.tsv",
        events="results/events/{subject}/{trial}.events.tsv",
        force=stride_force,
    output:
        strides="results/strides/{subject}/{trial}.strides.tsv",
        cycles="results/strides/{subject}/{trial}.cycles.tsv",
    log:
        "results/logs/strides/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/strides/{subject}/{trial}.tsv"
    group:
        "trial"
    params:
        side=TRIALS["perturbed_side"],
        n_points=config["strides"]["n_points"],
        whisker=config["strides"]["iqr_whisker"],
        max_fraction=config["strides"]["max_outlier_fraction"],
        min_valid=config["strides"]["min_valid_strides"],
    script:
        "../scripts/strides.py"


def transparency_inputs(wildcards):
    """Stride and cycle tables of the transparency pair, one list per condition and kind, in subject order."""
    return {
        f"{cond}_{kind}": [f"results/strides/{s}/{TRIALS[cond]}.{kind}.tsv" for s in transparency_subjects()]
        for cond in ("no_device", "device")
        for kind in ("strides", "cycles")
    }


rule transparency:
    input:
        unpack(transparency_inputs),
    output:
        rmsd=report(
            "results/transparency/rmsd.tsv",
            caption="../report/transparency_rmsd.rst",
            category="Transparency",
            labels={"table": "RMSD vs ISV_ave"},
        ),
        force=report(
            "results/transparency/force.tsv",
            caption="../report/transparency_force.rst",
            category="Transparency",
            labels={"table": "interaction force"},
        ),
        figure=report(
            "results/transparency/transparency.png",
            caption="../report/transparency_figure.rst",
            category="Transparency",
            labels={"figure": "gait cycle with and without LOPER"},
        ),
    log:
        "results/logs/transparency/transparency.log",
    benchmark:
        "results/benchmarks/transparency/transparency.tsv"
    params:
        subjects=transparency_subjects(),
        side=TRIALS["perturbed_side"],
        min_strides=config["strides"]["min_valid_strides"],
    script:
        "../scripts/transparency.py"


rule strides_summary:
    input:
        strides=[f"results/strides/{s}/{t}.strides.tsv" for s in processed_subjects() for t in subject_trials(s)],
        contacts=[f"results/events/{s}/{t}.contacts.tsv" for s in processed_subjects() for t in subject_trials(s)],
        ik=[f"results/ik/{s}/{t}.ik.tsv" for s in processed_subjects() for t in subject_trials(s)],
        markers=[f"results/markers/{s}/{t}.markers.tsv" for s in processed_subjects() for t in subject_trials(s)],
    output:
        report(
            "results/strides/summary.tsv",
            caption="../report/strides_summary.rst",
            category="Processing",
            labels={"table": "strides per trial"},
        ),
    log:
        "results/logs/strides_summary/summary.log",
    benchmark:
        "results/benchmarks/strides_summary/summary.tsv"
    params:
        subject_trial=[(s, t) for s in processed_subjects() for t in subject_trials(s)],
        min_valid=config["strides"]["min_valid_strides"],
    script:
        "../scripts/strides_summary.py"
