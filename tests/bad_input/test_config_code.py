"""No config file runs code: a YTE template (``__use_yte__``, whose expressions Snakemake evaluates as Python), a
Python tag (``!!python/object/apply:...``) and an alias bomb are refused before anything is built, naming the file
and the construct; ``subjects`` and ``raw_dir`` outside the project folder are refused unread unless
``allow_outside_project: true`` says so. The canary is a file that a rendered template would write."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
import yaml

from loper_analysis.cli import main
from loper_analysis.config_file import load_config, read_config_file
from loper_analysis.errors import LoperInputError
from loper_analysis.schema import MAX_VALUES, check_config, check_yaml_file
from tests.workflow_copy import ROOT, copy_workflow, snakemake

SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"

#: The classic billion laughs (about 600 bytes): nine levels of nine aliases, 10**9 strings expanded.
BOMB = "".join(
    [
        'lol: &l0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]\n',
        *(f"lol{k}: &l{k} [{', '.join([f'*l{k - 1}'] * 9)}]\n" for k in range(1, 10)),
    ]
)


def yte_template(canary: Path) -> str:
    """A YTE template whose rendering writes ``canary``."""
    return (
        "__use_yte__: true\n"
        "__definitions__:\n"
        "  - import pathlib\n"
        f"  - pathlib.Path({str(canary)!r}).write_text('the template ran')\n"
        "seed: 7\n"
    )


def python_tag(canary: Path) -> str:
    """A config whose unsafe loading would call ``os.system``, writing ``canary``."""
    return f"seed: !!python/object/apply:os.system [touch {canary}]\n"


def said(res) -> str:
    return res.stdout + res.stderr


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("__use_yte__: true\nseed: 1\n", r"c.yaml: line 1, column 1: key '__use_yte__': a YTE template"),
        ("seed: 1\n__use_yte__: yes\n", r"c.yaml: line 2, column 1: key '__use_yte__': a YTE template"),
        ("seed: !!python/object/apply:os.system [ls]\n", r"c.yaml: line 1, column 7: tag '!!python/object/apply:os"),
        ("seed: !!python/name:os.system\n", r"tag '!!python/name:os.system'"),
        ("a:\n  b: !!python/object:pathlib.Path {}\n", r"line 2, column 6: tag '!!python/object:pathlib.Path'"),
        ("seed: !custom 1\n", r"tag '!custom'"),
        ("a: &x [1, *x]\n", r"c.yaml: line 1, column 4: an alias of a value inside itself"),
    ],
)
def test_a_template_a_python_tag_or_a_recursive_alias_is_refused_naming_file_place_and_construct(
    tmp_path, monkeypatch, text, expected
):
    monkeypatch.chdir(tmp_path)
    Path("c.yaml").write_text(text)
    with pytest.raises(LoperInputError, match=expected):
        check_yaml_file("c.yaml")
    with pytest.raises(LoperInputError, match=expected):
        read_config_file("c.yaml")


def test_plain_yaml_with_standard_tags_aliases_and_a_switched_off_template_passes(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text("__use_yte__: false\nbase: &b {x: 1.5}\nother: *b\nname: !!str 12\nwhen: 2024-01-01\n")
    check_yaml_file(path)
    assert read_config_file(path)["other"] == {"x": 1.5}


def test_an_alias_bomb_is_refused_in_under_a_second_by_the_reader_and_by_the_schema_check(tmp_path):
    path = tmp_path / "bomb.yaml"
    path.write_text(BOMB)
    assert len(BOMB) < 700
    start = time.perf_counter()
    with pytest.raises(LoperInputError, match=r"bomb.yaml: line \d+, column \d+: .* more than 100000 values"):
        check_yaml_file(path)
    with pytest.raises(LoperInputError, match=r"alias bomb"):
        load_config([path], schema=SCHEMA)
    assert time.perf_counter() - start < 1.0
    # built by a loader elsewhere (shared lists), the schema check counts it without walking it
    data = yaml.safe_load(BOMB)
    start = time.perf_counter()
    with pytest.raises(LoperInputError, match=rf"mine.yaml: key 'lol\d': expands to more than {MAX_VALUES} values"):
        check_config(data, SCHEMA, "mine.yaml")
    assert time.perf_counter() - start < 1.0


def test_a_python_tag_is_named_by_the_reader_not_taken_for_tab_indentation(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    Path("mine.yaml").write_text(python_tag(tmp_path / "canary"))
    with pytest.raises(LoperInputError) as err:
        load_config(["mine.yaml"], schema=SCHEMA)
    assert "mine.yaml: line 1, column 7: tag '!!python/object/apply:os.system'" in str(err.value)
    assert "tab" not in str(err.value) and not (tmp_path / "canary").exists()


def test_a_template_as_config_yaml_is_refused_before_snakemake_renders_it(tmp_path):
    (tmp_path / "work").mkdir()
    work = copy_workflow(tmp_path / "work")
    canary = tmp_path / "canary"
    config = work / "config" / "config.yaml"
    config.write_text(yte_template(canary) + config.read_text().replace("seed: 2024", "", 1))
    res = snakemake(work, "-n", "-q")
    assert res.returncode != 0, said(res)
    assert "config/config.yaml: line 1, column 1: key '__use_yte__': a YTE template" in said(res), said(res)
    assert not canary.exists()


def test_a_python_tag_or_an_alias_bomb_in_config_yaml_stops_the_run_naming_file_and_construct(tmp_path):
    (tmp_path / "work").mkdir()
    work = copy_workflow(tmp_path / "work")
    canary = tmp_path / "canary"
    config = work / "config" / "config.yaml"
    original = config.read_text()
    config.write_text(original.replace("seed: 2024", python_tag(canary).strip(), 1))
    res = snakemake(work, "-n", "-q")
    assert res.returncode != 0 and "config/config.yaml: line 6, column 7: tag '!!python/object/apply:os.system'" in (
        said(res)
    ), said(res)
    assert "tab indentation" not in said(res) and not canary.exists()
    config.write_text(original + BOMB)
    start = time.perf_counter()
    res = snakemake(work, "-n", "-q")
    assert res.returncode != 0 and "config/config.yaml: line" in said(res) and "alias bomb" in said(res), said(res)
    assert time.perf_counter() - start < 60


def test_a_template_given_with_configfile_stops_the_run_before_any_job(tmp_path):
    (tmp_path / "work").mkdir()
    work = copy_workflow(tmp_path / "work")
    (work / "mine.yaml").write_text(yte_template(tmp_path / "canary"))
    res = snakemake(work, "-n", "-q", "--configfile", "mine.yaml")
    assert res.returncode != 0, said(res)
    assert "mine.yaml: line 1, column 1: key '__use_yte__': a YTE template" in said(res), said(res)
    (work / "bomb.yaml").write_text(BOMB)
    res = snakemake(work, "-n", "-q", "--configfile", "bomb.yaml")
    assert res.returncode != 0 and "bomb.yaml: line" in said(res) and "alias bomb" in said(res), said(res)


@pytest.mark.xfail(
    strict=True,
    reason="Snakemake 9 renders a --configfile template while it parses its command line (ConfigSettings), before "
    "the Snakefile runs; the workflow refuses the run after, and loper-analysis report before",
)
def test_a_template_given_with_configfile_to_snakemake_is_never_rendered(tmp_path):
    (tmp_path / "work").mkdir()
    work = copy_workflow(tmp_path / "work")
    canary = tmp_path / "canary"
    (work / "mine.yaml").write_text(yte_template(canary))
    snakemake(work, "-n", "-q", "--configfile", "mine.yaml")
    assert not canary.exists()


def test_the_report_command_refuses_a_template_before_starting_snakemake(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    canary = tmp_path / "canary"
    Path("mine.yaml").write_text(yte_template(canary))
    assert main(["report", "results/report.html", "-q", "--configfile", "mine.yaml"]) == 2
    err = capsys.readouterr().err
    assert "loper-analysis report: mine.yaml: line 1, column 1: key '__use_yte__': a YTE template" in err, err
    assert not canary.exists() and not Path("results").exists()


def test_subjects_or_raw_dir_outside_the_project_folder_are_refused_unread_unless_allowed(tmp_path):
    (tmp_path / "work").mkdir()
    work = copy_workflow(tmp_path / "work")
    res = snakemake(work, "-n", "-q", "--config", "subjects=/etc/passwd")
    assert res.returncode == 1, said(res)
    assert "--config: key 'subjects': '/etc/passwd' is outside the project folder" in said(res), said(res)
    assert "allow_outside_project: true" in said(res) and "root:" not in said(res)
    (work / "mine.yaml").write_text("raw_dir: ../lab/raw\n")
    res = snakemake(work, "-n", "-q", "--configfile", "mine.yaml")
    assert res.returncode == 1 and "mine.yaml: key 'raw_dir': '../lab/raw' is outside the project folder" in said(res)
    (work / "mine.yaml").write_text("raw_dir: ../lab/raw\nallow_outside_project: true\n")
    res = snakemake(work, "-n", "-q", "--configfile", "mine.yaml")
    assert res.returncode == 0, said(res)
