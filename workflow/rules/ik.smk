# Inverse kinematics (OpenSim): joint angles per trial, in one job or in time chunks joined.


if OPENSIM["ik_chunks"] == 1:

    rule ik:
        """The whole trial in one job (the default): IK, .mot and angle table."""
        input:
            model=subject_model,
            trc="results/markers/{subject}/{trial}.trc",
            lab_angles="results/markers/{subject}/{trial}.lab_angles.tsv",
        output:
            mot="results/ik/{subject}/{trial}.mot",
            angles="results/ik/{subject}/{trial}.angles.tsv",
            summary="results/ik/{subject}/{trial}.ik.tsv",
            agreement="results/ik/{subject}/{trial}.lab_agreement.tsv",
        log:
            "results/logs/ik/{subject}/{trial}.log",
        benchmark:
            "results/benchmarks/ik/{subject}/{trial}.tsv"
        group:
            "trial"
        params:
            **settings_params(ik_settings),
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
            **settings_params(ik_settings),
            n_chunks=OPENSIM["ik_chunks"],
        script:
            "../scripts/ik_chunk.py"

    rule ik_join:
        input:
            chunks=expand("results/ik/{{subject}}/{{trial}}.chunk{chunk}.mot", chunk=IK_CHUNKS),
            lab_angles="results/markers/{subject}/{trial}.lab_angles.tsv",
        output:
            mot="results/ik/{subject}/{trial}.mot",
            angles="results/ik/{subject}/{trial}.angles.tsv",
            summary="results/ik/{subject}/{trial}.ik.tsv",
            agreement="results/ik/{subject}/{trial}.lab_agreement.tsv",
        log:
            "results/logs/ik_join/{subject}/{trial}.log",
        benchmark:
            "results/benchmarks/ik_join/{subject}/{trial}.tsv"
        group:
            "trial"
        params:
            **settings_params(ik_settings),
        script:
            "../scripts/ik_join.py"
