# The report's front page: what was run, the headline numbers and the main figure, as one HTML fragment that
# workflow/report/workflow.rst pulls in above the methods text.


# a small job reading tables: on a cluster it runs in the controlling process, not as a SLURM job
localrules:
    front_page,


def front_page_inputs(wildcards) -> dict:
    """Tables the front page reads: the validation summary always, the device summary with device tests, the
    impedance tables and the main figure when the run has perturbation trials, the transparency table when a
    subject walked both trials of the pair (the targets of processing_targets)."""
    out = {"validation": "results/validation/summary.tsv"}
    if device_targets():
        out["device"] = "results/device/summary.tsv"
    targets = set(processing_targets())
    if "results/tables/impedance.tsv" in targets:
        out.update(
            impedance="results/tables/impedance.tsv",
            summary="results/tables/impedance_summary.tsv",
            figure="results/figures/impedance.png",
        )
    if "results/transparency/rmsd.tsv" in targets:
        out["rmsd"] = "results/transparency/rmsd.tsv"
    return out


rule front_page:
    input:
        unpack(front_page_inputs),
    output:
        "results/report/front_page.html",
    log:
        "results/logs/front_page/front_page.log",
    benchmark:
        "results/benchmarks/front_page/front_page.tsv"
    params:
        subjects=SUBJECT_SOURCE,
        trials={s: subject_trials(s) for s in processed_subjects()},
        settings=dict(
            seed=config["seed"],
            perturbation_onsets_ms=TRIALS["perturbation_onsets_ms"],
            perturbation_repeats=TRIALS["perturbation_repeats"],
            perturbed_side=TRIALS["perturbed_side"],
            filter_cutoff_hz=FILTER["cutoff_hz"],
            filter_order=FILTER["order"],
            window_before_s=IDENT["window_before_s"],
            window_after_s=IDENT["window_after_s"],
            stiffness_bounds_nm_per_rad=IDENT["stiffness_bounds_nm_per_rad"],
            damping_bounds_nms_per_rad=IDENT["damping_bounds_nms_per_rad"],
            n_starts=IDENT["n_starts"],
            noise_model=IDENT["noise_model"],
            null_pair_components=IDENT["null_pair_components"],
            synthetic_variability=config["synthetic"]["variability"],
            synthetic_walking_duration_s=config["synthetic"]["walking_duration_s"],
            pulse_force_n=config["synthetic"]["pulse_force_n"],
            pulse_duration_s=config["synthetic"]["pulse_duration_s"],
        ),
    script:
        "../scripts/front_page.py"
