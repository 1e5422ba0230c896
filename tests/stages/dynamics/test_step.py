"""The dynamics file step on a recorded lab's trial (tests/data/c3d-parser/RCH, run through the workflow's own
markers, model, ik, grf, events and strides rules): the tables it writes, their columns and units, a trial without
an ok contact, and nothing written when it fails."""

from __future__ import annotations

import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.config_file import update_config
from loper_analysis.dynamics.joint_cycles import CYCLE_COLUMNS, SUMMARY_COLUMNS
from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import read_model
from loper_analysis.layout import fill
from loper_analysis.stages import study_paths
from loper_analysis.stages.dynamics.files import DynamicsFiles
from loper_analysis.stages.dynamics.step import (
    DynamicsOutputs,
    DynamicsSettings,
    NoKnownLoadWarning,
    inverse_dynamics,
)
from tests.workflow_copy import copy_workflow, snakemake

pytestmark = pytest.mark.slow  # the workflow's upstream rules on a whole recorded trial (about 15 s)

ROOT = Path(__file__).resolve().parents[3]
LABS = ROOT / "tests/data/c3d-parser"
PATHS = study_paths()
SUBJECT, TRIAL = "RCH", "walk-nodevice"
SIDE_JOINTS = [(side, joint) for side in ("left", "right") for joint in ("hip", "knee", "ankle")]


def recorded_trial(work: Path, subject: str = SUBJECT, trial: str = TRIAL) -> dict:
    """A recorded lab's subject run as docs/first_recorded_subject.md does it (``inspect``, then the workflow's
    markers, model, ik, grf, events and strides rules) in ``work``. Returns the work folder, the merged config
    (the repository's config.yaml updated with the lab's sections) and the trial's files by name."""
    copy_workflow(work)
    raw = work / "data/raw" / subject
    raw.mkdir(parents=True)
    for name in ("static.c3d", f"{trial}.c3d"):
        shutil.copy(LABS / subject / name, raw / name)
    lab_config = work / "lab" / subject / "config.yaml"
    bin_dir = Path(sys.executable).parent
    res = subprocess.run(
        [bin_dir / "loper-analysis", "inspect", raw / "static.c3d", raw / f"{trial}.c3d", "--config-out", lab_config],
        cwd=work,
        capture_output=True,
        text=True,
        check=False,
    )
    assert res.returncode == 0, res.stderr[-3000:]
    (work / "lab/subjects.tsv").write_text(f"subject\tsource\n{subject}\trecorded\n")
    with lab_config.open("a") as f:
        f.write("subjects: lab/subjects.tsv\ndevice: {subject: null}\n")
    files = {
        "model": fill(PATHS.model.scaled, subject=subject),
        "ik": fill(PATHS.ik.mot, subject=subject, trial=trial),
        "grf": fill(PATHS.grf.mot, subject=subject, trial=trial),
        "contacts": fill(PATHS.events.contacts, subject=subject, trial=trial),
        "events": fill(PATHS.events.events, subject=subject, trial=trial),
        "strides": fill(PATHS.strides.strides, subject=subject, trial=trial),
        "markers_summary": fill(PATHS.markers.summary, subject=subject, trial=trial),
    }
    res = snakemake(
        work, *[files[k] for k in ("model", "ik", "grf", "contacts", "strides")], "--configfile", lab_config
    )
    assert res.returncode == 0, res.stderr[-3000:]
    config = yaml.safe_load((work / "config/config.yaml").read_text())
    update_config(config, yaml.safe_load(lab_config.read_text()))  # as Snakemake layers --configfile
    return {"work": work, "config": config, "files": {k: work / v for k, v in files.items()}}


def dynamics_files(trial: dict, **replaced) -> DynamicsFiles:
    """The step's input files of ``trial`` (:func:`recorded_trial`), some replaced by keyword."""
    f = trial["files"]
    paths = {
        "model_osim": f["model"],
        "ik_mot": f["ik"],
        "grf_mot": f["grf"],
        "contacts_tsv": f["contacts"],
        "events_tsv": f["events"],
        "strides_tsv": f["strides"],
    }
    paths.update(replaced)
    return DynamicsFiles(**paths)


def lab_settings(trial: dict) -> DynamicsSettings:
    """The step's settings with the lab's coordinate map (gait2392: knee_angle_* sign -1)."""
    return DynamicsSettings(coordinate_map=trial["config"]["ik"]["coordinate_map"])


@pytest.fixture(scope="module")
def trial(tmp_path_factory):
    return recorded_trial(tmp_path_factory.mktemp("dynamics_step"))


@pytest.fixture(scope="module")
def written(trial, tmp_path_factory):
    out = tmp_path_factory.mktemp("dynamics_out")
    outputs = DynamicsOutputs(out / "m.tsv", out / "c.tsv", out / "s.tsv", out / "f.png")
    cycles = inverse_dynamics(dynamics_files(trial), outputs, lab_settings(trial))
    return outputs, cycles


