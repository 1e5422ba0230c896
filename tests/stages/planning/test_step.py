"""The planner's file step: what it checks before reading the pilot's files and what it refuses after, with
nothing written either way."""

from __future__ import annotations

import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import write_tsv
from loper_analysis.io.segment_table import write_segments
from loper_analysis.stages.planning.files import PilotFiles, PilotTrial
from loper_analysis.stages.planning.step import PlanningSettings, plan
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry

SETTINGS = PlanningSettings(onsets_ms=(50,), strides=(5, 10))


def _outputs(tmp_path):
    return {"out_tsv": tmp_path / "plan.tsv", "answers_out": tmp_path / "answers.txt"}


def test_the_request_is_checked_before_any_file_is_read(tmp_path):
    missing = PilotFiles({"walk-1": PilotTrial(tmp_path / "no.angles.tsv", tmp_path / "no.strides.tsv")}, "no.tsv")
    with pytest.raises(LoperInputError, match=r"^unplannable must be 'raise' or 'note', got 'skip'$"):
        plan(missing, "P01", SETTINGS, **_outputs(tmp_path), unplannable="skip")
    with pytest.raises(LoperInputError, match=r"^planning settings: no onsets \(onsets_ms\) to plan for$"):
        plan(missing, "P01", PlanningSettings(), **_outputs(tmp_path))
    with pytest.raises(LoperInputError, match=r"got 0$"):
        plan(missing, "P01", PlanningSettings(onsets_ms=(50,), strides=(0,)), **_outputs(tmp_path))
    with pytest.raises(LoperInputError, match=r"^pilot P01: no trial walked with the device: the null pairs need one$"):
        plan(PilotFiles({}, tmp_path / "no.tsv"), "P01", SETTINGS, **_outputs(tmp_path))
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_plan_without_the_planned_impedance_is_refused_after_reading_the_pilot(tmp_path):
    write_segments(segment_parameters_from_anthropometry(1.73, 64.9), tmp_path / "segments.tsv")
    write_tsv(pd.DataFrame({"time_s": [0.0, 0.0078125]}), tmp_path / "walk.angles.tsv")
    write_tsv(pd.DataFrame({"stride": [0]}), tmp_path / "walk.strides.tsv")
    files = PilotFiles({"walk-1": PilotTrial(tmp_path / "walk.angles.tsv", tmp_path / "walk.strides.tsv")},
                       tmp_path / "segments.tsv")  # fmt: skip
    with pytest.raises(LoperInputError, match=r"^planned impedance: give the pilot's impedance rows or the values$"):
        plan(files, "P01", SETTINGS, **_outputs(tmp_path))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["segments.tsv", "walk.angles.tsv", "walk.strides.tsv"]
