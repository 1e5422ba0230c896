"""The file step of the impedance fit (loper_analysis.stages.impedance.step.subject_fits) on files in tmp_path."""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path

import pandas as pd
import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.coupling_rows import COUPLING_COLUMNS
from loper_analysis.impedance.identification.impedance import IdentificationSettings
from loper_analysis.impedance.responses import ResponseSettings
from loper_analysis.io.truth import write_truth
from loper_analysis.stages.impedance.files import FitFiles, FitOutputs, TrialFiles
from loper_analysis.stages.impedance.step import subject_fits
from loper_analysis.stages.settings import stage_settings


def test_onset_without_trials_writes_missing_rows(tmp_path):
    anthropometry = {"subject": "S01", "sex": "male", "age_yr": 26, "height_m": 1.8, "mass_kg": 72}
    write_truth(
        tmp_path / "truth.yaml", anthropometry, {175: {j: {"K": 40.0, "D": 2.0} for j in ("hip", "knee", "ankle")}}
    )
    out = [tmp_path / n for n in ("r.tsv", "c.tsv", "f.tsv", "k.tsv")]
    files = FitFiles(
        trials={}, segments=tmp_path / "segments.tsv", outputs=FitOutputs(*out), truth=tmp_path / "truth.yaml"
    )
    rows = subject_fits("S01", {175: files})
    assert (rows.status == "missing").all() and rows.K_nm_per_rad.isna().all()
    assert (rows.K_true_nm_per_rad == 40.0).all()
    assert all(p.is_file() for p in out)
    assert pd.read_csv(out[2], sep="\t").status.tolist() == ["missing"] * 3


CONFIG = yaml.safe_load((Path(__file__).resolve().parents[3] / "config" / "config.yaml").read_text())


def test_settings_of_the_config():
    """The response settings of the shipped config are the library's defaults; the identification's besides the
    seed and the plausible ranges (the config's own); a changed key reaches its field."""
    settings = stage_settings(CONFIG, "impedance")
    assert settings.response == ResponseSettings()
    ident = CONFIG["impedance"]
    expected = dataclasses.replace(
        IdentificationSettings(), seed=CONFIG["seed"], plausible_ranges=ident["plausible_ranges"]
    )
    assert settings.identification == expected
    changed = copy.deepcopy(CONFIG)
    changed["impedance"]["min_vaf_pct"] = 12.5
    changed["strides"]["min_valid_strides"] = 8
    settings = stage_settings(changed, "impedance")
    assert settings.identification.min_vaf_pct == 12.5 and settings.response.min_strides == 8


def test_every_onset_of_a_subject_without_trials(tmp_path):
    """subject_fits: one FitFiles per onset, in the mapping's order; every output written (the couplings' table of
    an onset without a fit: its header, no row)."""
    names = ("r", "c", "f", "k", "force", "couplings")
    fits = {
        onset: FitFiles(
            trials={},
            segments=tmp_path / "segments.tsv",
            outputs=FitOutputs(*(tmp_path / f"{onset:03d}.{n}.tsv" for n in names)),
        )
        for onset in (300, 50)
    }
    rows = subject_fits("S01", fits)
    assert rows.onset_ms.tolist() == [300] * 3 + [50] * 3 and (rows.status == "missing").all()
    assert all(p.is_file() for files in fits.values() for p in dataclasses.astuple(files.outputs))
    couplings = pd.read_csv(tmp_path / "050.couplings.tsv", sep="\t")
    assert list(couplings.columns) == list(COUPLING_COLUMNS) and couplings.empty


def test_an_onset_s_trial_needs_its_force_and_markers(tmp_path):
    out = FitOutputs(*(tmp_path / n for n in ("r.tsv", "c.tsv", "f.tsv", "k.tsv")))
    trial = TrialFiles(angles=tmp_path / "a.tsv", strides=tmp_path / "s.tsv", force=tmp_path / "f.tsv")
    with pytest.raises(LoperInputError, match="trial pert050-1 of the onset needs its force and markers files"):
        FitFiles(trials={"pert050-1": trial}, segments=tmp_path / "segments.tsv", outputs=out)
    FitFiles(trials={}, segments=tmp_path / "segments.tsv", outputs=out, null_trials={"pert050-1": trial})
