"""Read the workflow's configuration outside Snakemake: the same files, layered and checked as the workflow does.

:func:`load_config` reads ``config/config.yaml`` (or the files given),
updates each file with the next one as Snakemake does with its
``--configfile`` files (a recursive update: a mapping is merged key by key,
any other value replaces the one before), applies optional overrides last
(like Snakemake's ``--config``), and validates the result against the
workflow's schema ``workflow/schemas/config.schema.yaml``. A problem is one
:class:`~loper_analysis.errors.LoperInputError` naming the file (the one that
set the offending key), the key and the value.

The schema belongs to the project the configuration is for: it is looked for
in the project folder of each file (the parent of its ``config/`` folder),
then in the working directory and then in the repository this package was
installed from.
"""

from __future__ import annotations

import copy
import json
import os
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

import yaml

from loper_analysis.config_sections import translated
from loper_analysis.errors import LoperInputError
from loper_analysis.schema import check_config, check_yaml_file

__all__ = ["DEFAULT_CONFIG", "SCHEMA", "find_schema", "load_config", "read_config_file", "shown_path", "update_config"]

#: The workflow's own configuration file, relative to the working directory (the Snakefile's ``configfile:``).
DEFAULT_CONFIG = Path("config") / "config.yaml"

#: The configuration's schema, relative to a project folder.
SCHEMA = Path("workflow") / "schemas" / "config.schema.yaml"

#: The name of the overrides' layer in messages.
OVERRIDES = "overrides"


def shown_path(path: str | os.PathLike) -> str:
    """A file's name as the user would type it: relative to the working directory when inside it, else as given."""
    path = Path(path)
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


def config_layers(command_line: Mapping, files: Sequence, load) -> list[tuple[str, dict]]:
    """Where each config value came from, highest priority first: ``("--config", values)``, then each config file
    given, last to first, as ``(its name as typed, its values)`` (:func:`loper_analysis.schema.config_origin`).

    ``load(path) -> dict`` reads one file (Snakemake's ``load_configfile`` in the workflow)."""
    layers = [("--config", dict(command_line))] + [(shown_path(f), load(str(f)) or {}) for f in reversed(list(files))]
    for _, values in layers:  # a file of the former layout: its keys at their places now
        translated(values)
    return layers


def update_config(config: dict, overwrite_config: Mapping) -> None:
    """Recursively update ``config`` with ``overwrite_config`` in place, exactly as ``snakemake.utils.update_config``.

    A mapping in ``overwrite_config`` is merged key by key into the value at
    the same key (a non-mapping there is replaced by an empty mapping first);
    any other value (a list, a number, None) replaces the value before.

    Parameters
    ----------
    config : dict
        The configuration to update (changed in place).
    overwrite_config : mapping
        The values that win.
    """

    def _update(node, overwrite):
        for key, value in overwrite.items():
            if not isinstance(node, Mapping):
                node = {}
            if isinstance(value, Mapping):
                node[key] = _update(node.get(key, {}), value)
            else:
                node[key] = value
        return node

    _update(config, overwrite_config)


def read_config_file(path: str | os.PathLike) -> dict:
    """One configuration file as Snakemake's ``load_configfile`` reads it: JSON, else YAML (a mapping at the top).

    The syntax is checked first (:func:`loper_analysis.schema.check_yaml_file`),
    so that an error names the file, the line and the column, and nothing in
    the file is run or built: a YTE template, a Python tag and an alias bomb
    are refused before the values are read.

    Parameters
    ----------
    path : str or path-like
        A YAML or JSON file.

    Returns
    -------
    dict
        The file's keys and values.

    Raises
    ------
    LoperInputError
        The file cannot be read, is not YAML/JSON, holds no mapping at its top
        level, is a YTE template (``__use_yte__``), holds a Python tag or aliases
        expanding past :data:`loper_analysis.schema.MAX_VALUES` values.
    """
    shown = shown_path(path)
    check_yaml_file(path)
    text = Path(path).read_text(encoding="utf-8")
    try:
        data = json.loads(text)
    except ValueError:
        try:
            data = yaml.safe_load(text)  # no Python tag reaches it (check_yaml_file): Snakemake's loader gives the same
        except yaml.YAMLError as exc:  # accepted by the composer, refused by the loader
            raise LoperInputError(f"{shown}: YAML error: {' '.join(str(exc).split())}") from None
    if not isinstance(data, dict):
        raise LoperInputError(
            f"{shown}: the config file must hold keys at its top level (key: value), found a {type(data).__name__}"
        )
    data.pop("__use_yte__", None)  # false: a template is refused by check_yaml_file
    return data


