"""Time to simulate and analyse all device tests of one subject, and the figures it gives.

Usage: python benchmarks/device_tests.py
Simulates the broadband (FRF) and the step trial with the shipped config's
device, writes both robot logs to a temporary directory, reads them back,
analyses them and prints wall time and the device figures beside the study's.
"""

from __future__ import annotations

import dataclasses
import tempfile
import time
from pathlib import Path

import yaml

from loper_analysis.stages.device import step as device
from loper_analysis.stages.settings import stage_settings

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    settings = stage_settings(yaml.safe_load((ROOT / "config/config.yaml").read_text()), "device")
    rate = settings.parameters.sample_rate_hz
    analysis = settings.analysis
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        # compile once outside the timing (numba caches it for later runs anyway)
        device.device_trial(
            tmp / "warm.loper.tsv",
            "warm",
            "device-steps",
            settings.parameters,
            settings.leg,
            dataclasses.replace(settings.tests, step_repetitions=1),
            0,
        )
        t0 = time.perf_counter()
        for trial in ("device-frf", "device-steps"):
            device.device_trial(
                tmp / f"{trial}.loper.tsv", "S01", trial, settings.parameters, settings.leg, settings.tests, 2024
            )
        t1 = time.perf_counter()
        device.frf(tmp / "device-frf.loper.tsv", tmp / "frf.tsv", rate, analysis.frf)
        device.steps(
            tmp / "device-steps.loper.tsv",
            tmp / "steps.tsv",
            tmp / "avg.tsv",
            rate,
            settings.tests.step_amplitudes_n,
            analysis.steps,
        )
        summary = device.summary(tmp / "frf.tsv", tmp / "steps.tsv", tmp / "summary.tsv", analysis.reference_band_hz)
        t2 = time.perf_counter()
    print(
        f"simulate + write 2 device trials: {t1 - t0:.2f} s; read + analyse: {t2 - t1:.2f} s; "
        f"total {t2 - t0:.2f} s (target 10 s)"
    )
    print(summary.to_string(index=False, float_format=lambda v: f"{v:.3g}"))


if __name__ == "__main__":
    main()
