"""``docs/code_layout.md`` against the code: its stage table lists the stages of ``STAGES`` as they are, its
settings table names what each stage's reader builds and needs, and its Layers diagram is the order the
package's imports keep (none running up, no loop, at most 12 floors, the number the doc states)."""

from __future__ import annotations

import ast
import dataclasses
import importlib
import re
from pathlib import Path

import pytest

from loper_analysis.stages import STAGES, study_paths
from loper_analysis.stages.settings import stage_settings
from tests.study_files import CONFIG

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "code_layout.md"
SRC = ROOT / "src" / "loper_analysis"
STAGE_NAMES = [stage.name for stage in STAGES]
#: Most floors of the package's import graph (``docs/code_layout.md``, Layers).
MAX_FLOORS = 12


def _table(text: str, header: str) -> list[list[str]]:
    """The rows (lists of cells) of the Markdown table whose header row starts with ``header``."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(header))
    rows = []
    for line in lines[start + 2 :]:  # past the header and its rule
        if not line.startswith("|"):
            break
        rows.append([c.strip() for c in line.strip().strip("|").split("|")])
    return rows


def _first_code(cell: str) -> str:
    """The first name in backticks of a cell."""
    return re.search(r"`([^`]+)`", cell).group(1)


def test_the_table_reader_reads_a_table_and_its_cells():
    text = "intro\n\n| a | b |\n| --- | --- |\n| `x` (y) | `z`, w |\n| 2 | 3 |\n\nafter | no\n"
    rows = _table(text, "| a | b |")
    assert rows == [["`x` (y)", "`z`, w"], ["2", "3"]]
    assert _first_code(rows[0][0]) == "x"


# --- the stage table ---------------------------------------------------------------------------------------------


def _stage_rows(text: str) -> list[list[str]]:
    return _table(text, "| stage | rule file | file step | library | results | config |")


def stage_table_errors(text: str) -> list[str]:
    """What the stage table says that the stages are not: its stages and their order, each one's rule file, file
    step and results folder."""
    rows = _stage_rows(text)
    errors = []
    if [_first_code(r[0]) for r in rows] != STAGE_NAMES:
        errors.append(f"stages {[_first_code(r[0]) for r in rows]} != {STAGE_NAMES}")
    paths = study_paths()
    for row, stage in zip(rows, STAGES):
        name, rule_file, step, results = _first_code(row[0]), row[1], row[2], row[4]
        if name != stage.name:
            continue
        if rule_file != f"`{Path(stage.rule_file).name}`" or not (ROOT / stage.rule_file).is_file():
            errors.append(f"{name}: rule file {rule_file}")
        if step != f"`stages/{name}/step.py`" or not (SRC / "stages" / name / "step.py").is_file():
            errors.append(f"{name}: file step {step}")
        folder = f"`{getattr(paths, name).root}/`" if stage.files else "`{raw_dir}/{subject}/`"
        if results != folder:
            errors.append(f"{name}: results {results}, not {folder}")
    return errors


def test_the_stage_table_lists_the_stages_in_their_order_with_their_files():
    assert stage_table_errors(DOC.read_text()) == []


def test_the_stage_table_check_sees_a_wrong_row():
    text = DOC.read_text()
    grf, events = (next(line for line in text.splitlines() if f"| `{n}.smk` |" in line) for n in ("grf", "events"))
    wrong = stage_table_errors(text.replace("`results/grf/`", "`results/ground/`"))
    assert "grf: results `results/ground/`, not `results/grf/`" in wrong
    swapped = text.replace(grf, "@@").replace(events, grf).replace("@@", events)
    assert any(e.startswith("stages ") for e in stage_table_errors(swapped))


# --- the settings table ------------------------------------------------------------------------------------------


def _settings_rows(text: str) -> list[list[str]]:
    return _table(text, "| stage | settings | needs |")


def settings_table_errors(text: str) -> list[str]:
    """What the settings table says that the readers do not build or need, on the shipped config."""
    rows = _settings_rows(text)
    readers = ["study", *STAGE_NAMES]
    errors = []
    if [_first_code(r[0]) for r in rows] != readers:
        errors.append(f"readers {[_first_code(r[0]) for r in rows]} != {readers}")
    for row in rows:
        name = _first_code(row[0])
        if name not in readers:
            continue
        settings = stage_settings(CONFIG, name)
        kind = type(settings)
        built = f"{kind.__module__.removeprefix('loper_analysis.')}.{kind.__qualname__}"
        if _first_code(row[1]) != built:
            errors.append(f"{name}: settings {_first_code(row[1])}, built {built}")
        needs = importlib.import_module(f"loper_analysis.stages.{name}.settings").NEEDS
        if row[2] != (", ".join(needs) or "—"):
            errors.append(f"{name}: needs {row[2]}, NEEDS {needs}")
    return errors


def test_the_settings_table_names_each_readers_type_and_needs():
    assert settings_table_errors(DOC.read_text()) == []


@pytest.mark.parametrize("name", ["study", *STAGE_NAMES])
def test_each_stages_settings_are_one_frozen_dataclass(name):
    settings = stage_settings(CONFIG, name)
    assert dataclasses.is_dataclass(settings) and type(settings).__dataclass_params__.frozen, name


def test_the_settings_table_check_sees_a_wrong_type_or_need():
    text = DOC.read_text()
    wrong_type = text.replace("| `strides` | `gait.stride_settings.StrideSettings` |", "| `strides` | `gait.X` |")
    assert "strides: settings gait.X, built gait.stride_settings.StrideSettings" in settings_table_errors(wrong_type)
    wrong_needs = text.replace(
        "`transparency.TransparencySettings` | strides |", "`transparency.TransparencySettings` | — |"
    )
    assert "transparency: needs —, NEEDS ('strides',)" in settings_table_errors(wrong_needs)


# --- the import graph --------------------------------------------------------------------------------------------


def _module_name(path: Path) -> str:
    parts = ("loper_analysis", *path.relative_to(SRC).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_names(source: str, module: str, is_package: bool = False) -> set[str]:
    """Every ``loper_analysis`` name a module's source imports, wherever the import stands (inside functions
    too): ``import a.b`` gives ``a.b``, ``from a import b`` gives ``a.b``; relative imports resolved."""
    names = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            names |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                package = module.split(".") if is_package else module.split(".")[:-1]
                package = package[: len(package) - (node.level - 1)]
                base = ".".join([*package, *([node.module] if node.module else [])])
            names |= {f"{base}.{a.name}" for a in node.names}
    return {n for n in names if n.split(".")[0] == "loper_analysis"}


def _room(name: str) -> str | None:
    """The room of a dotted name of the package: its top-level folder (``gait/``) or module (``errors.py``)."""
    parts = name.split(".")
    if len(parts) < 2:
        return None
    return f"{parts[1]}/" if (SRC / parts[1]).is_dir() else f"{parts[1]}.py"


def _modules() -> dict[str, Path]:
    """Every module of the package but its ``__init__.py``, by dotted name."""
    return {_module_name(p): p for p in sorted(SRC.rglob("*.py")) if p != SRC / "__init__.py"}


def module_imports() -> dict[str, set[str]]:
    """Module -> the package's modules it imports (``from a import b``: ``a.b`` where that is a module, else
    ``a``), itself left out."""
    modules = _modules()
    graph = {}
    for name, path in modules.items():
        targets = set()
        for imported in imported_names(path.read_text(), name, path.name == "__init__.py"):
            parent = imported.rsplit(".", 1)[0]
            targets.add(imported if imported in modules else parent if parent in modules else imported)
        graph[name] = {t for t in targets if t in modules and t != name}
    return graph


def room_imports() -> dict[str, set[str]]:
    """Room -> the other rooms it imports: each folder of the package counted as one module."""
    graph: dict[str, set[str]] = {}
    for name, targets in module_imports().items():
        room = _room(name)
        graph.setdefault(room, set())
        graph[room] |= {_room(t) for t in targets} - {room}
    return graph


def loops(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import loops of a graph: its strongly connected parts of more than one node, and self-imports."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            part = []
            while not part or part[-1] != node:
                part.append(stack.pop())
            if len(part) > 1 or node in graph.get(node, ()):
                found.append(sorted(part))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return found


def floors(graph: dict[str, set[str]]) -> dict[str, int]:
    """Each node's floor: 1 for a node importing none, else one above the highest it imports (no loops)."""
    out: dict[str, int] = {}
    climbing: set[str] = set()

    def floor(node: str) -> int:
        if node in climbing:
            raise AssertionError(f"an import loop through {node}: no floors")
        if node not in out:
            climbing.add(node)
            out[node] = 1 + max((floor(n) for n in graph.get(node, ())), default=0)
            climbing.discard(node)
        return out[node]

    for node in graph:
        floor(node)
    return out


