"""Config and subject-sheet checks against the workflow's schemas."""

from pathlib import Path

import pandas as pd
import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.schema import check_config, check_table, config_origin

ROOT = Path(__file__).resolve().parents[1]
CONFIG_SCHEMA = ROOT / "workflow/schemas/config.schema.yaml"
SUBJECT_SCHEMA = ROOT / "workflow/schemas/subjects.schema.yaml"


def _config() -> dict:
    return yaml.safe_load((ROOT / "config/config.yaml").read_text())


def test_shipped_config_and_sheet_are_valid():
    check_config(_config(), CONFIG_SCHEMA)
    sheet = pd.read_csv(ROOT / "config/subjects.tsv", sep="\t", dtype={"subject": str})
    check_table(sheet, SUBJECT_SCHEMA, "subjects.tsv")
    assert len(sheet) >= 1


@pytest.mark.parametrize(
    ("section", "key", "value", "words"),
    [
        ("impedance", "n_starts", 0, ["impedance.n_starts", "0"]),
        ("impedance", "n_starts", "ten", ["impedance.n_starts", "'ten'"]),
        ("validation", "noise_peak_to_peak", -0.01, ["validation.noise_peak_to_peak", "-0.01"]),
        ("validation", "colour", "red", ["validation", "colour"]),
    ],
)
def test_bad_config_names_key_and_value(section, key, value, words):
    cfg = _config()
    cfg[section][key] = value
    with pytest.raises(LoperInputError) as info:
        check_config(cfg, CONFIG_SCHEMA, "config.yaml")
    for w in words:
        assert w in str(info.value), str(info.value)


def test_unknown_key_is_named_by_its_full_path():
    cfg = _config()
    cfg["impedance"]["n_stars"] = 3
    with pytest.raises(LoperInputError, match=r"^config.yaml: key 'impedance.n_stars': .*'n_stars' was unexpected"):
        check_config(cfg, CONFIG_SCHEMA, "config.yaml")


@pytest.mark.parametrize(
    ("key_path", "origin"),
    [
        (["seed"], "--config"),  # the command line wins over every file
        (["impedance", "n_starts"], "late.yaml"),  # the last --configfile wins over an earlier one
        (["impedance", "tolerance"], "early.yaml"),
        (["study", "perturbation_onsets_ms", 1], "early.yaml"),  # a list item
        (["study", "perturbation_onsets_ms", 5], "config/config.yaml"),  # beyond the list: nobody set it
        (["validation", "n_chunks"], "config/config.yaml"),
    ],
)
def test_config_origin_is_the_highest_layer_that_sets_the_key(key_path, origin):
    layers = [
        ("--config", {"seed": 3}),
        ("late.yaml", {"impedance": {"n_starts": 2}}),
        (
            "early.yaml",
            {"impedance": {"n_starts": 1, "tolerance": 1e-6}, "study": {"perturbation_onsets_ms": [50, 175]}},
        ),
    ]
    assert config_origin(key_path, layers, "config/config.yaml") == origin


@pytest.mark.parametrize(
    ("layers", "expected"),
    [
        ([("--config", {"impedance": {"n_starts": "ten"}})], "--config: key 'impedance.n_starts': 'ten'"),
        (
            [("--config", {"seed": 1}), ("lab.yaml", {"impedance": {"n_starts": "ten"}})],
            "lab.yaml: key 'impedance.n_starts': 'ten'",
        ),
        ([("lab.yaml", {"seed": 1})], "config/config.yaml: key 'impedance.n_starts': 'ten'"),
    ],
)
def test_bad_value_names_the_layer_that_set_it(layers, expected):
    cfg = _config()
    cfg["impedance"]["n_starts"] = "ten"
    with pytest.raises(LoperInputError) as info:
        check_config(cfg, CONFIG_SCHEMA, "config/config.yaml", layers)
    assert str(info.value).startswith(expected), str(info.value)


def test_unknown_key_names_the_layer_that_added_it():
    cfg = _config()
    cfg["validation"]["n_chunkz"] = 2
    with pytest.raises(LoperInputError, match=r"^extra.yaml: key 'validation.n_chunkz'"):
        check_config(cfg, CONFIG_SCHEMA, "config/config.yaml", [("extra.yaml", {"validation": {"n_chunkz": 2}})])


def test_missing_required_key():
    cfg = _config()
    del cfg["seed"]
    with pytest.raises(LoperInputError, match="'seed' is a required property"):
        check_config(cfg, CONFIG_SCHEMA)


@pytest.mark.parametrize(
    ("row", "words"),
    [
        ({"subject": "S 1", "source": "synthetic"}, ["row 2", "subject", "S 1"]),
        ({"subject": "S2", "source": "simulated"}, ["row 2", "source", "simulated"]),
        ({"subject": "S3", "source": "synthetic", "height_m": 3.0}, ["row 2", "height_m", "3.0"]),
    ],
)
def test_bad_subject_row_names_row_column_value(row, words):
    sheet = pd.DataFrame([{"subject": "S0", "source": "synthetic"}, row])
    with pytest.raises(LoperInputError) as info:
        check_table(sheet, SUBJECT_SCHEMA, "subjects.tsv")
    for w in words:
        assert w in str(info.value), str(info.value)
