"""NaN and infinity are no setting: the schema's minimum and maximum let NaN through (every comparison with it is
false), so every number of the configuration and every numeric command option is held finite at start, naming the
key and the file (or the option)."""

from __future__ import annotations

import json

import pytest

from loper_analysis.cli import main
from loper_analysis.config_file import load_config
from loper_analysis.errors import LoperInputError
from tests.workflow_copy import ROOT, copy_workflow, snakemake

CONFIG = ROOT / "config" / "config.yaml"


@pytest.mark.parametrize(
    ("section", "key", "value"),
    [
        ("impedance", "min_vaf_pct", ".nan"),
        ("strides", "iqr_whisker", ".nan"),
        ("synthetic", "walking_duration_s", ".nan"),
        ("synthetic", "walking_duration_s", ".inf"),
        ("dynamics", "cutoff_hz", "-.inf"),
    ],
)
def test_a_nan_or_infinite_key_in_a_configfile_is_named_with_its_file(tmp_path, section, key, value):
    mine = tmp_path / "mine.yaml"
    mine.write_text(f"{section}:\n  {key}: {value}\n")
    with pytest.raises(LoperInputError, match=rf"mine.yaml: key '{section}.{key}': -?(nan|inf) is not a finite"):
        load_config([CONFIG, mine])


def test_nan_in_a_list_or_a_json_config_is_refused(tmp_path):
    mine = tmp_path / "mine.yaml"
    mine.write_text("markers:\n  extent_range_m: [0.1, .nan]\n")
    with pytest.raises(LoperInputError, match=r"mine.yaml: key 'markers.extent_range_m.1': nan is not a finite"):
        load_config([CONFIG, mine])  # not "reversed or empty"
    mine = tmp_path / "mine.json"
    mine.write_text('{"strides": {"iqr_whisker": NaN}}')
    with pytest.raises(LoperInputError, match=r"mine.json: key 'strides.iqr_whisker': nan is not a finite"):
        load_config([CONFIG, mine])
    with pytest.raises(LoperInputError, match=r"overrides: key 'seed': nan is not a finite"):
        load_config([CONFIG], {"seed": json.loads("NaN")})


def test_the_workflow_refuses_nan_from_a_configfile_or_the_command_line(tmp_path):
    work = copy_workflow(tmp_path)
    (work / "mine.yaml").write_text("identification:\n  min_vaf_pct: .nan\n")
    res = snakemake(work, "-n", "-q", "--configfile", "mine.yaml")
    said = res.stdout + res.stderr
    assert res.returncode == 1 and "mine.yaml: key 'impedance.min_vaf_pct': nan is not a finite" in said, said
    res = snakemake(work, "-n", "-q", "--config", "seed=nan")
    said = res.stdout + res.stderr
    assert res.returncode == 1 and "--config: key 'seed': nan is not a finite" in said, said


CLI = {
    "ik limit": (
        ["ik", "--model", "m.osim", "--markers", "t.c3d", "--out", "{d}/o.mot", "--max-marker-rms-m", "nan"],
        "--max-marker-rms-m nan",
    ),  # fmt: skip
    "ik start (no config key)": (
        ["ik", "--model", "m.osim", "--markers", "t.c3d", "--out", "{d}/o.mot", "--start", "nan"],
        "--start nan",
    ),  # fmt: skip
    "filter": (["markers", "t.c3d", "--out", "{d}/t.trc", "--cutoff-hz", "NaN"], "--cutoff-hz nan"),
    "planned pulse": (["plan", "--force-n", "inf"], "--force-n inf"),
    "subject mass": (["segments", "--height-m", "1.8", "--mass-kg=-inf", "--out", "{d}/s.tsv"], "--mass-kg -inf"),
    "grf threshold": (["grf", "t.c3d", "--out", "{d}/t.mot", "--threshold-n", "nan"], "--threshold-n nan"),
}


@pytest.mark.parametrize("case", sorted(CLI))
def test_a_nan_or_infinite_option_stops_naming_the_option(case, tmp_path, capsys):
    argv, shown = CLI[case]
    assert main([a.format(d=tmp_path) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"{shown}: not a finite number" in err, err
    assert list(tmp_path.iterdir()) == []
