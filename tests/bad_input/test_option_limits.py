"""Every command option with a config counterpart is held to that key's limits (one schema for both), before any
work and naming the option, the value and the key."""

from __future__ import annotations

import pytest

from loper_analysis.cli import main
from loper_analysis.cli_checks import OPTION_KEYS

CASES = {
    "a planned pulse of 0 N": (["plan", "--force-n", "0"], "--force-n 0.0", "planning.pulse_force_n"),
    "a backward planned pulse": (["plan", "--force-n", "-40"], "--force-n -40.0", "planning.pulse_force_n"),
    "a 72 t subject": (
        ["segments", "--height-m", "1.8", "--mass-kg", "72000", "--out", "{d}/s.tsv"],
        "--mass-kg 72000.0",
        "mass_kg in subjects.schema.yaml",
    ),  # fmt: skip
    "a 4 m subject": (
        ["segments", "--height-m", "4", "--mass-kg", "72", "--out", "{d}/s.tsv"],
        "--height-m 4.0",
        "height_m",
    ),  # fmt: skip
    "a negative IK limit": (
        ["ik", "--model", "m.osim", "--markers", "t.c3d", "--out", "{d}/o.mot", "--max-marker-rms-m", "-1"],
        "--max-marker-rms-m -1.0",
        "ik.max_marker_rms_m",
    ),  # fmt: skip
    "a filter of order 12": (
        ["markers", "t.c3d", "--out", "{d}/t.trc", "--order", "12"],
        "--order 12",
        "markers.filter.order",
    ),  # fmt: skip
    "no starts": (
        ["validate", "--segments", "s.tsv", "--errors", "{d}/e.tsv", "--fits", "{d}/f.tsv", "--n-starts", "0"],
        "--n-starts 0",
        "impedance.n_starts",
    ),  # fmt: skip
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_an_option_past_its_keys_limits_stops_naming_option_value_and_key(case, tmp_path, capsys):
    argv, shown, key = CASES[case]
    assert main([a.format(d=tmp_path) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and shown in err and key in err, err
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_zero_switches_a_filter_off_and_every_mapped_key_exists(tmp_path, capsys):
    # markers.filter.cutoff_hz must exceed 0, but --cutoff-hz 0 switches the filter off: the missing file is what stops
    assert main(["markers", str(tmp_path / "t.c3d"), "--out", str(tmp_path / "t.trc"), "--cutoff-hz", "0"]) == 2
    assert "C3D file not found" in capsys.readouterr().err
    from loper_analysis.config_file import find_schema
    from loper_analysis.schema import check_value

    schema = find_schema()
    for command, options in OPTION_KEYS.items():
        for option, (which, key_path) in options.items():
            path = schema if which == "config" else schema.parent / "subjects.schema.yaml"
            with pytest.raises(Exception, match=r"the limits of"):
                check_value("not a number", path, key_path, f"{command} --{option}")
