"""The landmark synonyms the label matcher reads (``src/loper_analysis/templates/label_synonyms.yaml``).

The table is data: every landmark a name and the spellings labs give it
(:mod:`loper_analysis.motion.label_matching` reads them through :data:`LANDMARK_SYNONYMS`, read once when this
module is first imported).
"""

from __future__ import annotations

import os
import re
from importlib import resources
from pathlib import Path

from loper_analysis.errors import LoperInputError
from loper_analysis.io.readers import read_yaml

__all__ = ["LABEL_SYNONYMS_FILE", "LANDMARK_NAMES", "LANDMARK_SYNONYMS", "normalised_spelling", "read_label_synonyms"]

#: The package's synonym table.
LABEL_SYNONYMS_FILE: Path = Path(str(resources.files("loper_analysis") / "templates" / "label_synonyms.yaml"))

_NOT_ALNUM = re.compile(r"[^0-9a-z]")


def normalised_spelling(name: str) -> str:
    """A spelling as the matcher compares it: lowercase letters and digits only (``Med_kn`` -> ``medkn``)."""
    return _NOT_ALNUM.sub("", str(name).lower())


def read_label_synonyms(path: str | os.PathLike = LABEL_SYNONYMS_FILE) -> tuple[dict[str, tuple[str, ...]], dict]:
    """The landmark synonyms of a YAML file (``landmarks: {key: {name: ..., spellings: [...]}}``).

    Returns
    -------
    (dict, dict)
        Landmark key -> its spellings normalised (:func:`normalised_spelling`), in file order; landmark key -> its
        name (a line of text).

    Raises
    ------
    LoperInputError
        An unreadable file, a landmark without spellings, or a spelling given to two landmarks (naming the file,
        the spelling and both landmarks).
    """
    doc = read_yaml(path, "label synonym table")
    landmarks = doc.get("landmarks") if isinstance(doc, dict) else None
    if not isinstance(landmarks, dict) or not landmarks:
        raise LoperInputError(f"{path}: a label synonym table holds 'landmarks: {{key: {{name, spellings}}}}'")
    synonyms: dict[str, tuple[str, ...]] = {}
    names: dict[str, str] = {}
    owner: dict[str, str] = {}
    for key, entry in landmarks.items():
        spellings = entry.get("spellings") if isinstance(entry, dict) else None
        if not isinstance(spellings, list) or not spellings:
            raise LoperInputError(f"{path}: landmark {key!r} needs a list of spellings")
        flat = tuple(dict.fromkeys(normalised_spelling(s) for s in spellings))
        for s in flat:
            if not s:
                raise LoperInputError(f"{path}: landmark {key!r}: a spelling without letters or digits")
            if s in owner:
                raise LoperInputError(f"{path}: spelling {s!r} belongs to landmarks {owner[s]!r} and {key!r}")
            owner[s] = str(key)
        synonyms[str(key)] = flat
        names[str(key)] = str(entry.get("name", key))
    return synonyms, names


#: Landmark -> spellings (lowercase letters and digits, side removed), the package's table.
#: Landmark -> its name.
LANDMARK_SYNONYMS, LANDMARK_NAMES = read_label_synonyms()
