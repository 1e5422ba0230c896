"""Check configuration data against the workflow's JSON schemas with one short message.

A workflow's configuration is built in layers: the default file, then each
``--configfile`` in turn, then the ``--config`` values on the command line
(each layer overriding the ones before). :func:`check_config` names the layer
that set an offending key (:func:`config_origin`), so the message points at
the file or option to fix. :func:`check_yaml_file` reads a configuration
file before Snakemake does, so that a syntax error names the file, the line
and the column, and so that nothing in it is run or built: a YTE template
(``__use_yte__``, whose expressions Snakemake evaluates as Python), a Python
tag (``!!python/object/apply:...``) or aliases that expand past
:data:`MAX_VALUES` values (an alias bomb) are refused. :func:`check_config`
refuses a number that is not finite (``.nan``, ``.inf``), which the schema's
limits let through, and :func:`check_project_paths` a file or folder outside
the project folder unless ``allow_outside_project`` says so.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import pandas as pd
import yaml

from loper_analysis.errors import LoperInputError

__all__ = [
    "MAX_VALUES",
    "OUTSIDE_KEYS",
    "ConfigLayers",
    "check_config",
    "check_project_paths",
    "check_table",
    "check_value",
    "check_yaml_file",
    "config_origin",
    "refuse_non_finite_option",
]

#: The most values (mappings, lists and scalars, each alias counted as what it stands for) a config file or a
#: configuration may hold: the study's config holds about 700; aliases that expand past this are an alias bomb.
MAX_VALUES = 100_000
#: The keys naming a file or folder that must lie in the project folder unless ``allow_outside_project`` is true.
OUTSIDE_KEYS = ("subjects", "raw_dir")
#: The standard YAML tags (``tag:yaml.org,2002:...``) a config file may use; any other tag is refused.
_PLAIN_TAGS = frozenset(
    "tag:yaml.org,2002:" + name
    for name in ("str", "int", "float", "bool", "null", "map", "seq", "timestamp", "binary", "set", "omap", "pairs",
                 "merge", "value")
)  # fmt: skip

#: The configuration's layers, highest priority first: ``(name, mapping)``, e.g.
#: ``[("--config", {...}), ("my.yaml", {...}), ("config/config.yaml", {...})]``.
ConfigLayers = Sequence[tuple[str, Mapping]]


def _validator(schema_path: str | Path):
    import jsonschema

    schema = yaml.safe_load(Path(schema_path).read_text())
    return jsonschema.Draft202012Validator(schema)


def _sets(layer, key_path: Sequence) -> bool:
    """True if ``layer`` holds a value at ``key_path`` (mapping keys and list indices)."""
    node = layer
    for key in key_path:
        found = (isinstance(node, Mapping) and key in node) or (
            isinstance(node, list) and isinstance(key, int) and 0 <= key < len(node)
        )
        if not found:
            return False
        node = node[key]
    return True


def config_origin(key_path: Sequence, layers: ConfigLayers | None, default: str = "config") -> str:
    """Name of the first layer (highest priority first) that sets ``key_path``; ``default`` when none does.

    Parameters
    ----------
    key_path : sequence of str or int
        Keys from the top of the configuration (``["impedance", "n_starts"]``).
    layers : sequence of (name, mapping), optional
        The configuration's layers, highest priority first (:data:`ConfigLayers`).
    default : str
        The name returned when no layer sets the key (or no layers are given).
    """
    for name, layer in layers or ():
        if _sets(layer, list(key_path)):
            return name
    return default


def _offending_path(error) -> list:
    """The key path an error is about; for an unknown key, the unknown key itself."""
    path = list(error.absolute_path)
    if error.validator == "additionalProperties" and isinstance(error.instance, Mapping):
        known = set(error.schema.get("properties", {}))
        extra = sorted(k for k in error.instance if k not in known)
        if extra:
            path.append(extra[0])
    return path


def check_config(
    data: dict, schema_path: str | Path, source: str = "config", layers: ConfigLayers | None = None
) -> None:
    """Raise LoperInputError naming the source, the first offending key (dotted path) and the problem.

    ``source`` names the configuration; with ``layers`` (:data:`ConfigLayers`)
    the message names the layer that set the offending key instead (an unknown
    key is named itself, a missing one by its parent), falling back to ``source``.
    """

    def origin(path: Sequence) -> str:
        return config_origin(path, layers, source)

    _count_values(data, origin)  # before any walk: an alias bomb is refused in its expanded size, not walked
    _refuse_non_finite(data, origin)
    errors = sorted(_validator(schema_path).iter_errors(data), key=lambda e: list(map(str, e.absolute_path)))
    if errors:
        e = errors[0]
        path = _offending_path(e)
        key = ".".join(map(str, path)) or "(top level)"
        more = f" (and {len(errors) - 1} more problem(s))" if len(errors) > 1 else ""
        where = _elsewhere(schema_path, path) if e.validator == "additionalProperties" else ""
        raise LoperInputError(f"{config_origin(path, layers, source)}: key '{key}': {e.message}{where}{more}")
    _check_relations(data, origin)


def _schema_keys(node: Mapping, path: tuple = ()):
    """(dotted path, key) of every key the schema defines, sections and their keys (definitions aside)."""
    for name, sub in (node.get("properties") or {}).items():
        yield ".".join((*path, name)), name
        if isinstance(sub, Mapping):
            yield from _schema_keys(sub, (*path, name))


def _elsewhere(schema_path: str | Path, path: Sequence) -> str:
    """For a key the schema does not know at ``path``: where a key of that name belongs (a key in the wrong
    section), as the end of a message; '' when no section has it."""
    import yaml

    name = str(path[-1]) if path else ""
    schema = yaml.safe_load(Path(schema_path).read_text())
    places = [dotted for dotted, key in _schema_keys(schema) if key == name]
    return f"; a key '{name}' belongs in {' or '.join(repr(p) for p in places)}: move it there" if places else ""


def _count_values(data, origin) -> None:
    """Refuse a configuration of more than :data:`MAX_VALUES` values, counted as expanded (shared or recursive
    containers, which YAML aliases make, counted once per place they appear, each container's size computed once)."""
    sizes: dict[int, int] = {}
    busy: set[int] = set()

    def size(node, path: tuple) -> int:
        if not isinstance(node, (dict, list)):
            return 1
        if id(node) in sizes:
            return sizes[id(node)]
        if id(node) in busy:
            raise LoperInputError(f"{origin(path)}: key '{'.'.join(map(str, path))}': holds itself (a recursive alias)")
        busy.add(id(node))
        items = node.items() if isinstance(node, dict) else enumerate(node)
        total = 1 + sum(size(v, (*path, k)) for k, v in items)
        busy.discard(id(node))
        if total > MAX_VALUES:
            raise LoperInputError(
                f"{origin(path)}: key '{'.'.join(map(str, path)) or '(top level)'}': expands to more than "
                f"{MAX_VALUES} values (aliases repeating aliases: an alias bomb): refused unread; write the values out"
            )
        sizes[id(node)] = total
        return total

    size(data, ())


def _refuse_non_finite(node, origin, path: tuple = ()) -> None:
    """Refuse a number that is not finite (``.nan``, ``.inf``, ``-.inf`` in YAML, ``NaN`` in JSON): the schema's
    minimum and maximum let NaN through (every comparison with it is false), and no setting means infinity."""
    if isinstance(node, dict):
        for k, v in node.items():
            _refuse_non_finite(v, origin, (*path, k))
    elif isinstance(node, list):
        for k, v in enumerate(node):
            _refuse_non_finite(v, origin, (*path, k))
    elif isinstance(node, float) and not math.isfinite(node):
        raise LoperInputError(
            f"{origin(path)}: key '{'.'.join(map(str, path))}': {node} is not a finite number: give a number (NaN and "
            "infinity are no setting)"
        )


def check_project_paths(config: Mapping, project: str | os.PathLike, origin) -> None:
    """Refuse ``subjects`` or ``raw_dir`` (:data:`OUTSIDE_KEYS`) outside the project folder unless the config says
    ``allow_outside_project: true``: nothing outside is read, so no message shows a line of a file that is not the
    project's.

    A path is inside when, relative paths taken from ``project``, it lies in ``project`` as written (``..``
    resolved by name: a link inside the project folder is the project's own) or once links are followed.

    Parameters
    ----------
    config : mapping
        The validated configuration.
    project : path
        The project folder (the working directory of the workflow).
    origin : callable
        ``origin(key_path) -> str``: the file or option that set a key (:func:`config_origin`).

    Raises
    ------
    LoperInputError
        Naming the file or option, the key, the value and the project folder.
    """
    if config.get("allow_outside_project") is True:
        return
    root = os.path.abspath(project)
    for key in OUTSIDE_KEYS:
        value = config.get(key)
        if not isinstance(value, str):
            continue
        full = os.path.join(root, value)
        inside = _within(os.path.normpath(full), root) or _within(os.path.realpath(full), os.path.realpath(root))
        if not inside:
            raise LoperInputError(
                f"{origin((key,))}: key '{key}': '{value}' is outside the project folder {root}: refused unread; "
                "move it into the project folder, or set allow_outside_project: true to use files outside it"
            )


def _within(path: str, root: str) -> bool:
    return path == root or path.startswith(root.rstrip(os.sep) + os.sep)


#: Parts of a key's name that make a two-number list an interval [low, high].
_INTERVAL_WORDS = ("range", "bounds", "span", "window")
#: (lower, upper) keys of one setting: the first must not exceed the second.
_ORDERED_KEYS = (
    (("ik", "warn_marker_rms_m"), ("ik", "max_marker_rms_m")),
    (("ik", "geometry_warn_change"), ("ik", "geometry_stop_change")),
)


def _intervals(node, path: tuple = ()):
    """(key path, [low, high]) of every two-number list whose key names an interval (:data:`_INTERVAL_WORDS`)."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _intervals(v, (*path, str(k)))
    elif (
        isinstance(node, list)
        and len(node) == 2
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in node)
        and any(word in part for part in path for word in _INTERVAL_WORDS)
    ):
        yield path, node


def _check_relations(config: dict, origin) -> None:
    """Refuse settings that pass the schema one by one but not together: an interval whose low end is not below
    its high end, a warning level above its stop level, a static trial named like a walking trial."""
    for path, (low, high) in _intervals(config):
        if not low < high:
            raise LoperInputError(
                f"{origin(path)}: key '{'.'.join(path)}': [{low}, {high}] is reversed or empty: give [low, high] "
                "with low below high"
            )
    for lower, upper in _ORDERED_KEYS:
        a, b = _get(config, lower), _get(config, upper)
        if isinstance(a, (int, float)) and isinstance(b, (int, float)) and a > b:
            raise LoperInputError(
                f"{origin(lower)}: key '{'.'.join(lower)}' {a} exceeds '{'.'.join(upper)}' {b} (from "
                f"{origin(upper)}): the warning level must not be above the level that stops"
            )
    trials = config.get("study")
    if isinstance(trials, dict) and isinstance(trials.get("static"), str):
        for other in ("no_device", "device"):
            if trials.get(other) == trials["static"]:
                raise LoperInputError(
                    f"{origin(('study', 'static'))}: key 'study.static': '{trials['static']}' is also the walking "
                    f"trial study.{other}: the static trial is a standing trial of its own (e.g. 'static')"
                )


def _get(config: dict, path: Sequence[str]):
    node = config
    for key in path:
        if not isinstance(node, dict) or key not in node:
            return None
        node = node[key]
    return node


def check_value(value, schema_path: str | Path, key_path: Sequence[str], name: str) -> None:
    """Refuse a value outside the limits the schema sets for one key: a command's option is held to its config
    key's range, type and enumeration (one schema for both).

    Parameters
    ----------
    value
        The option's value (a number, a string, a list).
    schema_path : path
        The JSON schema (``config.schema.yaml`` or ``subjects.schema.yaml``).
    key_path : sequence of str
        The key's path through the schema's ``properties`` (``["planning", "pulse_force_n"]``).
    name : str
        The option, for the message (``--force-n``).

    Raises
    ------
    LoperInputError
        Naming the option, its value, the problem and the config key whose limits hold (a key the schema lacks is
        a programming error: KeyError).
    """
    import jsonschema

    refuse_non_finite_option(value, name)
    node = yaml.safe_load(Path(schema_path).read_text())
    for key in key_path:
        node = node["properties"][key]
    errors = list(jsonschema.Draft202012Validator(node).iter_errors(value))
    if errors:
        raise LoperInputError(
            f"{name} {value!r}: {errors[0].message} (the limits of {'.'.join(key_path)} in {Path(schema_path).name})"
        )


def refuse_non_finite_option(value, name: str) -> None:
    """Refuse a command's option value that is NaN or infinite (``--max-marker-rms-m nan``): Python reads ``nan``
    and ``inf`` as numbers, and limits let NaN through.

    Raises
    ------
    LoperInputError
        Naming the option and its value.
    """
    for item in value if isinstance(value, (list, tuple)) else [value]:
        if isinstance(item, float) and not math.isfinite(item):
            raise LoperInputError(f"{name} {item}: not a finite number: give a number (NaN and infinity are no value)")


def check_table(table: pd.DataFrame, schema_path: str | Path, source: str) -> None:
    """Validate every row of a sheet; the message names the row (1-based, after the header) and column."""
    validator = _validator(schema_path)
    for n, record in enumerate(table.to_dict("records"), start=1):
        row = {k: v for k, v in record.items() if not (isinstance(v, float) and pd.isna(v))}
        errors = list(validator.iter_errors(row))
        if errors:
            e = errors[0]
            col = ".".join(map(str, e.absolute_path)) or "(row)"
            raise LoperInputError(f"{source}: row {n}, column '{col}': {e.message}")


def _mark(mark) -> str:
    """A YAML position as ``line L, column C`` (1-based)."""
    return f"line {mark.line + 1}, column {mark.column + 1}"


def check_yaml_file(path: str | Path, what: str = "config file") -> None:
    """Refuse a YAML (or JSON) file that does not parse into a mapping, in one line naming the file and the place.

    Only the syntax is checked (the document is composed, no value is built,
    nothing is evaluated), so a file this accepts is read by Snakemake's own loader; the values are
    checked by :func:`check_config`. Snakemake's own message for a syntax
    error names neither the file nor the line.

    Parameters
    ----------
    path : str or path-like
        The file, e.g. ``config/config.yaml``.
    what : str
        The kind of file, for the message.

    Raises
    ------
    LoperInputError
        The file cannot be read or is not UTF-8; a YAML syntax error, e.g.
        ``config/config.yaml: line 73, column 8: YAML syntax error: expected ',' or ']', but got ':'
        (while parsing a flow sequence that starts at line 72, column 14)``; a file that holds no mapping of
        keys at its top level; a YTE template (``__use_yte__``), a tag other than YAML's own
        (``!!python/object/apply:...``), aliases expanding past :data:`MAX_VALUES` values.
    """
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise LoperInputError(f"{path}: cannot read the {what}: {exc.strerror or exc}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise LoperInputError(
            f"{path}: line {line}: the {what} is not UTF-8 text (byte {data[exc.start]:#04x} at offset {exc.start})"
        ) from None
    try:
        documents = list(yaml.compose_all(text, Loader=yaml.SafeLoader))
    except yaml.MarkedYAMLError as exc:
        where = _mark(exc.problem_mark) if exc.problem_mark is not None else "(unknown place)"
        context = ""
        if exc.context:
            context = f" ({exc.context}" + (
                f" that starts at {_mark(exc.context_mark)})" if exc.context_mark is not None else ")"
            )
        raise LoperInputError(f"{path}: {where}: YAML syntax error: {exc.problem}{context}") from None
    except yaml.YAMLError as exc:
        raise LoperInputError(f"{path}: YAML syntax error: {' '.join(str(exc).split())}") from None
    if not documents or not isinstance(documents[0], yaml.MappingNode):
        found = "nothing" if not documents else f"a {documents[0].id} at {_mark(documents[0].start_mark)}"
        raise LoperInputError(f"{path}: the {what} must hold keys at its top level (key: value), found {found}")
    _refuse_template(documents[0], path, what)
    for document in documents:
        _refuse_code_and_bombs(document, path, what)
    _refuse_duplicate_keys(documents[0], path, what)


def _refuse_template(top: yaml.MappingNode, path, what: str) -> None:
    """Refuse a YTE template: Snakemake renders a config file whose top level says ``__use_yte__: true``, running
    its expressions as Python (``?...`` values, ``__definitions__``)."""
    for key, value in top.value:
        if isinstance(key, yaml.ScalarNode) and key.value == "__use_yte__":
            off = isinstance(value, yaml.ScalarNode) and value.tag.endswith(":bool") and value.value.lower() in (
                "false", "no", "off")  # fmt: skip
            if not off:
                raise LoperInputError(
                    f"{path}: {_mark(key.start_mark)}: key '__use_yte__': a YTE template, whose expressions "
                    f"Snakemake would run as Python: refused; the {what} must hold the plain values (render it "
                    "yourself if you trust it)"
                )


def _tag(tag: str) -> str:
    return "!!" + tag.removeprefix("tag:yaml.org,2002:") if tag.startswith("tag:yaml.org,2002:") else tag


def _refuse_code_and_bombs(document: yaml.Node, path, what: str) -> None:
    """Refuse a tag other than YAML's standard ones (``!!python/object/apply:os.system`` builds a Python object, a
    call), and aliases that expand past :data:`MAX_VALUES` values or into themselves; each node is looked at once,
    however often aliases repeat it, so an alias bomb is refused at once."""
    sizes: dict[int, int] = {}
    busy: set[int] = set()

    def size(node: yaml.Node) -> int:
        if id(node) in sizes:
            return sizes[id(node)]
        if id(node) in busy:
            raise LoperInputError(f"{path}: {_mark(node.start_mark)}: an alias of a value inside itself: refused")
        if node.tag not in _PLAIN_TAGS:
            raise LoperInputError(
                f"{path}: {_mark(node.start_mark)}: tag '{_tag(node.tag)}': the {what} may hold plain values only "
                "(a Python tag builds an object or calls code): refused; give the value itself"
            )
        busy.add(id(node))
        if isinstance(node, yaml.MappingNode):
            total = 1 + sum(size(k) + size(v) for k, v in node.value)
        elif isinstance(node, yaml.SequenceNode):
            total = 1 + sum(size(v) for v in node.value)
        else:
            total = 1
        busy.discard(id(node))
        if total > MAX_VALUES:
            raise LoperInputError(
                f"{path}: {_mark(node.start_mark)}: this value's aliases expand to more than {MAX_VALUES} values "
                "(aliases repeating aliases: an alias bomb): refused unread; write the values out"
            )
        sizes[id(node)] = total
        return total

    size(document)


def _refuse_duplicate_keys(node, path, what: str, parents: tuple[str, ...] = ()) -> None:
    """Refuse a mapping that gives a key twice: YAML keeps the later value, which replaces the earlier one whole
    (a second, partial ``filter:`` block silently drops the keys of the first)."""
    if isinstance(node, yaml.MappingNode):
        seen: dict[str, yaml.Node] = {}
        for key, value in node.value:
            name = str(key.value) if isinstance(key, yaml.ScalarNode) else None
            if name is not None and name in seen:
                dotted = ".".join((*parents, name))
                raise LoperInputError(
                    f"{path}: key '{dotted}' is given twice in the {what}, at {_mark(seen[name].start_mark)} and "
                    f"{_mark(key.start_mark)}: YAML keeps the second, which replaces the first whole; merge them"
                )
            if name is not None:
                seen[name] = key
            _refuse_duplicate_keys(value, path, what, (*parents, name or "?"))
    elif isinstance(node, yaml.SequenceNode):
        for k, item in enumerate(node.value):
            _refuse_duplicate_keys(item, path, what, (*parents, str(k)))
