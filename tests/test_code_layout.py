"""The layout the docs promise (``docs/code_layout.md``): one name per stage, short file steps, no step importing
another."""

from __future__ import annotations

import ast
import importlib
import inspect
import re
from pathlib import Path

import pytest

from loper_analysis.stages import STAGES

ROOT = Path(__file__).resolve().parents[1]
RULES = ROOT / "workflow" / "rules"
STAGES_DIR = ROOT / "src" / "loper_analysis" / "stages"
#: Every stage's file step.
STEP_FILES = sorted(STAGES_DIR.glob("*/step.py"))
#: Rule files without a stage: config checks and targets, settings and input functions.
SHARED_RULE_FILES = {"common", "inputs"}
#: Results folders a stage writes besides its own (``docs/code_layout.md``).
OTHER_FOLDERS: dict[str, set[str]] = {}
#: Most parameters a file step takes (a settings object and a bundle of files instead of long lists).
MAX_STEP_PARAMETERS = 8

STAGE_NAMES = [stage.name for stage in STAGES]


def test_the_stages_are_the_rule_files_and_the_slices():
    """One list of stages: every rule file but the shared ones is a stage's, and every slice is listed."""
    assert sorted(STAGE_NAMES) == sorted(p.stem for p in RULES.glob("*.smk") if p.stem not in SHARED_RULE_FILES)
    assert sorted(STAGE_NAMES) == sorted(p.parent.name for p in STEP_FILES)
    assert all((STAGES_DIR / name / "files.py").is_file() for name in STAGE_NAMES)


@pytest.mark.parametrize("stage", STAGE_NAMES)
def test_each_rule_file_has_its_file_step_and_writes_to_its_folder(stage):
    assert (STAGES_DIR / stage / "step.py").is_file()
    outputs = "\n".join(_output_blocks((RULES / f"{stage}.smk").read_text()))
    folders = set(re.findall(r"PATHS\.([a-z_]+)\.", outputs)) - {"raw"}
    if stage == "synthetic":
        assert folders == set() and "PATHS.raw." in outputs  # the synthetic lab writes the raw files
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
        f"{p.parent.name}.{f.name}: {_n_parameters(f)}"
        for p in STEP_FILES
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
    found = []
    for p in STEP_FILES:
        for n in ast.walk(ast.parse(p.read_text())):
            if isinstance(n, ast.ImportFrom) and n.module:
                names = [n.module] + [f"{n.module}.{a.name}" for a in n.names]
                found += [
                    f"{p.parent.name} -> {m}"
                    for m in names
                    if m.split(".")[:2] == ["loper_analysis", "stages"]
                    and len(m.split(".")) > 2
                    and m.split(".")[2] in STAGE_NAMES
                    and m.split(".")[2] != p.parent.name
                ]
    assert found == []


#: Calls that read or write a file (or ask the file system), which only the file layer makes.
FILE_CALLS = re.compile(
    r"\b(open|read_text|write_text|read_bytes|write_bytes|to_csv|read_csv|is_file|exists|read_c3d|"
    r"read_\w+|write_\w+)\("
)
#: The file layer: formats, the file steps, the command line, the config's readers and the study's files (layout).
FILE_LAYER = (
    "io/",
    "stages/",
    "cli.py",
    "cli_parser.py",
    "cli_checks.py",
    "cli_options.py",
    "config_file.py",
    "schema.py",
    "layout.py",
    "study_checks.py",
)


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
            steps = set(re.findall(r"from loper_analysis\.stages\.(\w+) import step\b", text))
            if steps != {smk.stem}:
                wrong.append(f"{smk.name}: {script}.py calls {sorted(steps)}")
    assert wrong == []


#: A string that is a path under the results or the raw folder (prose naming a file has spaces).
PATH_LITERAL = re.compile(r"^(results|data/raw)/[^\s`]*$")


def _path_literals(text: str) -> list[str]:
    """String constants of Python source that are results or raw paths, docstrings aside."""
    tree = ast.parse(text)
    docs = {
        id(n.body[0].value)
        for n in ast.walk(tree)
        if isinstance(n, (ast.Module, ast.FunctionDef, ast.ClassDef))
        and n.body
        and isinstance(n.body[0], ast.Expr)
        and isinstance(n.body[0].value, ast.Constant)
    }
    return [
        n.value
        for n in ast.walk(tree)
        if isinstance(n, ast.Constant)
        and isinstance(n.value, str)
        and id(n) not in docs
        and PATH_LITERAL.match(n.value)
    ]


