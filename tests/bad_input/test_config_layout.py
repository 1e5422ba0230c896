"""A config in the former layout (sections ``trials``, ``filter``, ``opensim``, ``identification``; the static
trial's keys under ``markers``; ``ik.accuracy``, now two keys) is read once through the translation, which says on
the console where each of its keys stands now; a key in the wrong section is refused in one line naming the key and
where it belongs; nothing is written either way."""

from __future__ import annotations

import copy

import pytest
import yaml

from loper_analysis.config_file import load_config
from loper_analysis.config_sections import translated
from loper_analysis.errors import LoperInputError
from tests.study_files import CONFIG
from tests.workflow_copy import copy_workflow, snakemake

OLD_LAYOUT = (
    "trials: {perturbation_repeats: 1}\n"
    "filter: {cutoff_hz: 12.0}\n"
    "opensim: {accuracy: 1.0e-5, brace_attachment_fraction: 0.7}\n"
    "markers: {static_duration_s: 0.5}\n"
    "identification: {n_starts: 3}\n"
)
MOVES = (
    "trials.perturbation_repeats -> study.perturbation_repeats; filter.cutoff_hz -> markers.filter.cutoff_hz; "
    "identification.n_starts -> impedance.n_starts; "
    "opensim.accuracy -> ik.tree_step_tolerance and ik.opensim_accuracy; "
    "opensim.brace_attachment_fraction -> model.brace_attachment_fraction; "
    "markers.static_duration_s -> model.static_duration_s"
)


def test_the_former_layout_is_read_at_the_new_places_and_said(tmp_path, capsys):
    old = tmp_path / "old.yaml"
    old.write_text(OLD_LAYOUT)
    config, _ = load_config(["config/config.yaml", old])
    assert f"config: {old} is in the former layout, read as: {MOVES}" in capsys.readouterr().err
    assert config["study"]["perturbation_repeats"] == 1 and config["markers"]["filter"]["cutoff_hz"] == 12.0
    assert config["ik"]["tree_step_tolerance"] == config["ik"]["opensim_accuracy"] == 1e-5
    assert "accuracy" not in config["ik"] and config["model"]["brace_attachment_fraction"] == 0.7
    assert config["model"]["static_duration_s"] == 0.5 and config["impedance"]["n_starts"] == 3
    assert not {"trials", "filter", "opensim", "identification"} & set(config)


def test_the_former_ik_accuracy_is_read_at_both_its_keys_and_said(tmp_path, capsys):
    """``ik.accuracy`` was both the tree solver's step tolerance and OpenSim's solver's accuracy: its value goes
    to both keys (over the shipped config's), so the file is read with the meaning it had."""
    old = tmp_path / "old.yaml"
    old.write_text("ik: {accuracy: 1.0e-5, ik_solver: opensim}\n")
    config, _ = load_config(["config/config.yaml", old])
    said = "ik.accuracy -> ik.tree_step_tolerance and ik.opensim_accuracy"
    assert f"config: {old} is in the former layout, read as: {said}\n" in capsys.readouterr().err
    assert config["ik"]["tree_step_tolerance"] == config["ik"]["opensim_accuracy"] == 1e-5
    assert "accuracy" not in config["ik"] and config["ik"]["ik_solver"] == "opensim"


def test_a_split_key_goes_to_each_of_its_keys_over_their_values():
    """The translation itself: a former ``ik.accuracy`` (or ``opensim.accuracy``) wins over both new keys."""
    config = {"ik": {"accuracy": 1e-5, "tree_step_tolerance": 1e-8, "opensim_accuracy": 1e-7}}
    assert translated(config) == ["ik.accuracy -> ik.tree_step_tolerance and ik.opensim_accuracy"]
    assert config == {"ik": {"tree_step_tolerance": 1e-5, "opensim_accuracy": 1e-5}}
    config = {"opensim": {"accuracy": 1e-4}}
    assert translated(config) == ["opensim.accuracy -> ik.tree_step_tolerance and ik.opensim_accuracy"]
    assert config == {"ik": {"tree_step_tolerance": 1e-4, "opensim_accuracy": 1e-4}}
    assert translated(config) == []  # the layout now: nothing to move


def test_the_shipped_config_translated_from_its_former_layout_is_itself():
    """The former layout of the shipped config (rebuilt by hand from the table of moves) reads as the config."""
    c = copy.deepcopy(CONFIG)
    former = {k: v for k, v in c.items() if k not in ("study", "impedance", "model", "ik")}
    former["markers"] = {k: v for k, v in c["markers"].items() if k != "filter"}
    former["markers"].update({k: c["model"][k] for k in ("static_duration_s", "static_max_motion_rms_m")})
    former["trials"], former["identification"], former["filter"] = c["study"], c["impedance"], c["markers"]["filter"]
    former["opensim"] = {**{k: v for k, v in c["model"].items() if not k.startswith("static_")}, **c["ik"]}
    assert former["opensim"].pop("tree_step_tolerance") == former["opensim"].pop("opensim_accuracy")
    former["opensim"]["accuracy"] = c["ik"]["opensim_accuracy"]  # one key for both then
    moves = translated(former)
    assert len(moves) == 6 + 2 + 21 + 2 + 18 and former == c


def test_the_workflow_reads_a_former_layout_file_and_says_so(tmp_path):
    work = copy_workflow(tmp_path)
    (work / "old.yaml").write_text(OLD_LAYOUT)
    run = snakemake(work, "-n", "--configfile", "old.yaml")
    assert run.returncode == 0, run.stderr[-2000:]
    assert f"config: keys of the former layout read at their places now: {MOVES}" in run.stderr
    assert not (work / "results").exists()


@pytest.mark.parametrize(
    ("yaml_text", "key", "belongs"),
    [
        ("impedance: {cutoff_hz: 12.0}\n", "impedance.cutoff_hz", "'markers.filter.cutoff_hz' or 'dynamics.cutoff_hz'"),
        ("ik: {generic_model: m.osim}\n", "ik.generic_model", "'model.generic_model'"),
        ("study: {n_starts: 3}\n", "study.n_starts", "'impedance.n_starts'"),
    ],
)
def test_a_key_in_the_wrong_section_is_refused_naming_where_it_belongs(tmp_path, yaml_text, key, belongs):
    wrong = tmp_path / "wrong.yaml"
    wrong.write_text(yaml_text)
    name = key.rpartition(".")[2]
    with pytest.raises(LoperInputError) as err:
        load_config(["config/config.yaml", wrong])
    assert str(err.value).startswith(f"{wrong}: key '{key}': ")
    assert str(err.value).endswith(f"a key '{name}' belongs in {belongs}: move it there")
    assert yaml.safe_load(wrong.read_text())  # the file is as it was


def test_the_workflow_refuses_a_key_in_the_wrong_section_before_any_job(tmp_path):
    work = copy_workflow(tmp_path)
    (work / "wrong.yaml").write_text("impedance: {cutoff_hz: 12.0}\n")
    run = snakemake(work, "-n", "--configfile", "wrong.yaml")
    said = run.stdout + run.stderr  # Snakemake prints a WorkflowError on standard output
    assert run.returncode != 0
    assert "wrong.yaml: key 'impedance.cutoff_hz'" in said
    assert "a key 'cutoff_hz' belongs in 'markers.filter.cutoff_hz' or 'dynamics.cutoff_hz': move it there" in said
    assert not (work / "results").exists()
