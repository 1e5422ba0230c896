# Shared set-up: config and subject-sheet validation, target list, settings for rules.
from pathlib import Path

import pandas as pd
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

from loper_analysis.errors import LoperInputError
from loper_analysis.schema import check_config, check_table

_SCHEMAS = Path(workflow.basedir) / "workflow" / "schemas"
try:
    # one short message naming the key, then Snakemake's own validation
    check_config(config, _SCHEMAS / "config.schema.yaml", "config/config.yaml")
    validate(config, "../schemas/config.schema.yaml")
    _subjects_path = Path(config["subjects"])
    if not _subjects_path.is_file():
        raise LoperInputError(f"config key 'subjects': file '{_subjects_path}' not found")
    subjects = pd.read_csv(_subjects_path, sep="\t", dtype={"subject": str}, comment="#")
    check_table(subjects, _SCHEMAS / "subjects.schema.yaml", str(_subjects_path))
    validate(subjects, "../schemas/subjects.schema.yaml")
except LoperInputError as exc:
    raise WorkflowError(str(exc)) from None
if subjects["subject"].duplicated().any():
    dup = subjects.loc[subjects["subject"].duplicated(), "subject"].iloc[0]
    raise WorkflowError(f"{_subjects_path}: subject '{dup}' appears twice")

SUBJECT_SOURCE = dict(zip(subjects["subject"], subjects["source"]))
if config["device"]["subject"] not in SUBJECT_SOURCE:
    raise WorkflowError(
        f"config key 'device.subject': subject '{config['device']['subject']}' is not in {_subjects_path}"
    )
_synthetic = [s for s, src in SUBJECT_SOURCE.items() if src == "synthetic"]
SYNTHETIC_PATTERN = "|".join(_synthetic) if _synthetic else "(?!)"

VALIDATION_CHUNKS = [f"{i:03d}" for i in range(config["validation"]["n_chunks"])]


wildcard_constraints:
    subject=r"[A-Za-z0-9-]+",
    chunk=r"[0-9]{3}",


def validation_settings() -> dict:
    """Keyword arguments of loper_analysis.validation.ValidationSettings from the config."""
    v = config["validation"]
    ident = config["identification"]
    k_lo, k_hi = ident["stiffness_bounds_nm_per_rad"]
    d_lo, d_hi = ident["damping_bounds_nms_per_rad"]
    return dict(
        stiffness_levels_nm_per_rad=tuple(v["stiffness_levels_nm_per_rad"]),
        damping_levels_nms_per_rad=tuple(v["damping_levels_nms_per_rad"]),
        sample_rate_hz=v["sample_rate_hz"],
        swing_duration_s=v["swing_duration_s"],
        onset_s=v["onset_s"],
        pulse_force_n=v["pulse_force_n"],
        pulse_duration_s=v["pulse_duration_s"],
        force_direction_deg=v["force_direction_deg"],
        noise_peak_to_peak=v["noise_peak_to_peak"],
        truth_substeps=v["truth_substeps"],
        seed=config["seed"],
        window_before_s=ident["window_before_s"],
        window_after_s=ident["window_after_s"],
        n_starts=ident["n_starts"],
        n_substeps=ident["n_substeps"],
        tolerance=ident["tolerance"],
        merge_tolerance=ident["merge_tolerance"],
        initial_state_span_s=ident["initial_state_span_s"],
        initial_state_degree=ident["initial_state_degree"],
        lower=(k_lo, d_lo) * 3,
        upper=(k_hi, d_hi) * 3,
    )


def all_targets() -> list[str]:
    """Everything `snakemake` builds by default."""
    return [
        "results/validation/summary.tsv",
        "results/validation/errors.tsv",
        "results/validation/fits.tsv",
        "results/validation/errors.png",
        "results/device/summary.tsv",
        "results/device/bode.png",
        "results/device/steps.png",
    ]
