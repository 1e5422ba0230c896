"""Who reads the config, from the code itself: ``config[...]`` and ``config.get(...)`` appear only in a stage's
settings reader (``stages/<stage>/settings.py``), each reading its own section, and in the modules that check or
translate the config before any reader; the rules, the scripts and every other module take built settings.

(That each key is read by exactly one reader is tested on the shipped config in ``test_settings.py``.)
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from loper_analysis.stages import STAGES
from tests.study_files import CONFIG

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "src" / "loper_analysis"
#: Modules that read the raw config to check, translate or merge it before any reader builds settings, with why.
CHECKERS = {
    "schema.py": "checks the config's values, files and paths against the schema, naming the file that set each",
    "config_sections.py": "moves the keys of the former layout to their places before anything reads them",
    "config_file.py": "reads the config files and merges them in Snakemake's order",
}
#: The study's reader takes the trial design and the keys at the top of the config.
OWN_KEYS = {"study": {"study", "seed", "subjects", "raw_dir"}}
READERS = ["study", *(stage.name for stage in STAGES)]


def _is_config(node: ast.AST) -> bool:
    return (isinstance(node, ast.Name) and node.id in {"config", "cfg"}) or (
        isinstance(node, ast.Attribute) and node.attr == "config"
    )


def config_reads(source: str) -> list[tuple[int, str | None]]:
    """(line, key) of every ``config[key]`` and ``config.get(key, ...)`` of a module (key None: not a literal)."""
    reads = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Subscript) and _is_config(node.value):
            key = node.slice.value if isinstance(node.slice, ast.Constant) else None
            reads.append((node.lineno, key))
        elif (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute)
            and node.func.attr == "get"
            and _is_config(node.func.value)
        ):
            first = node.args[0] if node.args else None
            reads.append((node.lineno, first.value if isinstance(first, ast.Constant) else None))
    return sorted(reads)


def test_the_finder_sees_subscripts_gets_and_attributes():
    source = 'a = config["ik"]\nb = self.config["model"]["x"]\nc = cfg.get("seed")\nd = other["ik"]\n'
    assert config_reads(source) == [(1, "ik"), (2, "model"), (3, "seed")]


def test_only_the_stages_readers_and_the_config_checkers_read_the_config():
    readers = {PACKAGE / "stages" / name / "settings.py" for name in READERS}
    checkers = {PACKAGE / name for name in CHECKERS}
    assert all(path.is_file() for path in readers | checkers)
    elsewhere = {
        f"{path.relative_to(ROOT)}:{line}": key
        for path in sorted(PACKAGE.rglob("*.py"))
        if path not in readers | checkers
        for line, key in config_reads(path.read_text())
    }
    assert elsewhere == {}


@pytest.mark.parametrize("name", READERS)
def test_each_reader_reads_its_own_section(name):
    path = PACKAGE / "stages" / name / "settings.py"
    keys = {key for _, key in config_reads(path.read_text())}
    assert keys <= OWN_KEYS.get(name, {name})
    assert keys or name not in CONFIG  # a stage with a section reads it (one without takes others' settings)


def test_the_workflow_reads_no_config_key():
    pattern = re.compile(r"\bconfig\s*\[|\bconfig\.get\s*\(")
    files = [ROOT / "Snakefile", *sorted((ROOT / "workflow" / "rules").glob("*.smk"))]
    files += sorted((ROOT / "workflow" / "scripts").glob("*.py"))
    reads = [
        f"{path.relative_to(ROOT)}:{number}: {line.strip()}"
        for path in files
        for number, line in enumerate(path.read_text().splitlines(), 1)
        if pattern.search(line) and not line.lstrip().startswith("#")
    ]
    assert reads == []
