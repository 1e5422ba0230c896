"""A lab's pair written by a MIPS (SGI) processor is good data: ``inspect`` reads it as it reads the lab's Intel
files and writes the same set-up, file for file, where ezc3d alone refuses the files ("MIPS processor type not
supported"). The MIPS files are the clinical lab's own (SYD: three plates, one foot across two), byte-swapped
by the converter of ``tests/io/test_c3d_byte_order.py``.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import ezc3d
import pytest

from tests.io.test_c3d_byte_order import mips_copy

DATA = Path(__file__).resolve().parents[1] / "data" / "c3d-parser" / "SYD"
TRIALS = ("static", "walk-nodevice")


def _inspect(work: Path, folder: str) -> subprocess.CompletedProcess:
    files = [f"data/raw/{folder}/{trial}.c3d" for trial in TRIALS]
    return subprocess.run(
        [str(Path(sys.executable).parent / "loper-analysis"), "inspect", *files, "--config-out",
         f"lab/{folder}/config.yaml"],
        cwd=work, capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip


def test_inspect_writes_the_same_set_up_for_a_mips_pair_as_for_its_intel_twin(tmp_path):
    for folder in ("intel", "mips"):
        (tmp_path / "data" / "raw" / folder).mkdir(parents=True)
    for trial in TRIALS:
        raw = (DATA / f"{trial}.c3d").read_bytes()
        (tmp_path / "data" / "raw" / "intel" / f"{trial}.c3d").write_bytes(raw)
        (tmp_path / "data" / "raw" / "mips" / f"{trial}.c3d").write_bytes(mips_copy(raw))
    with pytest.raises(RuntimeError, match="MIPS"):  # why the reader needs the Intel twin
        ezc3d.c3d(str(tmp_path / "data" / "raw" / "mips" / "static.c3d"))
    intel, mips = _inspect(tmp_path, "intel"), _inspect(tmp_path, "mips")
    assert intel.returncode == 0, intel.stdout[-2000:] + intel.stderr[-2000:]
    assert mips.returncode == 0, mips.stdout[-2000:] + mips.stderr[-2000:]
    assert mips.stdout.replace("mips", "intel") == intel.stdout
    written = sorted(p.name for p in (tmp_path / "lab" / "intel").iterdir())
    assert sorted(p.name for p in (tmp_path / "lab" / "mips").iterdir()) == written
    assert {"config.yaml", "marker_set.xml", "scale_setup.xml"} <= set(written)
    for name in written:
        ours = (tmp_path / "lab" / "mips" / name).read_bytes().replace(b"mips", b"intel")
        assert ours == (tmp_path / "lab" / "intel" / name).read_bytes(), name