def test_the_import_reader_sees_every_import_and_counts_folders_as_one():
    source = (
        "import numpy\nfrom loper_analysis import cli_options\nfrom loper_analysis.gait.grf import up\n"
        "def f():\n    import loper_analysis.io.atomic\n    from .sibling import x\n"
    )
    names = imported_names(source, "loper_analysis.motion.ik")
    assert names == {
        "loper_analysis.cli_options",
        "loper_analysis.gait.grf.up",
        "loper_analysis.io.atomic",
        "loper_analysis.motion.sibling.x",
    }
    assert {_room(n) for n in names} == {"cli_options.py", "gait/", "io/", "motion/"}


def test_the_loop_and_floor_counts_on_a_small_graph():
    graph = {"a": {"b", "c"}, "b": {"c"}, "c": set(), "d": {"e"}, "e": {"d"}}
    assert loops(graph) == [["d", "e"]]
    with pytest.raises(AssertionError, match="an import loop"):
        floors(graph)
    del graph["d"], graph["e"]
    assert floors(graph) == {"a": 3, "b": 2, "c": 1}


def test_no_import_loop_among_the_packages_modules_or_rooms():
    assert loops(room_imports()) == []
    assert loops(module_imports()) == []


def layers(text: str) -> list[list[str]]:
    """The Layers diagram of ``docs/code_layout.md``, top to bottom: each line's modules and folders (left of its
    description), those outside the package (``workflow/``) left out."""
    block = text.split("## Layers", 1)[1].split("```", 2)[1]
    out = []
    for line in block.strip("\n").splitlines():
        names = re.split(r"\s{2,}", line.strip(), maxsplit=1)[0]
        out.append([n for n in re.findall(r"[\w/]+?(?:\.py|/)(?=\s|,|$)", names) if not n.startswith("workflow/")])
    return out


