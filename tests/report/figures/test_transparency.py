"""loper_analysis.report.figures.transparency: the transparency figure, written as a PNG."""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from loper_analysis.io.atomic import write_figure
from loper_analysis.report.figures.transparency import transparency_figure


def test_figure_writes_a_png(tmp_path):
    rng = np.random.default_rng(7)
    u = np.linspace(0, 1, 101)
    base = np.column_stack([0.4 * np.sin(2 * np.pi * u), 0.6 * np.sin(np.pi * u) ** 2, 0.1 * np.cos(2 * np.pi * u)])
    angles = {
        "no_device": base + rng.normal(0, 0.02, (12, 101, 3)),
        "device": base + 0.01 + rng.normal(0, 0.02, (10, 101, 3)),
    }
    force = 5 * np.sin(2 * np.pi * u) + rng.normal(0, 1, (10, 101))
    fig = transparency_figure(angles, force, toe_off_pct={"no_device": 61.0, "device": 62.5}, title="S01")
    assert isinstance(fig, Figure)
    out = tmp_path / "transparency.png"
    write_figure(fig, out)
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
    assert [p.name for p in tmp_path.iterdir()] == ["transparency.png"]  # no temporary left behind
    assert not plt.fignum_exists(fig.number)  # write_figure closes it