def test_only_the_layout_module_spells_a_results_or_raw_path():
    """Rules, scripts, the library, the command line and the benchmarks ask ``loper_analysis.layout``."""
    found = []
    for smk in [ROOT / "Snakefile", *RULES.glob("*.smk")]:
        found += [f"{smk.name}: {m}" for m in re.findall(r"f?\"(?:results|data/raw)/[^\"]*\"", smk.read_text())]
    python = [
        *(ROOT / "src").rglob("*.py"),
        *(ROOT / "workflow" / "scripts").glob("*.py"),
        *(ROOT / "benchmarks").glob("*.py"),
    ]
    for path in python:
        if path.name != "layout.py":
            found += [f"{path.relative_to(ROOT)}: {m}" for m in _path_literals(path.read_text())]
    assert found == []


def test_the_path_check_sees_a_spelled_path():
    assert _path_literals('x = "results/ik/S01/a.tsv"\ny = f"data/raw/{s}/t.c3d"\nz = "see results/x.tsv"') == [
        "results/ik/S01/a.tsv",
        "data/raw/",  # the f-string's first part
    ]


#: Most lines of the workflow's shared rule files (config checks, targets, settings, input functions).
MAX_SHARED_RULE_LINES = 250


def test_the_shared_rule_files_are_short():
    n = sum(len((RULES / f"{name}.smk").read_text().splitlines()) for name in SHARED_RULE_FILES)
    assert n <= MAX_SHARED_RULE_LINES


#: Most lines of code of a function (docstring, comments and blank lines aside).
MAX_FUNCTION_LINES = 80


def _code_lines(f: ast.FunctionDef, lines: list[str]) -> int:
    body = f.body
    doc = (
        range(body[0].lineno, body[0].end_lineno + 1)
        if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
        else range(0)
    )
    return sum(
        1
        for i in range(f.lineno, f.end_lineno + 1)
        if i not in doc and lines[i - 1].strip() and not lines[i - 1].strip().startswith("#")
    )


def test_no_library_function_is_longer_than_80_lines_of_code():
    src = ROOT / "src" / "loper_analysis"
    long = {}
    for path in src.rglob("*.py"):
        text = path.read_text()
        for f in _functions(path):
            if (n := _code_lines(f, text.splitlines())) > MAX_FUNCTION_LINES:
                long[f"{path.relative_to(src).as_posix()}:{f.name}"] = n
    assert long == {}


def test_the_function_length_counts_code_only():
    source = 'def f():\n    """Doc.\n\n    More."""\n    # comment\n\n    x = 1\n    return x\n'
    (f,) = _functions_of(source)
    assert _code_lines(f, source.splitlines()) == 3


def test_each_stages_library_column_names_modules_that_exist():
    """The library column of ``docs/code_layout.md``'s stage table: every module and package it names exists (a
    bare ``name.py`` lies in the package named before it on the row)."""
    src = ROOT / "src" / "loper_analysis"
    missing, rows = [], 0
    for line in (ROOT / "docs" / "code_layout.md").read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 6 or not cells[1].endswith(".smk`"):
            continue
        rows += 1
        package = ""
        for name in re.findall(r"`([a-z_/]+(?:\.py|/))`", cells[3]):
            found = next((p for p in (src / name, src / package / name) if p.exists()), None)
            if found is None:
                missing.append(f"{cells[0]}: {name}")
            elif "/" in name and (src / name).exists():
                package = name.rstrip("/") if name.endswith("/") else name.rsplit("/", 1)[0]
    assert rows == len(STAGES) and missing == []


#: Library functions that keep more than eight positional parameters, and why: compiled kernels (numba takes no
#: keyword-only parameters) and a response simulator whose ten arguments are all data.
MANY_POSITIONAL = {"swing_leg/kernels.py:simulate_deviation_batch", "synthetic/response.py:swing_response"}


def test_library_functions_take_their_options_by_name():
    """A library function of more than eight parameters takes its data positionally and its options keyword-only
    (``*``); private helpers called only in their module aside."""
    src = ROOT / "src" / "loper_analysis"
    found = []
    for path in src.rglob("*.py"):
        rel = path.relative_to(src).as_posix()
        if rel.startswith("stages/"):
            continue
        for f in _functions(path):
            a = f.args
            positional = [p.arg for p in (*a.posonlyargs, *a.args) if p.arg not in ("self", "cls")]
            name = f"{rel}:{f.name}"
            if len(positional) > MAX_STEP_PARAMETERS and name not in MANY_POSITIONAL and not f.name.startswith("_"):
                found.append(f"{name}: {len(positional)}")
    assert found == []


@pytest.mark.parametrize("stage", STAGES, ids=lambda s: s.name)
def test_each_slice_is_whole_a_reader_and_a_rule_for_every_file(stage):
    """A slice whose settings have no reader, or a result file no rule of its rule file writes, is incomplete."""
    reader = importlib.import_module(f"loper_analysis.stages.{stage.name}.settings")
    assert isinstance(reader.NEEDS, tuple) and callable(reader.read_settings)
    params = inspect.signature(reader.read_settings).parameters
    assert list(params) == ["config", *reader.NEEDS], stage.name  # each stage it needs passed in by name
    outputs = "\n".join(_output_blocks((RULES / f"{stage.name}.smk").read_text()))
    unwritten = [name for name in stage.files if f"PATHS.{stage.name}.{name}" not in outputs]
    assert unwritten == [], stage.name


