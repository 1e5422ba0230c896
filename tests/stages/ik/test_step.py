"""The IK file steps (loper_analysis.stages.ik.step): a TRC solved in time chunks and joined equals one solve of it; a
clinical lab's walking trial checked against its own static trial and against another lab's."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.config_file import update_config
from loper_analysis.errors import LoperInputError
from loper_analysis.io.opensim_tables import read_markers, read_mot, write_trc
from loper_analysis.io.osim import read_marker_set, read_model, write_model
from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.ik_settings import IKSettings
from loper_analysis.motion.marker_geometry import (
    geometry_change,
    geometry_ratio,
    marker_geometry,
    same_body_marker_pairs,
)
from loper_analysis.motion.model import MARKERS, build_lower_body_model
from loper_analysis.stages.ik.step import ik_chunk, ik_join, ik_trial
from loper_analysis.stages.inspect import inspect_subject
from loper_analysis.stages.markers.step import markers
from loper_analysis.stages.settings import stage_settings

FS = 128.0
ROOT = Path(__file__).resolve().parents[3]
LABS = ROOT / "tests" / "data" / "c3d-parser"


@pytest.fixture(scope="module")
def trial(tmp_path_factory):
    """A generic model (.osim) and a 2 s TRC of its markers moved through known angles."""
    tmp = tmp_path_factory.mktemp("ik_steps")
    model = build_lower_body_model(1.73, 64.9)
    t = np.arange(256) / FS
    w = 2 * np.pi * 0.6
    truth = {
        "pelvis_tx": 0.02 * np.sin(2 * w * t),
        "pelvis_ty": 0.93 + 0.01 * np.sin(2 * w * t),
        "pelvis_tilt": 0.05 * np.sin(w * t),
        "hip_flexion_l": 0.1 + 0.3 * np.sin(w * t),
        "knee_flexion_l": 0.6 + 0.5 * np.sin(w * t + 1),
        "ankle_dorsiflexion_l": 0.1 * np.sin(w * t + 2),
    }
    trc = write_trc(tmp / "trial.trc", t, marker_positions(model, truth), list(MARKERS))
    return write_model(model, tmp / "model.osim"), trc, truth


def test_chunks_joined_through_files_equal_the_whole_trial(trial, tmp_path):
    model_osim, trc, truth = trial
    fine = IKSettings(tree_step_tolerance=1e-8)
    whole = ik_trial(model_osim, trc, tmp_path / "whole.mot", tmp_path / "whole.angles.tsv", fine)
    np.testing.assert_allclose(whole.knee_left_rad, truth["knee_flexion_l"], atol=np.deg2rad(0.1) / 10)
    mots = [tmp_path / f"chunk{c}.mot" for c in range(3)]
    for c, mot in enumerate(mots):
        ik_chunk(model_osim, trc, mot, c, 3, fine)
    assert [len(read_mot(m)) for m in mots] == [85, 86, 85]
    joined = ik_join(mots, tmp_path / "joined.mot", tmp_path / "joined.angles.tsv", summary_tsv=tmp_path / "j.ik.tsv")
    assert (tmp_path / "joined.mot").is_file() and (tmp_path / "joined.angles.tsv").is_file()
    summary = pd.read_csv(tmp_path / "j.ik.tsv", sep="\t").iloc[0]  # the chunks keep no marker errors
    assert (summary.n_frames, summary.n_frames_solved, summary.n_frames_left_out) == (256, 256, 0)
    assert np.isnan(summary.marker_rms_mean_m) and summary.last_solved_s == whole.time_s.iloc[-1]
    assert list(joined.columns) == list(whole.columns)
    np.testing.assert_allclose(joined.time_s, whole.time_s, atol=1e-9)
    np.testing.assert_allclose(joined.drop(columns="time_s"), whole.drop(columns="time_s"), atol=1e-7)


def test_joining_an_overlapping_chunk_names_its_file(trial, tmp_path):
    model_osim, trc, _ = trial
    first, again = tmp_path / "first.mot", tmp_path / "again.mot"
    ik_chunk(model_osim, trc, first, 0, 3)
    again.write_bytes(first.read_bytes())
    with pytest.raises(LoperInputError, match=r"again\.mot: starts at t = 0\.0000"):
        ik_join([first, again], tmp_path / "out.mot", tmp_path / "out.angles.tsv")
    assert not (tmp_path / "out.mot").exists() and not (tmp_path / "out.angles.tsv").exists()


@pytest.fixture(scope="module")
def rch(tmp_path_factory):
    """The children's hospital's static and walking trial (tests/data/c3d-parser/RCH) onboarded as a lab would
    (``inspect``: Plug-in Gait on gait2392) and through the markers step, and another lab's static trial (QCMAS)
    through the same settings but the label map (its labels are the template's names). Returns the TRCs, the
    template's model with its markers (not scaled to this child) and the IK settings of the lab's config,
    loosened: every marker of the walk weighs 1, the others 0, and IK's marker error never stops (the model's
    fit is not tested here)."""
    tmp = tmp_path_factory.mktemp("rch")
    lab = tmp / "lab"
    inspect_subject([LABS / "RCH/static.c3d", LABS / "RCH/walk-nodevice.c3d"], lab / "config.yaml")
    config = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    update_config(config, yaml.safe_load((lab / "config.yaml").read_text()))  # as Snakemake layers --configfile
    label_map = config["markers"]["label_map"]  # as the workflow passes it to every trial
    settings = dataclasses.replace(stage_settings(config, "markers"), label_map=(label_map,) if label_map else None)
    trcs = {}
    for name, c3d, trial_settings in (
        ("static", LABS / "RCH/static.c3d", settings.for_static()),
        ("walk", LABS / "RCH/walk-nodevice.c3d", settings),
        ("QCMAS static", LABS / "QCMAS/static.c3d", dataclasses.replace(settings.for_static(), label_map=None)),
    ):
        trcs[name] = tmp / f"{name.replace(' ', '-')}.trc"
        markers(c3d, trcs[name], settings=trial_settings)
    model = read_model(lab / "gait2392_simbody.osim")
    model.updateMarkerSet(read_marker_set(lab / "marker_set.xml"))
    walk_labels = read_markers(trcs["walk"])[2]
    names = [model.getMarkerSet().get(i).getName() for i in range(model.getMarkerSet().getSize())]
    loose = dataclasses.replace(
        stage_settings(config, "ik"),
        tasks_file=None,
        marker_weights={name: 0.0 for name in names if name not in walk_labels},
        max_marker_rms_m=np.inf,
        warn_marker_rms_m=None,
    )
    return trcs, write_model(model, tmp / "model.osim"), loose


def _geometry(model_osim, trc, static_trc) -> pd.DataFrame:
    _, X, labels = read_markers(trc)
    _, S, static_labels = read_markers(static_trc)
    pairs = same_body_marker_pairs(read_model(model_osim), labels, min_distance_m=0.0)
    return marker_geometry(pairs, X, labels, S, static_labels).set_index(["marker_a", "marker_b"])


def test_a_clinical_walk_keeps_the_marker_geometry_of_its_own_static_trial(rch, tmp_path):
    trcs, model_osim, settings = rch
    table = _geometry(model_osim, trcs["walk"], trcs["static"])
    assert len(table) >= 8  # the pelvis's 6 pairs of ASIS and PSIS markers, heel-toe on each foot, ...
    psis = table.loc[("LPSI", "RPSI")]  # measured: 100.7 mm standing, 102.0 walking (the template's gait2392: 90)
    assert psis.reference_distance_m == pytest.approx(0.1007, abs=1e-3)
    assert psis.trial_distance_m == pytest.approx(0.1020, abs=1e-3)
    assert table.loc[("LASI", "RASI")].reference_distance_m == pytest.approx(0.1978, abs=1e-3)
    assert table.loc[("LASI", "RASI")].trial_distance_m == pytest.approx(0.1939, abs=1e-3)
    assert table.loc[("LHEE", "LTOE")].reference_distance_m == pytest.approx(0.1066, abs=1e-3)
    assert table.loc[("LHEE", "LTOE")].trial_distance_m == pytest.approx(0.1094, abs=1e-3)
    assert geometry_change(table) < 0.02  # median over the pairs (measured: 1.5 to 1.8 %)
    assert np.abs(table["change"]).max() < 0.04
    # the step: IK of the walk with the static trial as its reference keeps it
    summary = tmp_path / "walk.ik.tsv"
    ik_trial(
        model_osim, trcs["walk"], tmp_path / "walk.mot", tmp_path / "walk.angles.tsv", settings, summary,
        static_trc=trcs["static"],
    )  # fmt: skip
    row = pd.read_csv(summary, sep="\t", keep_default_na=False).iloc[0]
    assert row["marker_geometry_change"] == pytest.approx(geometry_change(table), abs=1e-9)
    assert "geometry" not in row["warnings"]


def test_a_clinical_walk_against_another_labs_static_trial_stops_its_ik(rch, tmp_path):
    trcs, model_osim, settings = rch
    table = _geometry(model_osim, trcs["walk"], trcs["QCMAS static"])
    # an adult of 1.86 m: the pelvis 271 mm wide at the ASIS markers (the child's 194), heel-toe 196 (109)
    assert table.loc[("LASI", "RASI")].reference_distance_m == pytest.approx(0.2709, abs=1e-3)
    assert table.loc[("LHEE", "LTOE")].reference_distance_m == pytest.approx(0.1963, abs=1e-3)
    assert table.loc[("LPSI", "RPSI")].reference_distance_m == pytest.approx(0.0859, abs=1e-3)
    change, ratio = geometry_change(table), geometry_ratio(table)
    # measured: 8.3 % over 10 pairs (13.5 % over the 8 without the medial malleolus): the adult's ankle and
    # malleolus markers sit about as far apart as the child's
    assert settings.geometry_stop_change < change < 0.14
    out = tmp_path / "walk.mot"
    with pytest.raises(LoperInputError) as err:
        ik_chunk(model_osim, trcs["walk"], out, 0, 1, settings, trcs["QCMAS static"])
    message = str(err.value)
    assert message.startswith(f"{trcs['walk']} with {model_osim}: the distances between markers on one body ")
    assert f"differ from the same pairs in the static trial {trcs['QCMAS static']} by {100 * change:.1f} %" in message
    assert (
        f"in the median of {len(table)} pairs (limit ik.geometry_stop_change 0.08; trial/static ratio "
        f"{ratio:.3f})" in message
    )
    assert ": RHEE-RTOE (calcn_r) 104 mm against 192, LHEE-LTOE (calcn_l) 109 mm against 196" in message
    assert "Is this a recording of another subject, or the static trial of another subject?" in message
    assert not out.exists()


def test_without_a_static_trial_the_walk_is_compared_with_the_models_markers_and_says_so(rch, tmp_path):
    trcs, model_osim, settings = rch
    out = tmp_path / "walk.mot"
    with pytest.raises(LoperInputError) as err:  # the template's markers on gait2392 as distributed: an adult's
        ik_chunk(model_osim, trcs["walk"], out, 0, 1, settings)
    message = str(err.value)
    _, X, labels = read_markers(trcs["walk"])
    table = marker_geometry(same_body_marker_pairs(read_model(model_osim), labels), X, labels)
    change, ratio = geometry_change(table), geometry_ratio(table)
    assert change > settings.geometry_stop_change  # measured: 13.4 % over 10 pairs (the PSIS: 102 mm against 90)
    assert f"differ from the subject's model's markers (no static trial to compare with) by {100 * change:.1f} %" in (
        message
    )
    assert f"(limit ik.geometry_stop_change 0.08; trial/model ratio {ratio:.3f})" in message
    assert not out.exists()
