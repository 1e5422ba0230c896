"""A C3D whose last frames hold zero bytes only (an interrupted copy or export) is refused by the reader, naming
the file, the first zeroed frame, its time and the zeroed share of the trial; the steps and the command write
nothing and keep an earlier output; every real C3D of the repository reads as before (walking5's 57 first frames
without any marker included: their missing markers carry residual -1 and the analog channels their noise).

The damaged copies are a real trial (walking5, float data, 12 analog channels) with the last 40 % of its data
block's bytes set to 0, and a trial of our writer with its last 120 of 300 frames zeroed.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from loper_analysis.cli import main
from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.c3d_layout import zeroed_tail_frames
from loper_analysis.stages.markers.step import markers as markers_step
from tests.bad_input.test_c3d_guards import (
    N_FRAMES,
    RATE,
    WALKING5,
    WORDS,
    assert_refused_and_nothing_written,
    run_events,
    write_trial,
)

ROOT = Path(__file__).resolve().parents[2]
#: Every C3D of the repository: recordings of several labs and the examples' trials.
REAL_FILES = sorted((ROOT / "tests" / "data").rglob("*.c3d")) + sorted((ROOT / "examples").rglob("*.c3d"))


def data_block(path: Path) -> tuple[int, int]:
    """Byte offset of the data block (header word 9: its first 512-byte block) and its size to the file's end."""
    data = path.read_bytes()
    start = ((data[16] | data[17] << 8) - 1) * 512
    return start, len(data) - start


def zeroed_copy(path: Path, out: Path, first_byte: int) -> Path:
    """``path`` with every byte from ``first_byte`` on set to 0 (the file keeps its size)."""
    data = bytearray(path.read_bytes())
    data[first_byte:] = bytes(len(data) - first_byte)
    out.write_bytes(bytes(data))
    return out


@pytest.mark.parametrize("path", REAL_FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_real_file_reads(path):
    assert len(REAL_FILES) >= 15
    rec = read_c3d(path)
    assert np.isfinite(rec.markers_m).any()


def test_walking5_has_frames_without_any_marker_and_reads(tmp_path):
    """The rule is about zero bytes, not about missing markers: walking5's first 57 frames hold no marker."""
    rec = read_c3d(WALKING5)
    none = ~np.isfinite(rec.markers_m).any(axis=(1, 2))
    assert none[:57].all() and not none[57]
    start, _ = data_block(WALKING5)
    n_words = 4 * 40 + 12 * 8
    assert zeroed_tail_frames(WALKING5, start // 512 + 1, 1103, 4 * n_words) == 0


def test_real_trial_with_its_last_40_percent_zeroed_is_refused(tmp_path):
    start, size = data_block(WALKING5)
    frame_bytes = 4 * (4 * 40 + 12 * 8)  # 40 points, 12 channels x 8 samples a frame, 4-byte floats
    n_frames = 1103
    assert size - n_frames * frame_bytes in range(0, 512)  # the block and its padding
    cut = start + math.ceil(0.6 * n_frames * frame_bytes)
    bad = zeroed_copy(WALKING5, tmp_path / "walking5_zeroed.c3d", cut)
    first = math.ceil((cut - start) / frame_bytes) + 1  # the first frame whose every byte is 0
    zeroed = n_frames - first + 1
    assert (first, zeroed) == (663, 441)
    expected = (
        f"the last 441 of 1103 frames (40 % of the trial) hold zeros only, from frame 663 at {662 / 250:.3f} s on",
        "every marker at exactly (0, 0, 0), every analog sample 0",
        "likely an interrupted copy or export: the file's last 441 frames hold zeros",
    )
    with pytest.raises(LoperInputError) as err:
        read_c3d(bad)
    message = str(err.value)
    assert message.startswith(f"{bad}: "), message
    assert all(e in message for e in expected), message
    assert "2.648 s" in message
    assert_refused_and_nothing_written(markers_step, bad, tmp_path / "markers.trc", *expected)


def test_written_trial_with_its_last_frames_zeroed_is_refused_by_steps_and_command(tmp_path, capsys):
    good = write_trial(tmp_path / "trial.c3d")
    start, _ = data_block(good)
    assert read_c3d(good).markers_m.shape == (N_FRAMES, 2, 3)
    bad = zeroed_copy(good, tmp_path / "zeroed.c3d", start + 180 * WORDS * 4)
    expected = (
        f"the last 120 of {N_FRAMES} frames (40 % of the trial) hold zeros only, from frame 181 at "
        f"{180 / RATE:.3f} s on",
        "the file's last 120 frames hold zeros",
    )
    assert_refused_and_nothing_written(run_events, bad, tmp_path / "events.tsv", *expected)
    assert_refused_and_nothing_written(markers_step, bad, tmp_path / "markers.trc", *expected)
    assert main(["markers", str(bad), "--out", str(tmp_path / "cli_new.trc")]) == 2
    said = capsys.readouterr().err
    assert f"{bad}: the last 120 of {N_FRAMES} frames" in said and "interrupted copy or export" in said, said
    assert not (tmp_path / "cli_new.trc").exists()
    one = zeroed_copy(good, tmp_path / "one.c3d", start + (N_FRAMES - 1) * WORDS * 4)
    with pytest.raises(LoperInputError, match=r"the last 1 of 300 frames \(0.3 % of the trial\)"):
        read_c3d(one)
    # a zeroed part that ends before the last frame is another damage: not this guard's
    assert zeroed_tail_frames(good, start // 512 + 1, N_FRAMES, WORDS * 4) == 0