#: Private names one module takes from another, each by the importing module (``docs/code_layout.md``, Layers).
PRIVATE_IMPORTS: set[str] = set()


def private_imports(source: str) -> list[str]:
    """The package's ``_name`` names a source imports (``from loper_analysis.x import _name``)."""
    return [
        f"{n.module}.{a.name}"
        for n in ast.walk(ast.parse(source))
        if isinstance(n, ast.ImportFrom) and (n.module or "").startswith("loper_analysis")
        for a in n.names
        if a.name.startswith("_") and not a.name.startswith("__")
    ]


def test_no_module_imports_another_modules_private_names_but_the_one_named():
    src = ROOT / "src" / "loper_analysis"
    found = {
        f"{p.relative_to(src).as_posix()}: {name}" for p in src.rglob("*.py") for name in private_imports(p.read_text())
    }
    assert found == PRIVATE_IMPORTS


def test_the_private_import_check_sees_one_inside_a_function():
    source = "from loper_analysis.io import readers\ndef f():\n    from loper_analysis.gait.grf import _rest, up\n"
    assert private_imports(source) == ["loper_analysis.gait.grf._rest"]


def test_no_module_of_the_package_holds_the_snakemake_object():
    """Only the rules' scripts see ``snakemake``; the package takes what they pass on."""
    src = ROOT / "src" / "loper_analysis"
    found = [
        f"{p.relative_to(src).as_posix()}:{n.lineno}"
        for p in src.rglob("*.py")
        for n in ast.walk(ast.parse(p.read_text()))
        if (isinstance(n, ast.Name) and n.id == "snakemake") or (isinstance(n, ast.arg) and n.arg == "snakemake")
    ]
    assert found == []


@pytest.mark.parametrize("stage", STAGES, ids=lambda s: s.name)
def test_the_result_files_are_the_slices_files(stage):
    """``stages.RESULT_FILES`` (hence ``PATHS``) is built from each slice's ``files.FILES``."""
    from loper_analysis.stages import RESULT_FILES

    files = importlib.import_module(f"loper_analysis.stages.{stage.name}.files").FILES
    assert dict(stage.files) == dict(files)
    assert RESULT_FILES.get(stage.name, {}) == dict(files)


def test_the_snakefile_includes_each_stages_rule_file_through_stages():
    """The Snakefile includes the shared rule files, then every stage's by ``STAGES``; ``rule all`` asks every
    stage's targets."""
    text = (ROOT / "Snakefile").read_text()
    includes = re.findall(r"^\s*include:\s*(.+?)\s*$", text, re.M)
    assert includes == ['"workflow/rules/common.smk"', '"workflow/rules/inputs.smk"', "_stage.rule_file"]
    assert re.search(r"^for _stage in STAGES:\n\n?\s+include: _stage\.rule_file$", text, re.M)
    assert re.search(r"^rule all:\n(?:\s+.*\n)*?\s+input:\n\s+all_targets\(STUDY\),", text, re.M)


def _rules(text: str) -> dict[str, str]:
    """Rule name -> its text, of one rule file."""
    parts = re.split(r"^\s*rule (\w+):\s*$", text, flags=re.M)
    return dict(zip(parts[1::2], parts[2::2]))


def test_every_rule_names_its_outputs_log_and_benchmark():
    missing = []
    for smk in sorted(RULES.glob("*.smk")):
        for name, body in _rules(smk.read_text()).items():
            sections = set(re.findall(r"^\s+(\w+):\s*$", body, re.M))
            missing += [f"{name}: {s}" for s in ("output", "log", "benchmark", "script") if s not in sections]
    assert missing == []


def test_each_rules_script_calls_one_function_of_its_step():
    """A rule's script calls one function of its stage's ``step.py`` (a bundle of files aside: a class)."""
    wrong = []
    for script in sorted((ROOT / "workflow" / "scripts").glob("*.py")):
        tree = ast.parse(script.read_text())
        alias = next(
            a.asname or a.name
            for n in ast.walk(tree)
            if isinstance(n, ast.ImportFrom) and n.module and n.module.startswith("loper_analysis.stages.")
            for a in n.names
            if a.name == "step"
        )
        called = {
            n.func.attr
            for n in ast.walk(tree)
            if isinstance(n, ast.Call)
            and isinstance(n.func, ast.Attribute)
            and isinstance(n.func.value, ast.Name)
            and n.func.value.id == alias
            and not n.func.attr[0].isupper()
        }
        if len(called) != 1:
            wrong.append(f"{script.name}: {sorted(called)}")
    assert wrong == []
