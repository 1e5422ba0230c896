"""The layout the docs promise (``docs/code_layout.md``): one name per stage, short file steps, no step importing
another."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RULES = ROOT / "workflow" / "rules"
STEPS = ROOT / "src" / "loper_analysis" / "steps"
#: Rule files without a stage: config checks and targets, settings and input functions.
SHARED_RULE_FILES = {"common", "inputs"}
#: Results folders a stage writes besides its own (``docs/code_layout.md``).
OTHER_FOLDERS: dict[str, set[str]] = {}
#: Most parameters a file step takes (a settings object and a bundle of files instead of long lists).
MAX_STEP_PARAMETERS = 8

STAGES = sorted(p.stem for p in RULES.glob("*.smk") if p.stem not in SHARED_RULE_FILES)


@pytest.mark.parametrize("stage", STAGES)
def test_each_rule_file_has_its_file_step_and_writes_to_its_folder(stage):
    assert (STEPS / f"{stage}.py").is_file()
    outputs = "\n".join(_output_blocks((RULES / f"{stage}.smk").read_text()))
    folders = set(re.findall(r'"results/([a-z_]+)/', outputs))
    if stage == "synthetic":
        assert folders == set() and "data/raw/" in outputs  # the synthetic lab writes the raw files
    else:
        assert folders and folders <= {stage} | OTHER_FOLDERS.get(stage, set()), folders


def _output_blocks(text: str) -> list[str]:
    """The lines of every ``output:`` section of a rule file (those indented deeper than the keyword)."""
    blocks, lines = [], text.splitlines()
    for i, line in enumerate(lines):
        if line.strip() == "output:":
            indent, block = len(line) - len(line.lstrip()), []
            for nxt in lines[i + 1 :]:
                if nxt.strip() and len(nxt) - len(nxt.lstrip()) <= indent:
                    break
                block.append(nxt)
            blocks.append("\n".join(block))
    return blocks


def _functions(path: Path):
    return [n for n in ast.walk(ast.parse(path.read_text())) if isinstance(n, ast.FunctionDef)]


def _n_parameters(f: ast.FunctionDef) -> int:
    a = f.args
    return len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None) + (a.kwarg is not None)


def test_no_file_step_takes_more_than_eight_parameters():
    long = [
        f"{p.stem}.{f.name}: {_n_parameters(f)}"
        for p in sorted(STEPS.glob("*.py"))
        for f in _functions(p)
        if _n_parameters(f) > MAX_STEP_PARAMETERS
    ]
    assert long == []


def test_the_parameter_count_sees_every_kind_of_parameter():
    (f,) = _functions_of("def f(a, /, b, *c, d, **e): pass")
    assert _n_parameters(f) == 5


def _functions_of(source: str):
    return [n for n in ast.walk(ast.parse(source)) if isinstance(n, ast.FunctionDef)]


def test_no_file_step_imports_another():
    steps = {p.stem for p in STEPS.glob("*.py")} - {"__init__", "logs"}
    found = []
    for p in sorted(STEPS.glob("*.py")):
        for n in ast.walk(ast.parse(p.read_text())):
            if isinstance(n, ast.ImportFrom) and n.module:
                names = [n.module] + [f"{n.module}.{a.name}" for a in n.names]
                found += [
                    f"{p.stem} -> {m}"
                    for m in names
                    if m.split(".")[:2] == ["loper_analysis", "steps"]
                    and len(m.split(".")) > 2
                    and m.split(".")[2] in steps
                    and m.split(".")[2] != p.stem
                ]
    assert found == []


#: Calls that read or write a file (or ask the file system), which only the file layer makes.
FILE_CALLS = re.compile(
    r"\b(open|read_text|write_text|read_bytes|write_bytes|to_csv|read_csv|is_file|exists|read_c3d|"
    r"read_\w+|write_\w+)\("
)
#: The file layer: formats, the file steps, the command line and the config's readers.
FILE_LAYER = ("io/", "steps/", "cli.py", "cli_parser.py", "cli_checks.py", "config_file.py", "schema.py")


def test_no_library_module_outside_the_file_layer_opens_a_file():
    """Below the file layer functions take arrays, tables, recordings and models, never paths."""
    src = ROOT / "src" / "loper_analysis"
    found = []
    for path in sorted(src.rglob("*.py")):
        rel = path.relative_to(src).as_posix()
        if rel.startswith(FILE_LAYER):
            continue
        tree = ast.parse(path.read_text())
        code = "\n".join(
            ast.get_source_segment(path.read_text(), node) or ""
            for node in ast.walk(tree)
            if isinstance(node, ast.Call)
        )
        found += [f"{rel}: {m}" for m in sorted(set(FILE_CALLS.findall(code)))]
    assert found == []


def test_the_file_layer_check_sees_a_file_read():
    assert FILE_CALLS.findall("x = read_force_platforms(path, up); Path(p).read_text()") == [
        "read_force_platforms",
        "read_text",
    ]


#: Most lines of a library module: a longer one does several jobs.
MAX_MODULE_LINES = 600


def test_no_library_module_is_longer_than_600_lines():
    src = ROOT / "src" / "loper_analysis"
    long = {p.relative_to(src).as_posix(): n for p in src.rglob("*.py") if (n := len(p.read_text().splitlines())) > 600}
    assert long == {}


def test_each_rule_calls_its_own_stages_step():
    """A rule's script calls the file step of the stage whose rule file holds the rule, never another stage's."""
    wrong = []
    for smk in RULES.glob("*.smk"):
        for script in re.findall(r'"\.\./scripts/(\w+)\.py"', smk.read_text()):
            text = (ROOT / "workflow" / "scripts" / f"{script}.py").read_text()
            steps = set(re.findall(r"from loper_analysis\.steps import (\w+)", text)) - {"rule_log"}
            if steps != {smk.stem}:
                wrong.append(f"{smk.name}: {script}.py calls {sorted(steps)}")
    assert wrong == []
