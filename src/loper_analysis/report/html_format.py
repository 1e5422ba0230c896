"""How the front page writes its numbers: checkable ``<span>`` elements, marks, shares and settings.

Every number the front page (:mod:`loper_analysis.report.front_page`) shows sits in a ``<span>`` whose
``data-q`` names its table, row and column (``table|row|column``) and whose ``data-v`` holds the value at full
precision (``repr``): :func:`num` and :func:`count` write them. :func:`mark` is a verdict's mark, :func:`pct` a
share, :func:`g` a setting's number, :func:`decimals` and :func:`text` the rounding of a column.
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable

import numpy as np

__all__ = ["MINUS", "count", "decimals", "g", "mark", "num", "pct", "text"]

#: The true minus sign the page writes.
MINUS = "\u2212"


def g(value: float) -> str:
    """A setting's number without trailing zeros (``40``, ``0.1``, ``12.5``), with a true minus sign."""
    return f"{float(value):g}".replace("-", MINUS)


def decimals(values: Iterable[float | None], significant: int = 3, most: int = 4) -> int:
    """Decimals that show the largest magnitude among ``values`` with ``significant`` digits (0 to ``most``)."""
    finite = np.abs(np.asarray([v for v in values if v is not None], dtype=float))
    finite = finite[np.isfinite(finite) & (finite > 0)]
    if not finite.size:
        return 2
    return int(min(most, max(0, significant - 1 - math.floor(math.log10(finite.max())))))


def text(value: float | None, places: int) -> str:
    """A number with ``places`` decimals and a true minus sign; no negative zero; NaN as an en dash."""
    if value is None or not math.isfinite(value):
        return "–"
    shown = f"{value:.{places}f}"
    if float(shown) == 0.0:
        shown = shown.lstrip("-")
    return shown.replace("-", MINUS)


def num(value: float | None, places: int, key: str) -> str:
    """A number as a ``<span>`` carrying its key (``table|row|column``) and full-precision value."""
    value = math.nan if value is None else float(value)
    return f'<span data-q="{html.escape(key)}" data-v="{value!r}">{text(value, places)}</span>'


def count(value: int, key: str) -> str:
    """A whole number as a ``<span>`` carrying its key and value."""
    return f'<span data-q="{html.escape(key)}" data-v="{int(value)!r}">{int(value)}</span>'


def mark(ok: bool | None) -> str:
    """✓ (green), ✗ (red) or a grey dot (no criterion or no verdict)."""
    if ok is None:
        return '<span class="lf-mark lf-dim">●</span>'
    return '<span class="lf-mark lf-ok">✓</span>' if ok else '<span class="lf-mark lf-bad">✗</span>'


def pct(n: int, total: int) -> str:
    """``n`` of ``total`` in whole per cent (``"87 %"``); an en dash of nothing."""
    return f"{100.0 * n / total:.0f} %" if total else "–"