def find_schema(paths: Sequence[str | os.PathLike] = (), name: str = SCHEMA.name) -> Path:
    """The workflow's config schema for configuration files ``paths`` (or another schema of its folder, ``name``:
    ``subjects.schema.yaml``).

    Looked for, in this order, in the project folder of each file (the parent
    of the folder holding it: ``PROJECT/config/config.yaml`` ->
    ``PROJECT/workflow/schemas/config.schema.yaml``), in the working directory
    and in the repository this package was installed from (an editable install).

    Raises
    ------
    LoperInputError
        Found in none of those places (the message lists them).
    """
    schema = SCHEMA.parent / name
    candidates = [Path(p).resolve().parent.parent / schema for p in paths]
    candidates += [Path.cwd() / schema, Path(__file__).resolve().parents[2] / schema]
    tried = list(dict.fromkeys(candidates))
    for candidate in tried:
        if candidate.is_file():
            return candidate
    files = ", ".join(shown_path(p) for p in paths) or "the configuration"
    raise LoperInputError(
        f"{files}: cannot validate: no {schema.as_posix()} found (looked in: {', '.join(str(c) for c in tried)})"
    )


def load_config(
    paths: Sequence[str | os.PathLike] | None = None,
    overrides: Mapping | None = None,
    *,
    schema: str | os.PathLike | None = None,
) -> tuple[dict, list[str]]:
    """Read, layer and validate the workflow's configuration.

    Parameters
    ----------
    paths : sequence of str or path-like, optional
        Configuration files (YAML or JSON), each updating the ones before it
        recursively as Snakemake's ``--configfile`` files do
        (:func:`update_config`); default ``config/config.yaml`` of the working
        directory.
    overrides : mapping, optional
        Values applied over the files last (as Snakemake's ``--config``).
    schema : str or path-like, optional
        The JSON schema to validate against; default the project's
        ``workflow/schemas/config.schema.yaml`` (:func:`find_schema`).

    Returns
    -------
    (dict, list of str)
        The merged configuration, and the files read in order (as typed, or
        relative to the working directory when inside it).

    Raises
    ------
    LoperInputError
        A file that cannot be read or parsed, no file given, no schema found,
        or a configuration the schema refuses: the message names the file
        (or ``overrides``) that set the offending key, the key and the problem
        with its value.
    """
    files = [DEFAULT_CONFIG] if paths is None else [Path(p) for p in paths]
    if not files:
        raise LoperInputError("load_config: no configuration file given")
    layers = []
    config: dict = {}
    for path in files:
        data = read_config_file(path)
        moves = translated(data)
        if moves:
            print(f"config: {shown_path(path)} is in the former layout, read as: {'; '.join(moves)}", file=sys.stderr)
        layers.append((shown_path(path), data))
        update_config(config, data)
    if overrides:
        overrides = copy.deepcopy(dict(overrides))
        translated(overrides)
        update_config(config, overrides)
        layers.append((OVERRIDES, overrides))
    schema_path = Path(schema) if schema is not None else find_schema(files)
    # highest priority first; a key no layer sets (a missing one) is named after the first file
    check_config(config, schema_path, layers[0][0], list(reversed(layers)))
    return config, [shown_path(p) for p in files]