def _read(path) -> pd.DataFrame:
    return pd.read_csv(path, sep="\t", keep_default_na=False, na_values=[""])


def test_the_moments_table_has_the_documented_columns_and_units(trial, written):
    outputs, _ = written
    moments = _read(outputs.moments)
    expected = ["time_s"]
    for side, joint in SIDE_JOINTS:
        expected += [f"{joint}_{side}_{q}" for q in ("moment_nm", "moment_nm_per_kg", "power_w_per_kg")]
    assert list(moments.columns) == [*expected, "valid_left", "valid_right"]
    assert moments["valid_left"].dtype == bool and moments["valid_left"].any() and moments["valid_right"].any()
    # per kg: divided by the scaled model's total mass
    model = read_model(trial["files"]["model"])
    bodies = model.getBodySet()
    mass = sum(bodies.get(i).getMass() for i in range(bodies.getSize()))
    for side, joint in SIDE_JOINTS:
        np.testing.assert_allclose(
            moments[f"{joint}_{side}_moment_nm_per_kg"], moments[f"{joint}_{side}_moment_nm"] / mass, rtol=1e-6
        )
    # the valid times: RCH walks over 5 plates, L R L R L, each foot alone on its plate
    t = moments["time_s"].to_numpy()
    left = t[moments["valid_left"].to_numpy()]
    assert left.min() == pytest.approx(5.881, abs=0.011) and left.max() == pytest.approx(8.855, abs=0.011)
    # in stance the ankle's moment is plantarflexor (negative, our sense: dorsiflexion positive), N·m of a child
    stance = (t > 6.0) & (t < 6.4)
    assert moments.loc[stance, "ankle_left_moment_nm"].max() < 0
    assert moments.loc[stance, "ankle_left_moment_nm"].min() > -100


def test_the_cycles_are_the_valid_strides_normalised(written, trial):
    outputs, cycles = written
    table = _read(outputs.cycles)
    assert list(table.columns) == list(CYCLE_COLUMNS)
    strides = _read(trial["files"]["strides"])
    kept = strides[~strides["removed"].astype(bool)]
    # both left strides of RCH lie in the left foot's valid times
    assert sorted(set(zip(table["side"], table["stride"]))) == sorted(zip(kept["side"], kept["stride"]))
    counts = table.groupby(["side", "stride", "joint"]).size()
    assert (counts == 101).all() and len(counts) == 3 * len(kept)
    first = table[table["percent_cycle"] == 0.0]
    assert len(first) == len(counts)
    np.testing.assert_allclose(table["percent_cycle"].max(), 100.0)
    pd.testing.assert_frame_equal(table.reset_index(drop=True), cycles.reset_index(drop=True), check_dtype=False)
    summary = _read(outputs.summary)
    assert list(summary.columns) == list(SUMMARY_COLUMNS) and (summary["n_strides"] == len(kept)).all()
    assert Path(outputs.figure).stat().st_size > 10_000


def test_a_trial_without_an_ok_contact_has_empty_cycles_and_a_warning(trial, tmp_path):
    contacts = _read(trial["files"]["contacts"])
    contacts["flag"] = "two_feet"
    flagged = tmp_path / "flagged.contacts.tsv"
    contacts.to_csv(flagged, sep="\t", index=False)
    outputs = DynamicsOutputs(tmp_path / "m.tsv", tmp_path / "c.tsv")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cycles = inverse_dynamics(dynamics_files(trial, contacts_tsv=flagged), outputs, lab_settings(trial))
    said = [str(w.message) for w in caught if issubclass(w.category, NoKnownLoadWarning)]
    assert [side for side in ("left", "right") if any(f"no ok contact of the {side} foot" in m for m in said)] == [
        "left",
        "right",
    ]
    assert cycles.empty
    assert list(_read(outputs.cycles).columns) == list(CYCLE_COLUMNS) and _read(outputs.cycles).empty
    moments = _read(outputs.moments)
    assert not moments["valid_left"].any() and not moments["valid_right"].any()


def test_nothing_is_written_when_the_step_fails(trial, tmp_path):
    contacts = _read(trial["files"]["contacts"])
    contacts.loc[0, "plate"] = 9  # a plate the ground reactions lack
    wrong = tmp_path / "wrong.contacts.tsv"
    contacts.to_csv(wrong, sep="\t", index=False)
    outputs = DynamicsOutputs(tmp_path / "m.tsv", tmp_path / "c.tsv", tmp_path / "s.tsv", tmp_path / "f.png")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(LoperInputError, match="plate 9"):
            inverse_dynamics(dynamics_files(trial, contacts_tsv=wrong), outputs, lab_settings(trial))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["wrong.contacts.tsv"]
