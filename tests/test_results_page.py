"""benchmarks/results_page.py: the generated parts of docs/results.md from a (tiny, fake) finished run."""

from __future__ import annotations

import importlib.util
import math
import re
from pathlib import Path

import pytest

from loper_analysis.stages import study_paths

PATHS = study_paths()

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("results_page", ROOT / "benchmarks" / "results_page.py")
results_page = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(results_page)

CONFIG = """\
subjects: config/subjects.tsv
seed: 7
study: {perturbation_onsets_ms: [50, 175], perturbation_repeats: 1}
synthetic: {walking_duration_s: 30.0, variability: study}
"""
SUBJECTS = "subject\tsource\nA1\tsynthetic\nB2\tsynthetic\n"

IMPEDANCE_COLUMNS = [
    "subject",
    "onset_ms",
    "joint",
    "K_nm_per_rad",
    "D_nms_per_rad",
    "K_ci95_low_nm_per_rad",
    "K_ci95_high_nm_per_rad",
    "D_ci95_low_nms_per_rad",
    "D_ci95_high_nms_per_rad",
    "vaf_pct",
    "n_strides",
    "K_true_nm_per_rad",
    "D_true_nms_per_rad",
    "K_error_nm_per_rad",
    "D_error_nms_per_rad",
    "status",
]
# subject, onset, joint, K, D, K CI, D CI, VAF, strides, truth K, D
FITS = [
    ("A1", 50, "hip", 61.0, 3.0, (50.0, 70.0), (2.0, 4.0), 99.1, 11, 60.0, 3.1, "ok"),  # K, D within
    ("B2", 50, "hip", 80.0, 2.0, (75.0, 85.0), (1.9, 2.1), 98.7, 9, 60.0, 3.0, "ok"),  # off, CI misses
    ("A1", 175, "hip", 30.0, 3.5, (0.0, 90.0), (0.0, 9.0), 97.3, 12, 55.0, 3.5, "not_identifiable"),
    (
        "B2",
        175,
        "hip",
        float("nan"),
        float("nan"),
        (float("nan"),) * 2,
        (float("nan"),) * 2,
        float("nan"),
        10,
        50.0,
        3.0,
        "failed",
    ),
]
SUMMARY = (
    "\t".join(
        [
            "joint",
            "onset_ms",
            "n_subjects",
            "n_not_identifiable",
            "K_group_mean_nm_per_rad",
            "K_group_ci95_low_nm_per_rad",
            "K_group_ci95_high_nm_per_rad",
            "K_between_sd_nm_per_rad",
            "D_group_mean_nms_per_rad",
            "D_group_ci95_low_nms_per_rad",
            "D_group_ci95_high_nms_per_rad",
            "D_between_sd_nms_per_rad",
            "vaf_pct_mean",
        ]
    )
    + """
hip\t50\t2\t0\t70.5\t-50.2\t191.2\t13.4350288\t2.5\t-3.85\t8.85\t0.707106781\t98.9
hip\t175\t1\t1\t30\t\t\t\t3.5\t\t\t\t97.3
"""
)
VALIDATION = """\
condition\tparameter\tmin_error\tmax_error\tsd_error\tmax_abs_error\tn\tstudy_min_error\tstudy_max_error\tstudy_sd_error
no_noise\tK_hip\t-0.000123\t0.00456\t0.0007\t0.00456\t729\t-0.87\t0.59\t
no_noise\tD_hip\t-0.000321\t0.0000211\t0.00006\t0.000321\t729\t-0.092\t0.047\t
noise\tK_hip\t-70\t47\t13.579\t70\t729\t-6.2\t6.5\t15
noise\tD_hip\t-4\t8\t1.2345\t8\t729\t-0.57\t0.5\t0.12
"""
FITS_TSV = "condition\tn_starts\tn_starts_at_best\nno_noise\t10\t10\nno_noise\t10\t9\nnoise\t10\t10\n"
RMSD = (
    "\t".join(
        [
            "subject",
            "phase",
            "joint",
            "n_strides_no_device",
            "n_strides_device",
            "rmsd_rad",
            "sd_rad",
            "isv_ave_rad",
            "transparent",
            "study_rmsd_rad",
            "study_isv_ave_rad",
        ]
    )
    + """
A1\tswing\tknee\t21\t23\t0.0912\t0.05\t0.1234\tTrue\t0.071\t0.129
B2\tswing\tknee\t22\t20\t0.1500\t0.05\t0.1234\tFalse\t0.071\t0.129
all\tswing\tknee\t43\t43\t0.0777\t0.05\t0.1234\tTrue\t0.071\t0.129
"""
)
FORCE = """\
subject\tphase\tn_strides\trms_force_mean_n\tmax_abs_force_mean_n\tstudy_rms_force_mean_n\tstudy_max_abs_force_mean_n
all\tstance\t43\t2.3456\t5.4321\t1.97\t4.46
"""
DEVICE = """\
metric\tvalue\tstudy_value\tunit\tdifference_pct
bandwidth_hz\t41.234\t39\tHz\t5.728
rise_time_ms_at_20n\t9.87\t\tms\t
"""
STRIDES = """\
subject\ttrial\tn_strides\tn_perturbed\tn_removed\tn_kept\tstatus
A1\twalk\t26\t0\t1\t25\tok
A1\tpert050-1\t27\t6\t2\t19\tok
B2\twalk\t3\t0\t0\t3\ttoo_few_strides
"""
ANSWERS = "hip K at 50 ms: ±15 % (95 % CI) needs 123 perturbed strides kept in the average\n"

