"""``loper-analysis inspect`` on seven clinical labs' own static + walking pairs (tests/data/c3d-parser, provenance
in tests/data/c3d-parser/inspect_pairs.md and README.md): the synonym table, the lab's label map, what the written
config may hold (markers present, a cut-off below Nyquist) and the dry run that comes before anything is written."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.cli import main
from loper_analysis.inspection import MAX_CUTOFF_RATE_FRACTION, marker_cutoff_hz
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.c3d_writer import write_recording
from loper_analysis.io.osim import read_marker_set
from loper_analysis.io.readers import read_label_map, read_tsv
from loper_analysis.motion.marker_names import strip_subject_prefix
from loper_analysis.motion.marker_templates import derived_markers
from loper_analysis.stages.inspect import inspect_subject
from loper_analysis.subject_setup import NoTemplateFits

DATA = Path(__file__).resolve().parents[1] / "data" / "c3d-parser"
LABS = ("AUC", "FMC", "MH", "QCMAS", "RBWH", "RCH", "SYD")


def _pair(lab: str) -> list[Path]:
    return [DATA / lab / "static.c3d", DATA / lab / "walk-nodevice.c3d"]


def _present(path: Path) -> set[str]:
    rec = read_c3d(path)
    seen = np.all(np.isfinite(rec.markers_m), axis=2).any(axis=0)
    return {strip_subject_prefix(lab) for lab, s in zip(rec.marker_labels, seen) if s}


def test_auc_qualisys_labels_choose_plug_in_gait_with_every_required_group(tmp_path):
    result = inspect_subject(_pair("AUC"), tmp_path / "AUC" / "config.yaml")
    setup = result.setup
    assert setup.template.name == "plugin_gait" and setup.fits[0].fits
    assert len(setup.template.required) - len(setup.fits[0].missing_groups) == 12
    assert dict(zip(setup.label_map["label"], setup.label_map["marker"])) == {
        "STER_NOTCH": "CLAV",
        "RLA_TOE": "RTOE",
        "LLA_TOE": "LTOE",
        "RMed_kn": "RMKNE",
        "LMed_kn": "LMKNE",
        "RMed_ank": "RMMAL",
        "LMed_ank": "LMMAL",
    }
    # no template marker for these: trochanter, fibular head, acromion, T2, first metatarsal head
    assert set(setup.unmapped) == {"RACROM", "LACROM", "T2", "RTROC", "LTROC", "RFIB", "LFIB", "RMed_toe", "LMed_toe"}
    assert setup.static_only == ("RMKNE", "LMKNE", "RMMAL", "LMMAL")  # the walk has no medial markers
    # the walk lacks the medial labels: their rows go to the static trial's own map
    assert read_label_map(tmp_path / "AUC" / "label_map.tsv") == {
        "STER_NOTCH": "CLAV",
        "RLA_TOE": "RTOE",
        "LLA_TOE": "LTOE",
    }
    doc = yaml.safe_load((tmp_path / "AUC" / "config.yaml").read_text())
    assert doc["markers"]["trial_label_maps"] == {"static": str(tmp_path / "AUC" / "label_map_static.tsv")}
    assert doc["markers"]["filter"]["cutoff_hz"] == 40  # 120 Hz markers: min(40, 0.4 x 120 = 48)


#: Medial spellings of Vicon labs and the template marker each is.
MEDIAL = {
    "FMC": {"LKNEMED": "LMKNE", "RKNEMED": "RMKNE", "LMED": "LMMAL", "RMED": "RMMAL"},
    "MH": {"LMED": "LMMAL", "RMED": "RMMAL"},
    "RBWH": {"LMKN": "LMKNE", "RMKN": "RMKNE", "LMED": "LMMAL", "RMED": "RMMAL"},
    "RCH": {"LMED": "LMMAL", "RMED": "RMMAL"},
    "SYD": {"LMED": "LMMAL", "RMED": "RMMAL"},
    "QCMAS": {},
}


@pytest.mark.parametrize("lab", sorted(MEDIAL))
def test_vicon_medial_spellings_map_to_the_medial_markers_they_are(lab, tmp_path):
    setup = inspect_subject(_pair(lab)).setup
    assert setup.template.name == "plugin_gait" and setup.fits[0].fits
    assert dict(zip(setup.label_map["label"], setup.label_map["marker"])) == MEDIAL[lab]
    # LMED is the medial malleolus: beside the lateral one, far from the knee (median over the static trial)
    rec = read_c3d(DATA / lab / "static.c3d")
    labels = list(rec.marker_labels)

    def distance_m(a: str, b: str) -> float:
        X = rec.markers_m
        return float(np.nanmedian(np.linalg.norm(X[:, labels.index(a)] - X[:, labels.index(b)], axis=1)))

    if "LMED" in labels:
        knee = "LKNE" if "LKNE" in labels else "LKAX"
        assert 0.06 < distance_m("LMED", "LANK") < 0.12 and distance_m("LMED", knee) > 0.30


@pytest.mark.parametrize("lab", LABS)
def test_the_written_marker_set_holds_only_markers_of_the_static_trial(lab, tmp_path):
    out = tmp_path / lab / "config.yaml"
    result = inspect_subject(_pair(lab), out)
    setup = result.setup
    to_marker = dict(zip(setup.label_map["label"], setup.label_map["marker"]))
    present = {to_marker.get(lab_, lab_) for lab_ in _present(DATA / lab / "static.c3d")}
    present |= set(derived_markers(sorted(present)))  # a knee alignment device yields the knee marker
    ms = read_marker_set(out.parent / "marker_set.xml")
    # the template's markers (a marker set may add virtual markers the calibration computes, no lab's label)
    names = {ms.get(i).getName() for i in range(ms.getSize())} & set(setup.template.marker_names)
    assert names == set(setup.static_markers) and names <= present
    tasks = read_tsv(out.parent / "ik_tasks.tsv")
    assert set(tasks.loc[tasks["kind"] == "marker", "name"]) <= names
    walking = {to_marker.get(lab_, lab_) for lab_ in _present(DATA / lab / "walk-nodevice.c3d")}
    assert set(tasks.loc[tasks["kind"] == "marker", "name"]) <= walking
    for key in ("label_map", *yaml.safe_load(out.read_text())["markers"].get("trial_label_maps", {})):
        path = out.parent / ("label_map.tsv" if key == "label_map" else f"label_map_{key}.tsv")
        if path.is_file():  # every row names a label its trial holds
            trials = ["static", "walk-nodevice"] if key == "label_map" else [key]
            for trial in trials:
                held = {strip_subject_prefix(x) for x in read_c3d(DATA / lab / f"{trial}.c3d").marker_labels}
                assert set(read_label_map(path)) <= held


def test_a_marker_never_present_in_the_static_is_left_out_and_its_pairs_said(tmp_path):
    rec = read_c3d(DATA / "QCMAS" / "static.c3d")
    X = rec.markers_m.copy()
    X[:, rec.marker_labels.index("CLAV")] = np.nan  # the label stays, the marker is never seen
    static = tmp_path / "in" / "static.c3d"
    static.parent.mkdir()
    write_recording(static, dataclasses.replace(rec, markers_m=X))
    result = inspect_subject([static, DATA / "QCMAS" / "walk-nodevice.c3d"], tmp_path / "S" / "config.yaml")
    assert "CLAV" not in result.setup.static_markers and "CLAV" not in result.setup.walking_markers
    assert "static.c3d: label(s) present in no frame, left out of the marker set and the scaling: CLAV" in result.text
    assert "measurement torso: no pair left (RASI-CLAV, LASI-CLAV; the static trial lacks CLAV)" in result.text


# ---------------------------------------------------------------- the cut-off below Nyquist


def test_the_cut_off_rule_and_the_filter_it_keeps():
    from scipy.signal import butter, sosfreqz

    assert marker_cutoff_hz(40.0, [100.0])[0] == 40.0
    assert marker_cutoff_hz(40.0, [120.0, 250.0])[0] == 40.0
    assert marker_cutoff_hz(40.0, [60.0])[0] == pytest.approx(24.0)  # < Nyquist 30 Hz
    assert marker_cutoff_hz(40.0, [250.0, 60.0])[0] == pytest.approx(24.0)  # the lowest rate rules
    assert marker_cutoff_hz(None, [60.0])[0] is None
    # at 0.4 of the rate the zero-phase order-4 Butterworth passes 10 Hz and stops 0.9 of Nyquist
    rate = 60.0
    sos = butter(4, MAX_CUTOFF_RATE_FRACTION * rate / (rate / 2), output="sos")
    _, h = sosfreqz(sos, worN=[10.0, 0.45 * rate], fs=rate)
    gain = np.abs(h) ** 2  # forward and backward
    assert gain[0] > 0.999 and gain[1] < 0.01


def test_a_60_hz_lab_gets_a_cut_off_below_its_nyquist_frequency(tmp_path):
    walk = read_c3d(DATA / "QCMAS" / "walk-nodevice.c3d")
    static = read_c3d(DATA / "QCMAS" / "static.c3d")
    folder = tmp_path / "raw"
    folder.mkdir()
    for name, rec in (("static", static), ("walk-nodevice", walk)):  # the same frames, declared at 60 Hz
        slow = dataclasses.replace(rec, point_rate_hz=60.0, analog_rate_hz=600.0)
        write_recording(folder / f"{name}.c3d", slow)
    out = tmp_path / "S" / "config.yaml"
    result = inspect_subject([folder / "static.c3d", folder / "walk-nodevice.c3d"], out, cutoff_hz=40.0)
    cutoff = yaml.safe_load(out.read_text())["markers"]["filter"]["cutoff_hz"]
    assert cutoff == pytest.approx(24.0) and cutoff < 30.0
    assert "min(configured 40, 0.4 x 60 Hz markers = 24) Hz: below the Nyquist frequency 30 Hz" in result.text


# ---------------------------------------------------------------- the lab's label map, round trip


def _renamed_pair(tmp_path: Path) -> list[Path]:
    """QCMAS's pair with the toes labelled LZEH/RZEH (no synonym spells them) and the medial knees MK_L/MK_R."""
    names = {"LTOE": "LZEH", "RTOE": "RZEH", "LMKNE": "MK_L", "RMKNE": "MK_R"}
    folder = tmp_path / "raw"
    folder.mkdir()
    out = []
    for name in ("static", "walk-nodevice"):
        rec = read_c3d(DATA / "QCMAS" / f"{name}.c3d")
        labels = [names.get(lab, lab) for lab in rec.marker_labels]
        write_recording(folder / f"{name}.c3d", dataclasses.replace(rec, marker_labels=labels))
        out.append(folder / f"{name}.c3d")
    return out


