"""Check configuration data against the workflow's JSON schemas with one short message."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import yaml

from .errors import LoperInputError

__all__ = ["check_config", "check_table"]


def _validator(schema_path: str | Path):
    import jsonschema

    schema = yaml.safe_load(Path(schema_path).read_text())
    return jsonschema.Draft202012Validator(schema)


def check_config(data: dict, schema_path: str | Path, source: str = "config") -> None:
    """Raise LoperInputError naming the first offending key (dotted path) of ``data``."""
    errors = sorted(_validator(schema_path).iter_errors(data), key=lambda e: list(map(str, e.absolute_path)))
    if errors:
        e = errors[0]
        key = ".".join(map(str, e.absolute_path)) or "(top level)"
        more = f" (and {len(errors) - 1} more problem(s))" if len(errors) > 1 else ""
        raise LoperInputError(f"{source}: key '{key}': {e.message}{more}")


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