def upward_imports(text: str) -> list[str]:
    """The imports that run up the doc's Layers diagram, and the rooms it places not once."""
    rank = {}
    diagram = layers(text)
    placed = [name for layer in diagram for name in layer]
    graph = room_imports()
    errors = [f"{n} placed {placed.count(n)} times" for n in sorted(set(graph) | set(placed)) if placed.count(n) != 1]
    for height, layer in enumerate(reversed(diagram)):
        rank |= dict.fromkeys(layer, height)
    errors += [
        f"{room} -> {target}"
        for room, targets in sorted(graph.items())
        for target in sorted(targets)
        if room in rank and target in rank and rank[target] > rank[room]
    ]
    return errors


def test_the_layers_diagram_places_every_module_once_and_no_import_runs_up():
    assert upward_imports(DOC.read_text()) == []


def test_the_layers_check_sees_a_module_placed_too_low_or_missing():
    text = DOC.read_text()
    lowered = text.replace("\nlayout.py ", "\n          ").replace(
        "checks.py errors.py", "checks.py layout.py errors.py"
    )
    assert {"layout.py -> io/", "layout.py -> synthetic/"} <= set(upward_imports(lowered))
    assert "swing_leg/ placed 0 times" in upward_imports(text.replace("swing_leg/   ", "             "))


def stated_floors(text: str) -> tuple[int, int]:
    """The most floors the doc allows and the floors it says the package stands on today."""
    most = re.search(r"at most\s+(\d+)\s+floors", text)
    today = re.search(r"stands on\s+(\d+)\s+today", text)
    return int(most.group(1)), int(today.group(1))


def test_the_package_stands_on_at_most_12_floors_as_the_doc_says():
    measured = max(floors(room_imports()).values())
    assert measured <= MAX_FLOORS
    assert stated_floors(DOC.read_text()) == (MAX_FLOORS, measured)


def test_the_floor_check_reads_the_docs_numbers():
    text = DOC.read_text()
    assert stated_floors(re.sub(r"stands on\s+\d+\s+today", "stands on 11 today", text))[1] == 11
