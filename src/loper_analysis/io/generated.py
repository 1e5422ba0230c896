"""Raw files the workflow generates (the synthetic lab's recordings, the simulated device tests), told apart from
recordings by the manifests their writers keep beside them.

A writer of generated raw files keeps a manifest in the subject's raw folder,
``{writer}.generated.sha256``, one line ``{sha256}  {file name}`` per file it
wrote (the format of ``sha256sum``, so ``sha256sum -c`` checks it). A raw file
in the folder is the workflow's own when a manifest there lists its name with
its content's checksum; any other is taken for a recording and never written
over (:func:`refuse_foreign_files`, :func:`unvouched_files`).

:func:`generated` writes one file: the new checksum enters the manifest before
the file is moved into place and the old one leaves it after, so that the
folder, looked at any time (another job checking it while this one writes),
holds no file its manifest does not vouch for.
"""

from __future__ import annotations

import contextlib
import os
import re
from collections.abc import Iterable, Iterator
from pathlib import Path

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import staged, write_text
from loper_analysis.io.raw_files import RAW_SUFFIXES, content_checksum

__all__ = [
    "MANIFEST_SUFFIX",
    "generated",
    "manifest_path",
    "refuse_foreign_files",
    "unvouched_files",
    "vouched_checksums",
]

#: A manifest's name ends so: ``synthetic_lab.generated.sha256``, ``device-frf.generated.sha256``.
MANIFEST_SUFFIX = ".generated.sha256"
_LINE = re.compile(r"^([0-9a-f]{64}) [ *](.+)$")


def manifest_path(folder: str | os.PathLike, writer: str) -> Path:
    """The manifest of ``writer`` (``synthetic_lab``, a device test's name) in a raw folder."""
    return Path(folder) / f"{writer}{MANIFEST_SUFFIX}"


def _read_manifest(path: Path) -> dict[str, list[str]]:
    """File name -> its checksums (more than one only while a writer replaces the file).

    Raises
    ------
    LoperInputError
        A line that is not ``{sha256}  {name}``, naming the manifest, the line and its text.
    """
    entries: dict[str, list[str]] = {}
    if not path.is_file():
        return entries
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        if not line.strip():
            continue
        match = _LINE.match(line)
        if match is None:
            raise LoperInputError(
                f"{path}: line {number}: '{line}' is not '{{sha256}}  {{file name}}'; this manifest of generated "
                f"raw files is the workflow's own: delete it with the files it lists, and they are generated again"
            )
        entries.setdefault(match.group(2), []).append(match.group(1))
    return entries


def _write_manifest(path: Path, entries: dict[str, list[str]]) -> None:
    lines = [f"{checksum}  {name}\n" for name in sorted(entries) for checksum in entries[name]]
    write_text(path, "".join(lines), "manifest of generated raw files")


def vouched_checksums(folder: str | os.PathLike) -> dict[str, set[str]]:
    """File name -> the checksums the folder's manifests (``*.generated.sha256``) give it; empty without any."""
    folder, out = Path(folder), {}
    if not folder.is_dir():
        return out
    for manifest in sorted(folder.glob(f"*{MANIFEST_SUFFIX}")):
        for name, checksums in _read_manifest(manifest).items():
            out.setdefault(name, set()).update(checksums)
    return out


def _why_foreign(path: Path, vouched: dict[str, set[str]]) -> str | None:
    """Why ``path`` is not the workflow's own file (None when it is)."""
    if path.name not in vouched:
        return "in no manifest"
    if not path.is_file() or content_checksum(path) not in vouched[path.name]:
        return "content differs from its manifest's checksum"
    return None


def unvouched_files(folder: str | os.PathLike) -> list[tuple[str, str]]:
    """The raw files (suffixes :data:`~loper_analysis.io.raw_files.RAW_SUFFIXES`, in any case) of ``folder`` that
    no manifest vouches for, with the reason: ``(name, "in no manifest")`` or ``(name, "content differs ...")``.

    Returns
    -------
    list of (str, str)
        Sorted by name; empty for a folder that does not exist.
    """
    folder = Path(folder)
    if not folder.is_dir():
        return []
    vouched = vouched_checksums(folder)
    raw = sorted(p for p in folder.iterdir() if p.name.lower().endswith(RAW_SUFFIXES))
    return [(p.name, why) for p in raw if (why := _why_foreign(p, vouched)) is not None]


def refuse_foreign_files(paths: Iterable[str | os.PathLike], writer: str) -> None:
    """Before a writer of generated raw files writes anything: every one of ``paths`` that exists must be the
    workflow's own (vouched for by a manifest of its folder).

    Raises
    ------
    LoperInputError
        Naming the folder, the files and what to do; nothing has been written.
    """
    foreign: dict[Path, list[str]] = {}
    for path in map(Path, paths):
        if os.path.lexists(path):
            why = _why_foreign(path, vouched_checksums(path.parent))
            if why is not None:
                foreign.setdefault(path.parent, []).append(f"{path.name} ({why})")
    for folder, names in foreign.items():
        raise LoperInputError(
            f"{folder}: {', '.join(names)}: not written by the workflow (no manifest *{MANIFEST_SUFFIX} vouches "
            f"for it): {writer} writes over no recording; mark the subject 'recorded' in the subject sheet (column "
            f"source), or move these files out of {folder}"
        )


@contextlib.contextmanager
def generated(path: str | os.PathLike, writer: str, what: str = "file") -> Iterator[Path]:
    """Yield a staged path for the generated raw file ``path``; when the body returns, enter its checksum in
    ``writer``'s manifest, move it over ``path`` and drop the checksum of the file it replaced.

    Raises
    ------
    LoperInputError
        ``path`` exists and is not the workflow's own (:func:`refuse_foreign_files`); nothing is written.
    """
    path = Path(path)
    refuse_foreign_files([path], writer)
    manifest = manifest_path(path.parent, writer)
    with staged(path, what) as tmp:
        yield tmp
        checksum = content_checksum(tmp) if tmp.is_file() else None  # no file: staged() refuses it
        if checksum is not None:  # the old file's checksum and the new one, while the new file moves in
            entries = _read_manifest(manifest)
            entries = {n: c for n, c in entries.items() if n == path.name or (path.parent / n).is_file()}
            entries[path.name] = [*(c for c in entries.get(path.name, []) if c != checksum), checksum]
            _write_manifest(manifest, entries)
    entries = _read_manifest(manifest)
    entries[path.name] = [checksum]
    _write_manifest(manifest, entries)
