# LOPER device tests: simulated logs for a synthetic device subject, FRF and step analysis from disk.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    device_summary,
    device_figures,


rule device_trial:
    output:
        "data/raw/{subject}/{trial}.loper.tsv",
    log:
        "results/logs/device_trial/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/device_trial/{subject}/{trial}.tsv"
    wildcard_constraints:
        subject=SYNTHETIC_PATTERN,
        trial="|".join(DEVICE_TESTS),
    group:
        "device"
    params:
        device=DEVICE["parameters"],
        leg=DEVICE["leg"],
        tests=DEVICE["tests"],
        seed=config["seed"],
    script:
        "../scripts/device_trial.py"


rule device_log_from_mat:
    input:
        "data/raw/{subject}/{trial}.mat",
    output:
        "results/device/{subject}/{trial}.loper.tsv",
    log:
        "results/logs/device_log_from_mat/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/device_log_from_mat/{subject}/{trial}.tsv"
    params:
        **raw_checksums("data/raw/{subject}/{trial}.mat"),
        column_map=DEVICE["mat_column_map"],
        sample_rate_hz=DEVICE_RATE_HZ,
    script:
        "../scripts/device_log_from_mat.py"


rule device_frf:
    input:
        device_log("device-frf"),
    output:
        "results/device/frf.tsv",
    log:
        "results/logs/device_frf/frf.log",
    benchmark:
        "results/benchmarks/device_frf/frf.tsv"
    group:
        "device"
    params:
        **raw_checksums(lambda wildcards: device_log("device-frf")),
        sample_rate_hz=DEVICE_RATE_HZ,
        window_samples=DEVICE["analysis"]["welch_window_samples"],
        overlap_samples=DEVICE["analysis"]["welch_overlap_samples"],
    script:
        "../scripts/device_frf.py"


rule device_steps:
    input:
        device_log("device-steps"),
    output:
        metrics="results/device/step_metrics.tsv",
        average="results/device/step_average.tsv",
    log:
        "results/logs/device_steps/steps.log",
    benchmark:
        "results/benchmarks/device_steps/steps.tsv"
    group:
        "device"
    params:
        **raw_checksums(lambda wildcards: device_log("device-steps")),
        sample_rate_hz=DEVICE_RATE_HZ,
        amplitudes_n=DEVICE["tests"]["step_amplitudes_n"],
        before_s=DEVICE["analysis"]["step_before_s"],
        after_s=DEVICE["analysis"]["step_after_s"],
        steady_window_s=DEVICE["analysis"]["steady_window_s"],
    script:
        "../scripts/device_steps.py"


rule device_summary:
    input:
        frf="results/device/frf.tsv",
        metrics="results/device/step_metrics.tsv",
    output:
        report(
            "results/device/summary.tsv",
            caption="../report/device_summary.rst",
            category="Device",
            labels={"table": "device figures vs study"},
        ),
    log:
        "results/logs/device_summary/summary.log",
    benchmark:
        "results/benchmarks/device_summary/summary.tsv"
    params:
        reference_band_hz=DEVICE["analysis"]["bandwidth_reference_band_hz"],
    script:
        "../scripts/device_summary.py"


rule device_figures:
    input:
        frf="results/device/frf.tsv",
        summary="results/device/summary.tsv",
        average="results/device/step_average.tsv",
    output:
        bode=report(
            "results/device/bode.png",
            caption="../report/device_bode.rst",
            category="Device",
            labels={"figure": "Bode plot"},
        ),
        steps=report(
            "results/device/steps.png",
            caption="../report/device_steps.rst",
            category="Device",
            labels={"figure": "step responses"},
        ),
    log:
        "results/logs/device_figures/figures.log",
    benchmark:
        "results/benchmarks/device_figures/figures.tsv"
    script:
        "../scripts/device_figures.py"
