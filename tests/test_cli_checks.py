"""cli_checks.py: a command line that would write over its own input, or give an option outside its config key's
limits, is refused before any work (exact messages)."""

from __future__ import annotations

import os
import re

import pytest

from loper_analysis.cli_checks import check_option_limits, refuse_overwriting
from loper_analysis.cli_parser import SUBCOMMANDS, build_parser
from loper_analysis.errors import LoperInputError


@pytest.fixture(scope="module")
def parser():
    return build_parser(dict.fromkeys(SUBCOMMANDS, print))


def _refused(message: str):
    return pytest.raises(LoperInputError, match="^" + re.escape(message) + "$")


def test_an_output_over_an_input_or_another_output_is_refused(parser, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with _refused("t.c3d: --out would write over c3d t.c3d: nothing was done; give another output path"):
        refuse_overwriting(parser.parse_args(["markers", "t.c3d", "--out", "t.c3d"]))
    with _refused("sub/../e.tsv: --fits would write over --errors e.tsv: nothing was done; give another output path"):
        refuse_overwriting(
            parser.parse_args(["validate", "--segments", "s.tsv", "--errors", "e.tsv", "--fits", "./sub/../e.tsv"])
        )
    with _refused("b.yaml: --out would write over --configfile b.yaml: nothing was done; give another output path"):
        refuse_overwriting(parser.parse_args(["grf", "t.c3d", "--out", "b.yaml", "--configfile", "a.yaml", "b.yaml"]))
    assert refuse_overwriting(parser.parse_args(["markers", "t.c3d", "--out", "t.trc", "--gaps", "g.tsv"])) is None


def test_a_link_to_an_input_is_the_input(parser, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.c3d").write_bytes(b"x")
    os.link("t.c3d", "hard.trc")
    os.symlink("t.c3d", "soft.trc")
    for out in ("hard.trc", "soft.trc"):
        with _refused(f"{out}: --out would write over c3d t.c3d: nothing was done; give another output path"):
            refuse_overwriting(parser.parse_args(["markers", "t.c3d", "--out", out]))


@pytest.mark.parametrize(
    "argv, message",
    [
        (
            ["plan", "--force-n", "0"],
            "--force-n 0.0: 0.0 is less than or equal to the minimum of 0 "
            "(the limits of planning.pulse_force_n in config.schema.yaml)",
        ),
        (
            ["segments", "--height-m", "1.8", "--mass-kg", "400", "--out", "s.tsv"],
            "--mass-kg 400.0: 400.0 is greater than the maximum of 300 (the limits of mass_kg in subjects.schema.yaml)",
        ),
        (
            ["markers", "t.c3d", "--out", "t.trc", "--order", "12"],
            "--order 12: 12 is greater than the maximum of 8 (the limits of markers.filter.order in "
            "config.schema.yaml)",
        ),
        (
            ["validate", "--segments", "s", "--errors", "e", "--fits", "f", "--seed", "-1"],
            "--seed -1: -1 is less than the minimum of 0 (the limits of seed in config.schema.yaml)",
        ),
    ],
)
def test_an_option_past_its_keys_limits_names_option_value_and_key(parser, project, argv, message):
    with _refused(message):
        check_option_limits(parser.parse_args(argv))


def test_zero_switches_a_step_off_and_values_within_the_limits_pass(parser, project):
    for argv in (
        ["markers", "t.c3d", "--out", "t.trc", "--cutoff-hz", "0", "--order", "8"],
        ["scale", "--model", "m", "--setup", "s", "--static", "t", "--out", "o", "--max-motion-rms-m", "0"],
        ["plan", "--force-n", "40", "--strides", "10", "20"],
        ["inspect", "t.c3d"],  # a command without mapped options
    ):
        assert check_option_limits(parser.parse_args(argv)) is None
    # the same zero is refused where it switches nothing off
    with pytest.raises(LoperInputError, match=r"^--max-gap-frames -1: "):
        check_option_limits(parser.parse_args(["markers", "t.c3d", "--out", "t.trc", "--max-gap-frames", "-1"]))
    with pytest.raises(LoperInputError, match=r"^--duration-s 0\.0: "):
        check_option_limits(parser.parse_args(["plan", "--duration-s", "0"]))