PAGE = """\
# Results\r
Hand-written text, kept byte for byte: 2 min 25.5 s, `python benchmarks/x.py`.

<!-- generated: run -->
old stamp
<!-- end generated -->

Between the parts ✓ (measured on 2026-11-25 with `snakemake -j2`)
<!-- generated: impedance-summary -->
| old | table |
<!-- end generated -->
<!-- generated: truth-recovery -->
<!-- end generated -->
<!-- generated: validation -->
<!-- end generated -->
<!-- generated: transparency -->
<!-- end generated -->
<!-- generated: interaction-force -->
<!-- end generated -->
<!-- generated: device -->
<!-- end generated -->
<!-- generated: strides -->
<!-- end generated -->
<!-- generated: planning -->
<!-- end generated -->

Trailing hand-written text\x20\x20\x20
without a final newline"""


def impedance_tsv() -> str:
    lines = ["\t".join(IMPEDANCE_COLUMNS)]
    for s, o, j, k, d, kci, dci, vaf, n, kt, dt, status in FITS:
        cells = [s, o, j, k, d, *kci, *dci, vaf, n, kt, dt, k - kt, d - dt, status]
        lines.append("\t".join("" if isinstance(c, float) and math.isnan(c) else str(c) for c in cells))
    return "\n".join(lines) + "\n"


@pytest.fixture
def run(tmp_path, monkeypatch):
    """A finished run's folder with a few rows in each table, and a page to rewrite; the current directory."""
    files = {
        "config/config.yaml": CONFIG,
        "config/subjects.tsv": SUBJECTS,
        PATHS.impedance.table: impedance_tsv(),
        PATHS.impedance.summary: SUMMARY,
        PATHS.validation.summary: VALIDATION,
        PATHS.validation.fits: FITS_TSV,
        PATHS.transparency.rmsd: RMSD,
        PATHS.transparency.force: FORCE,
        PATHS.device.summary: DEVICE,
        PATHS.strides.summary: STRIDES,
        PATHS.planning.answers: ANSWERS,
    }
    for name, text in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text, encoding="utf-8")
    (tmp_path / "results.md").write_bytes(PAGE.encode("utf-8"))
    monkeypatch.chdir(tmp_path)
    return tmp_path


def outside_parts(text: str) -> str:
    """The page with the inside of every generated part cut out (the marker lines kept)."""
    return re.sub(
        r"(^<!-- generated: [\w-]+ -->\n).*?(^<!-- end generated -->$)", r"\1\2", text, flags=re.MULTILINE | re.DOTALL
    )


def part(text: str, name: str) -> str:
    found = re.search(rf"^<!-- generated: {name} -->\n(.*?)^<!-- end generated -->$", text, re.MULTILINE | re.DOTALL)
    return found.group(1)


