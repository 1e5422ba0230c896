"""A subject's raw files (io.raw_files): present, absent or refused by kind; files matching no trial; miscased
names; the content checksum against SHA-256 of known bytes."""

from __future__ import annotations

import hashlib
import os

import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.raw_files import (
    RAW_SUFFIXES,
    content_checksum,
    raw_file_present,
    refuse_miscased_raw_files,
    unmatched_raw_files,
)

TRIALS = ["static", "walk-device", "pert050-1"]


def test_present_absent_and_refused_paths(tmp_path):
    """A file: True; nothing: False; a broken link names its target; a directory is refused by kind."""
    (tmp_path / "static.c3d").write_bytes(b"x")
    assert raw_file_present(tmp_path / "static.c3d") is True
    assert raw_file_present(tmp_path / "pert050-1.c3d") is False
    link = tmp_path / "walk-device.c3d"
    link.symlink_to(tmp_path / "elsewhere" / "walk.c3d")
    with pytest.raises(
        LoperInputError,
        match=rf"^{link}: the raw file of trial 'walk-device' is a broken link "
        rf"\(to '{tmp_path / 'elsewhere' / 'walk.c3d'}'\)",
    ):
        raw_file_present(link, "raw file of trial 'walk-device'")
    (tmp_path / "pert050-1.mat").mkdir()
    with pytest.raises(
        LoperInputError, match=r"pert050-1.mat: the raw file is a directory; a trial's raw file must be"
    ):
        raw_file_present(tmp_path / "pert050-1.mat")


def test_files_matching_no_trial_are_listed_sorted(tmp_path):
    """Raw suffixes only (any case), sorted; a trial's own files and other files are not listed."""
    assert RAW_SUFFIXES == (".c3d", ".loper.tsv", ".mat")
    for name in ("static.c3d", "walk-device.loper.tsv", "pert050-1.mat", "walk-fast.c3d", "B.MAT", "notes.txt"):
        (tmp_path / name).write_bytes(b"x")
    assert unmatched_raw_files(tmp_path, TRIALS) == ["B.MAT", "walk-fast.c3d"]
    assert unmatched_raw_files(tmp_path / "absent", TRIALS) == []


def test_a_miscased_trial_file_is_refused_with_its_right_name(tmp_path):
    (tmp_path / "walk-device.LOPER.tsv").write_bytes(b"x")
    (tmp_path / "Other.C3D").write_bytes(b"x")  # no trial's name: not this check's business
    with pytest.raises(
        LoperInputError,
        match=rf"^{tmp_path / 'walk-device.LOPER.tsv'}: the raw file of trial 'walk-device' is named "
        r"'walk-device.LOPER.tsv'; .* rename it 'walk-device.loper.tsv'",
    ):
        refuse_miscased_raw_files(tmp_path, TRIALS)
    refuse_miscased_raw_files(tmp_path / "absent", TRIALS)


def test_checksum_is_sha256_and_follows_a_copy_that_keeps_the_time(tmp_path):
    """SHA-256 of b"abc"; new content written back with the old modification time gives the new checksum."""
    path = tmp_path / "static.c3d"
    path.write_bytes(b"abc")
    assert content_checksum(path) == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
    st = os.stat(path)
    path.write_bytes(b"abd")
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert content_checksum(path) == hashlib.sha256(b"abd").hexdigest()
