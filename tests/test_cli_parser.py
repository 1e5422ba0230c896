"""cli_parser.py: known command lines parse into known values (types, counts, defaults, handlers)."""

from __future__ import annotations

import pytest

from loper_analysis.cli_parser import SUBCOMMANDS, build_parser


def _handler(name: str):
    def handler(args) -> str:
        return name

    return handler


@pytest.fixture(scope="module")
def parser():
    return build_parser({name: _handler(name) for name in SUBCOMMANDS}, "the description")


def test_subcommands_in_help_order_each_with_its_handler(parser):
    assert SUBCOMMANDS == (
        "markers",
        "scale",
        "segments",
        "ik",
        "grf",
        "events",
        "plan",
        "validate",
        "report",
        "inspect",
    )
    assert parser.prog == "loper-analysis" and parser.description == "the description"
    minimal = {
        "markers": ["t.c3d", "--out", "t.trc"],
        "grf": ["t.c3d", "--out", "g.mot"],
        "events": ["t.c3d", "--out", "e.tsv"],
        "scale": ["--model", "m.osim", "--setup", "s.xml", "--static", "s.c3d", "--out", "o.osim"],
        "segments": ["--out", "s.tsv"],
        "ik": ["--model", "m.osim", "--markers", "t.c3d", "--out", "o.mot"],
        "validate": ["--segments", "s.tsv", "--errors", "e.tsv", "--fits", "f.tsv"],
        "plan": [],
        "inspect": ["t.c3d"],
        "report": ["r.html"],
    }
    for name in SUBCOMMANDS:
        args = parser.parse_args([name, *minimal[name]])
        assert args.command == name and args.func(args) == name and args.traceback is False


def test_markers_options_keep_their_types(parser):
    args = parser.parse_args(
        ["--traceback", "markers", "t.c3d", "--out", "t.trc", "--rotate-deg", "-90", "0", "180", "--cutoff-hz", "6.5"]
        + ["--order", "4", "--max-gap-frames", "10", "--walking-direction", "auto", "--configfile", "a.yaml", "b.yaml"]
    )
    assert args.traceback is True
    assert (args.c3d, args.out, args.gaps, args.label_map) == ("t.c3d", "t.trc", None, None)
    assert args.rotate_deg == [-90.0, 0.0, 180.0] and all(isinstance(a, float) for a in args.rotate_deg)
    assert (args.cutoff_hz, args.order, args.max_gap_frames) == (6.5, 4, 10)
    assert isinstance(args.order, int) and isinstance(args.cutoff_hz, float)
    assert args.walking_direction == "auto" and args.configfile == ["a.yaml", "b.yaml"]
    # no default stands in for the config's values
    args = parser.parse_args(["markers", "t.c3d", "--out", "t.trc"])
    assert (args.rotate_deg, args.cutoff_hz, args.order, args.max_gap_frames, args.walking_direction) == (None,) * 5


def test_events_feet_and_plates(parser):
    args = parser.parse_args(
        ["events", "t.c3d", "--out", "e.tsv", "--feet", "L.Heel", "R.Heel", "--plates", "left=1,right=2"]
        + ["--threshold-on-n", "30", "--threshold-off-n", "15", "--label-map", "map.tsv"]
    )
    assert args.feet == ["L.Heel", "R.Heel"] and args.plates == "left=1,right=2" and args.label_map == "map.tsv"
    assert (args.threshold_on_n, args.threshold_off_n) == (30.0, 15.0)


def test_scale_and_validate_defaults(parser):
    args = parser.parse_args(["scale", "--model", "m.osim", "--setup", "s.xml", "--static", "s.c3d", "--out", "o"])
    assert (args.cutoff_hz, args.mass_kg, args.end) == (0.0, None, None)
    args = parser.parse_args(["validate", "--segments", "s", "--errors", "e", "--fits", "f", "--n-starts", "3"])
    assert (args.chunk, args.n_chunks, args.n_starts, args.seed) == (0, None, 3, None)


def test_plan_lists_and_repeated_targets(parser):
    args = parser.parse_args(
        ["plan", "--strides", "10", "20", "--onset-ms", "0", "100.5", "--target", "hip", "D", "15"]
        + ["--target", "knee", "K", "20", "--impedance-values", "50", "3", "2", "0.1", "8", "0.3"]
        + ["--exclude-trials"]
    )
    assert args.strides == [10, 20] and args.onset_ms == [0.0, 100.5]
    assert args.target == [["hip", "D", "15"], ["knee", "K", "20"]] and args.target_half_width is None
    assert args.impedance_values == [50.0, 3.0, 2.0, 0.1, 8.0, 0.3]
    assert args.exclude_trials == [] and args.results == "results" and args.force_n is None


def test_segments_side_and_report_passes_the_rest_on(parser):
    args = parser.parse_args(["segments", "--model", "m.osim", "--side", "left", "--out", "s.tsv"])
    assert (args.model, args.side, args.height_m) == ("m.osim", "left", None)
    args = parser.parse_args(["report", "results/report.html", "--configfile", "my.yaml", "-j", "2"])
    assert args.target == "results/report.html" and args.snakemake_args == ["--configfile", "my.yaml", "-j", "2"]
    args = parser.parse_args(["inspect", "a.c3d", "b.c3d", "--model", "m.osim"])
    assert args.c3d == ["a.c3d", "b.c3d"] and args.model == "m.osim"


@pytest.mark.parametrize(
    "argv",
    [
        [],
        ["markers", "t.c3d"],  # --out is required
        ["segments", "--side", "middle", "--out", "s.tsv"],
        ["markers", "t.c3d", "--out", "t.trc", "--rotate-deg", "-90", "0"],
        ["markers", "t.c3d", "--out", "t.trc", "--order", "4.5"],
        ["markers", "t.c3d", "--out", "t.trc", "--walking-direction", "north"],
    ],
)
def test_malformed_command_lines_exit_with_status_2(parser, argv, capsys):
    with pytest.raises(SystemExit) as stop:
        parser.parse_args(argv)
    assert stop.value.code == 2
    assert "error:" in capsys.readouterr().err
