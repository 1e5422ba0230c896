"""The one error type of the library, and its one warning."""

from __future__ import annotations

__all__ = ["LoperInputError", "TooFewStridesWarning"]


class LoperInputError(ValueError):
    """Bad input: the message names the file (or argument), the field and the offending value."""


class TooFewStridesWarning(UserWarning):
    """Fewer valid strides than required remain for an average."""