def test_the_parts_hold_the_run_and_the_rest_is_kept_byte_for_byte(run, capsys):
    assert results_page.main(["--page", "results.md"]) == 0
    text = (run / "results.md").read_bytes().decode("utf-8")
    assert outside_parts(text) == outside_parts(PAGE)
    assert text.startswith("# Results\r\nHand-written text, kept byte for byte: 2 min 25.5 s,")
    assert text.endswith("Trailing hand-written text   \nwithout a final newline")
    assert "old stamp" not in text and "| old | table |" not in text

    stamp = part(text, "run")
    assert "`snakemake -j2`" in stamp and "`python benchmarks/results_page.py`" in stamp
    assert "`config/config.yaml` (SHA-256" in stamp and "`config/subjects.tsv`" in stamp
    assert "2 subjects (2 synthetic); seed 7; `synthetic.variability: study`" in stamp
    assert "walking trials of 30 s; onsets 50, 175 ms; 1 trial per onset" in stamp

    summary_part = part(text, "impedance-summary")
    assert "| hip | 50 | 2 | 0 | 70.5 [−50.2, 191] | 13.4 | 2.50 [−3.85, 8.85] | 0.707 | 98.9 |" in summary_part
    assert "| hip | 175 | 1 | 1 | 30.0 [—, —] | — | 3.50 [—, —] | — | 97.3 |" in summary_part

    truth = part(text, "truth-recovery")
    # onset 50: A1 within (K 1 of 60, D 0.1 of 3.1), B2 off (K 20, D 1.0); both CIs of B2 miss its truth
    assert "| hip | 50 | 2 / 0 / 0 | 1 / 2 | 1 / 2 | 20.0 | 1 / 2 | 1 / 2 | 1.00 | 98.9 |" in truth
    assert "| hip | 175 | 0 / 1 / 1 | 0 / 1 | 1 / 1 | 25.0 | 1 / 1 | 1 / 1 | 0 | 97.3 |" in truth
    assert "| **hip** | all | 2 / 1 / 1 | 1 / 3 | 2 / 3 | 25.0 | 2 / 3 | 2 / 3 | 1.00 | 98.4 |" in truth
    assert "2 subjects with a known truth, 9–12 perturbed strides per fit" in truth
    assert (
        "B2, 50 ms, hip K 80.0 for 60.0 (95 % CI 75.0–85.0); B2, 50 ms, hip D 2.00 for 3.00 (95 % CI 1.90–2.10)."
    ) in truth

    validation = part(text, "validation")
    assert "| K_hip (N·m/rad) | −0.00012 … 0.0046 | −0.87 … 0.59 | 13.6 | 15 |" in validation
    assert "| D_hip (N·m·s/rad) | −0.00032 … 0.000021 | −0.092 … 0.047 | 1.23 | 0.12 |" in validation
    assert "|ΔK| ≤ 0.0046 N·m/rad and |ΔD| ≤ 0.00032 N·m·s/rad" in validation
    assert "in 1 of 2 noise-free fits and in 1 of 1 noisy fits" in validation

    transparency = part(text, "transparency")
    assert "| swing | knee | 0.078 (0.071) | 0.123 (0.129) | 1 / 2 |" in transparency
    assert "2 subjects, 20–23 kept strides per trial" in transparency
    assert "| stance | 43 | 2.35 (1.97) | 5.43 (4.46) |" in part(text, "interaction-force")
    device = part(text, "device")
    assert "| `bandwidth_hz` | 41.2 | 39 | Hz | 5.7 |" in device
    assert "| `rise_time_ms_at_20n` | 9.87 | — | ms | — |" in device
    strides = part(text, "strides")
    assert "| A1 | 2 | 53 | 6 | 3 | 44 | 19–25 | none |" in strides
    assert "| **all** | 3 | 56 | 6 | 3 | 47 | 3–25 | walk (too_few_strides) |" in strides
    assert "needs 123 perturbed strides" in part(text, "planning")

    # a second run changes nothing; --check agrees; a changed table makes --check fail and is written
    assert results_page.main(["--page", "results.md"]) == 0
    assert (run / "results.md").read_bytes().decode("utf-8") == text
    assert results_page.main(["--page", "results.md", "--check"]) == 0
    (run / PATHS.device.summary).write_text(DEVICE.replace("41.234", "40.111"))
    assert results_page.main(["--page", "results.md", "--check"]) == 1
    assert (run / "results.md").read_bytes().decode("utf-8") == text
    assert results_page.main(["--page", "results.md"]) == 0
    assert "| `bandwidth_hz` | 40.1 | 39 |" in (run / "results.md").read_text(encoding="utf-8")


def test_a_part_without_its_table_and_extra_config_files(run):
    (run / PATHS.device.summary).unlink()
    (run / "config/paper.yaml").write_text("synthetic: {walking_duration_s: 240.0}\n")
    assert results_page.main(["--page", "results.md", "--configfile", "config/paper.yaml"]) == 0
    text = (run / "results.md").read_text(encoding="utf-8")
    assert part(text, "device").strip() == f"*Not in this run: no `{PATHS.device.summary}`.*"
    stamp = part(text, "run")
    assert "`snakemake -j2 --configfile config/paper.yaml`" in stamp
    assert "`python benchmarks/results_page.py --configfile config/paper.yaml`" in stamp
    assert "walking trials of 240 s" in stamp and "`synthetic.variability: study`" in stamp


@pytest.mark.parametrize(
    "page, message",
    [
        ("<!-- generated: nonsense -->\n<!-- end generated -->\n", "unknown generated part(s) ['nonsense']"),
        ("<!-- generated: run -->\nno end\n", "1 opening, 0 closing markers"),
    ],
)
def test_a_bad_page_is_named_and_left_alone(run, capsys, page, message):
    (run / "results.md").write_text(page)
    assert results_page.main(["--page", "results.md"]) == 2
    assert message in capsys.readouterr().err
    assert (run / "results.md").read_text() == page