def test_the_starter_map_completed_and_given_back_is_used(tmp_path, capsys):
    files = _renamed_pair(tmp_path)
    out = tmp_path / "lab" / "S1" / "config.yaml"
    assert main(["inspect", *map(str, files), "--config-out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "missing: LTOE, RTOE" in err and "labels left without a marker: " in err and "LZEH" in err
    starter = out.parent / "label_map_starter.tsv"
    assert sorted(p.name for p in out.parent.iterdir()) == ["label_map_starter.tsv"]
    table = read_tsv(starter, "starter", ("label", "marker"), dtype=str, keep_default_na=False)
    rows = dict(zip(table["label"], table["marker"]))
    assert rows["LASI"] == "LASI" and rows["LZEH"] == "" and rows["MK_L"] == "" and rows["RBAK"] == ""
    # the lab fills in the toes and the medial knees, leaves the rest as it is
    table.loc[table["label"] == "LZEH", "marker"] = "LTOE"
    table.loc[table["label"] == "RZEH", "marker"] = "RTOE"
    table.loc[table["label"] == "MK_L", "marker"] = "LMKNE"
    table.loc[table["label"] == "MK_R", "marker"] = "RMKNE"
    table.to_csv(starter, sep="\t", index=False)
    assert main(["inspect", *map(str, files), "--config-out", str(out), "--label-map", str(starter)]) == 0
    printed = capsys.readouterr().out
    n_rows = int((table["marker"] != "").sum())  # the rows left empty are skipped
    assert f"label map given: {n_rows} row(s) ({starter})" in printed and n_rows == 25 - 1  # RBAK: no marker
    assert "dry run: every trial's markers read" in printed
    assert read_label_map(out.parent / "label_map.tsv") == {"LZEH": "LTOE", "RZEH": "RTOE"}
    assert read_label_map(out.parent / "label_map_static.tsv") == {"MK_L": "LMKNE", "MK_R": "RMKNE"}
    ms = read_marker_set(out.parent / "marker_set.xml")
    assert {"LTOE", "RTOE", "LMKNE", "RMKNE"} <= {ms.get(i).getName() for i in range(ms.getSize())}


def test_markers_label_map_of_a_configfile_is_used(tmp_path, capsys):
    files = _renamed_pair(tmp_path)
    given = tmp_path / "lab" / "map.tsv"
    given.parent.mkdir()
    pd.DataFrame({"label": ["LZEH", "RZEH"], "marker": ["LTOE", "RTOE"]}).to_csv(given, sep="\t", index=False)
    extra = tmp_path / "lab" / "inspect.yaml"
    extra.write_text(f"markers:\n  label_map: {given}\n")
    out = tmp_path / "lab" / "S1" / "config.yaml"
    with pytest.raises(NoTemplateFits):
        inspect_subject(files)
    assert main(["inspect", *map(str, files), "--config-out", str(out), "--configfile", str(extra)]) == 0
    assert read_label_map(out.parent / "label_map.tsv") == {"LZEH": "LTOE", "RZEH": "RTOE"}
    # MK_L and MK_R stay unmapped: the medial knees are left out, the rest is as usual
    assert "labels without a template marker (kept, not used): RBAK, MK_L, MK_R" in capsys.readouterr().out


# ---------------------------------------------------------------- the dry run


@pytest.mark.slow
def test_a_static_trial_that_cannot_scale_stops_inspect_and_nothing_is_written(tmp_path, capsys):
    rec = read_c3d(DATA / "QCMAS" / "static.c3d")
    X = rec.markers_m.copy()
    for label in ("LASI", "LPSI"):  # the left pelvis markers 1 m out: a pelvis 5 times the model's
        X[:, rec.marker_labels.index(label), 0] += 1.0
    static = tmp_path / "raw" / "static.c3d"
    static.parent.mkdir()
    write_recording(static, dataclasses.replace(rec, markers_m=X))
    out = tmp_path / "lab" / "S1" / "config.yaml"
    code = main(["inspect", str(static), str(DATA / "QCMAS" / "walk-nodevice.c3d"), "--config-out", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert "inspect: nothing written: scaling the static trial" in err
    assert "scale factor(s) outside 0.5 .. 2" in err and "pelvis 5.1" in err
    assert "the lab must add a static trial" in err and "LASI, LHEE" in err
    assert not out.parent.exists()


@pytest.mark.slow
@pytest.mark.parametrize("lab", LABS)
def test_every_lab_passes_the_dry_run(lab, tmp_path, capsys):
    out = tmp_path / lab / "config.yaml"
    assert main(["inspect", *map(str, _pair(lab)), "--config-out", str(out)]) == 0
    assert "dry run: every trial's markers read and the static trial static.c3d scaled" in capsys.readouterr().out
    assert out.is_file()
