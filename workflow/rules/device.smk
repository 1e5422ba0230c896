# LOPER device tests: simulated logs for a synthetic device subject, FRF and step analysis from disk.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    device_summary,
    device_figures,


rule device_trial:
    output:
        PATHS.raw.robot_log,
    log:
        PATHS.log("device_trial", "{subject}/{trial}"),
    benchmark:
        PATHS.benchmark("device_trial", "{subject}/{trial}")
    wildcard_constraints:
        subject=SYNTHETIC_PATTERN,
        trial="|".join(DEVICE_TESTS),
    group:
        "device"
    params:
        **settings_params(SETTINGS["device"].parameters, "device"),
        **settings_params(SETTINGS["device"].leg, "leg"),
        **settings_params(SETTINGS["device"].tests, "tests"),
        seed=SETTINGS["study"].seed,
    script:
        "../scripts/device_trial.py"


rule device_log_from_mat:
    input:
        PATHS.raw.mat,
    output:
        PATHS.device.robot_log,
    log:
        PATHS.log("device_log_from_mat", "{subject}/{trial}"),
    benchmark:
        PATHS.benchmark("device_log_from_mat", "{subject}/{trial}")
    params:
        **raw_checksums(PATHS.raw.mat),
        column_map=SETTINGS["device"].mat_column_map,
        sample_rate_hz=SETTINGS["device"].parameters.sample_rate_hz,
    script:
        "../scripts/device_log_from_mat.py"


rule device_frf:
    input:
        STUDY.device_log("device-frf"),
    output:
        PATHS.device.frf,
    log:
        PATHS.log("device_frf", "frf"),
    benchmark:
        PATHS.benchmark("device_frf", "frf")
    group:
        "device"
    params:
        **raw_checksums(lambda wildcards: STUDY.device_log("device-frf")),
        **settings_params(SETTINGS["device"].analysis.frf),
        sample_rate_hz=SETTINGS["device"].parameters.sample_rate_hz,
    script:
        "../scripts/device_frf.py"


rule device_steps:
    input:
        STUDY.device_log("device-steps"),
    output:
        metrics=PATHS.device.step_metrics,
        average=PATHS.device.step_average,
    log:
        PATHS.log("device_steps", "steps"),
    benchmark:
        PATHS.benchmark("device_steps", "steps")
    group:
        "device"
    params:
        **raw_checksums(lambda wildcards: STUDY.device_log("device-steps")),
        **settings_params(SETTINGS["device"].analysis.steps),
        sample_rate_hz=SETTINGS["device"].parameters.sample_rate_hz,
        amplitudes_n=SETTINGS["device"].tests.step_amplitudes_n,
    script:
        "../scripts/device_steps.py"


rule device_summary:
    input:
        frf=PATHS.device.frf,
        metrics=PATHS.device.step_metrics,
    output:
        report(
            PATHS.device.summary,
            caption="../report/device_summary.rst",
            category="Device",
            labels={"table": "device figures vs study"},
        ),
    log:
        PATHS.log("device_summary", "summary"),
    benchmark:
        PATHS.benchmark("device_summary", "summary")
    params:
        reference_band_hz=SETTINGS["device"].analysis.reference_band_hz,
    script:
        "../scripts/device_summary.py"


rule device_figures:
    input:
        frf=PATHS.device.frf,
        summary=PATHS.device.summary,
        average=PATHS.device.step_average,
    output:
        bode=report(
            PATHS.device.bode,
            caption="../report/device_bode.rst",
            category="Device",
            labels={"figure": "Bode plot"},
        ),
        steps=report(
            PATHS.device.steps,
            caption="../report/device_steps.rst",
            category="Device",
            labels={"figure": "step responses"},
        ),
    log:
        PATHS.log("device_figures", "figures"),
    benchmark:
        PATHS.benchmark("device_figures", "figures")
    script:
        "../scripts/device_figures.py"
