"""The one error type of the library."""

from __future__ import annotations

__all__ = ["LoperInputError"]


class LoperInputError(ValueError):
    """Bad input: the message names the argument (or file/field) and the offending value."""
