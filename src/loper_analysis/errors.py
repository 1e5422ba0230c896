"""The one error type of the library, its one warning, and the one-line form of any error."""

from __future__ import annotations

__all__ = ["LoperInputError", "TooFewStridesWarning", "one_line"]


class LoperInputError(ValueError):
    """Bad input: the message names the file (or argument), the field and the offending value."""


class TooFewStridesWarning(UserWarning):
    """Fewer valid strides than required remain for an average."""


def one_line(exc: BaseException) -> str:
    """An error as one line: a LoperInputError's message, any other error prefixed with its type's name."""
    text = " ".join(str(exc).split())
    return text if isinstance(exc, LoperInputError) else f"{type(exc).__name__}: {text}"
