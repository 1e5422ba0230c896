# Inverse kinematics (OpenSim): joint angles per trial, in one job or in time chunks joined.


if SETTINGS["ik"].n_chunks == 1:

    rule ik:
        """The whole trial in one job (the default): IK, .mot and angle table (the marker geometry checked against
        the static trial's, or the model's without one)."""
        input:
            model=by_subject(STUDY.subject_model),
            trc=PATHS.markers.trc,
            static=by_subject(STUDY.static_markers),
            lab_angles=PATHS.markers.lab_angles,
        output:
            mot=PATHS.ik.mot,
            angles=PATHS.ik.angles,
            summary=PATHS.ik.summary,
            agreement=PATHS.ik.agreement,
        log:
            PATHS.log("ik", "{subject}/{trial}"),
        benchmark:
            PATHS.benchmark("ik", "{subject}/{trial}")
        group:
            "trial"
        params:
            **settings_params(ik_settings),
        script:
            "../scripts/ik.py"

else:

    rule ik_chunk:
        """One of ik.ik_chunks time chunks of a trial (long trials, many cores)."""
        input:
            model=by_subject(STUDY.subject_model),
            trc=PATHS.markers.trc,
            static=by_subject(STUDY.static_markers),
        output:
            temp(PATHS.ik.chunk),
        log:
            PATHS.log("ik_chunk", "{subject}/{trial}.{chunk}"),
        benchmark:
            PATHS.benchmark("ik_chunk", "{subject}/{trial}.{chunk}")
        group:
            "trial"
        params:
            **settings_params(ik_settings),
            n_chunks=SETTINGS["ik"].n_chunks,
        script:
            "../scripts/ik_chunk.py"

    rule ik_join:
        input:
            chunks=expand(PATHS.ik.chunk, chunk=IK_CHUNKS, allow_missing=True),
            lab_angles=PATHS.markers.lab_angles,
        output:
            mot=PATHS.ik.mot,
            angles=PATHS.ik.angles,
            summary=PATHS.ik.summary,
            agreement=PATHS.ik.agreement,
        log:
            PATHS.log("ik_join", "{subject}/{trial}"),
        benchmark:
            PATHS.benchmark("ik_join", "{subject}/{trial}")
        group:
            "trial"
        params:
            **settings_params(ik_settings),
        script:
            "../scripts/ik_join.py"
