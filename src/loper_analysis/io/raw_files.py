"""A subject's raw files: which trials of the design are on disk, and which files match none.

Raw files are named ``{trial}{suffix}`` in the subject's folder, with the
suffixes of :data:`RAW_SUFFIXES`. A path that exists but is not a readable
file (a broken link, a directory, a file without read permission) is an
error, not a missing trial: a trial silently left out changes every average
it would have entered.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Iterable
from pathlib import Path

from loper_analysis.errors import LoperInputError

__all__ = [
    "RAW_SUFFIXES",
    "content_checksum",
    "raw_file_present",
    "refuse_miscased_raw_files",
    "repeated_files",
    "unmatched_raw_files",
]

#: Suffixes of raw files: motion capture, robot log, the robot's MATLAB export.
RAW_SUFFIXES: tuple[str, ...] = (".c3d", ".loper.tsv", ".mat")


def raw_file_present(path: str | os.PathLike, what: str = "raw file") -> bool:
    """Whether a raw file is there: True for a readable file, False when nothing is at ``path``.

    Raises
    ------
    LoperInputError
        Something is at ``path`` but it is not a readable file: a broken
        link (naming its target), a directory or other non-file, or a file
        that cannot be opened for reading.
    """
    p = Path(path)
    if not os.path.lexists(p):
        return False
    if p.is_symlink() and not p.exists():
        raise LoperInputError(
            f"{p}: the {what} is a broken link (to '{os.readlink(p)}'); restore its target or remove the link"
        )
    if not p.is_file():
        kind = "a directory" if p.is_dir() else "not a regular file"
        raise LoperInputError(f"{p}: the {what} is {kind}; a trial's raw file must be a file")
    if not os.access(p, os.R_OK):
        raise LoperInputError(f"{p}: the {what} cannot be read (permission denied)")
    return True


def unmatched_raw_files(folder: str | os.PathLike, trials: Iterable[str]) -> list[str]:
    """Names of the raw files in ``folder`` (suffixes :data:`RAW_SUFFIXES`) that belong to none of ``trials``.

    Returns
    -------
    list of str
        File names, sorted; empty when the folder does not exist.
    """
    folder = Path(folder)
    if not folder.is_dir():
        return []
    names = {f"{t}{suffix}" for t in trials for suffix in RAW_SUFFIXES}
    raw = [p.name for p in folder.iterdir() if p.name.lower().endswith(RAW_SUFFIXES)]
    lower = {n.lower() for n in names}
    return sorted(n for n in raw if n not in names and n.lower() not in lower)


def refuse_miscased_raw_files(folder: str | os.PathLike, trials: Iterable[str]) -> None:
    """Refuse a trial's raw file whose name differs from the expected one only in case (``pert175-2.C3D``,
    ``walk-device.Loper.tsv``, as some exports write them): the workflow, on a case-sensitive file system,
    would not find it and would leave the trial out without a word.

    Raises
    ------
    LoperInputError
        Naming the file and the name it must have.
    """
    folder = Path(folder)
    if not folder.is_dir():
        return
    expected = {f"{t}{suffix}".lower(): f"{t}{suffix}" for t in trials for suffix in RAW_SUFFIXES}
    for p in sorted(folder.iterdir()):
        want = expected.get(p.name.lower())
        if want is not None and p.name != want:
            raise LoperInputError(
                f"{p}: the raw file of trial '{want.split('.')[0]}' is named '{p.name}'; raw files are named "
                f"{{trial}}.c3d, .loper.tsv or .mat in lower case: rename it '{want}' (it would be left out)"
            )


_CHECKSUMS: dict[tuple, str] = {}


def content_checksum(path: str | os.PathLike) -> str:
    """SHA-256 of a file's content (hex).

    A raw file copied over with its old time kept (``cp -p``, ``rsync -a``) looks older than the results made
    from it; its checksum tells that it changed. Computed once per process for a file whose size, modification
    time and status-change time (which no copy keeps) are unchanged.
    """
    st = os.stat(path)
    key = (os.fspath(path), st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino)
    if key not in _CHECKSUMS:
        digest = hashlib.sha256()
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                digest.update(block)
        _CHECKSUMS[key] = digest.hexdigest()
    return _CHECKSUMS[key]


def repeated_files(paths: Iterable[str | os.PathLike]) -> list[tuple[Path, Path, str]]:
    """The files among ``paths`` that are another one of them: the same file (a symbolic or hard link to it) or
    a copy of its content.

    Sizes are compared first; only files of equal size are read (their SHA-256, :func:`content_checksum`).
    Empty files and paths that are not files are left to the readers.

    Returns
    -------
    list of (Path, Path, str)
        ``(repeat, first, how)`` in the order of ``paths``: ``repeat`` is the same as the earlier ``first``;
        ``how`` says how (``"a symbolic link to the same file"``, ``"a hard link to the same file"``,
        ``"a copy: the same content"``).
    """
    files = [Path(p) for p in paths if Path(p).is_file()]
    stats = {p: os.stat(p) for p in files}
    by_size: dict[int, list[Path]] = {}
    for p in files:
        if stats[p].st_size > 0:
            by_size.setdefault(stats[p].st_size, []).append(p)
    out = []
    for group in (g for g in by_size.values() if len(g) > 1):
        firsts: dict[tuple, Path] = {}
        for p in group:
            inode = (stats[p].st_dev, stats[p].st_ino)
            if inode in firsts:
                first = firsts[inode]
                link = "symbolic" if p.is_symlink() or first.is_symlink() else "hard"
                out.append((p, first, f"a {link} link to the same file"))
                continue
            checksum = content_checksum(p)
            first = firsts.get(("sha256", checksum))
            firsts[inode] = p
            if first is not None:
                out.append((p, first, "a copy: the same content"))
            else:
                firsts[("sha256", checksum)] = p
    order = {p: k for k, p in enumerate(files)}
    return sorted(out, key=lambda item: order[item[0]])
