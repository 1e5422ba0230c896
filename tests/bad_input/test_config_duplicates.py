"""A key given twice in a config file: YAML keeps the second silently, replacing the first whole; the run stops
naming the file, the key and both lines."""

from __future__ import annotations

import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.schema import check_yaml_file
from tests.workflow_copy import copy_workflow, snakemake


def test_a_repeated_key_is_named_with_both_lines_at_any_depth(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text("seed: 1\nfilter:\n  cutoff_hz: 40.0\n  order: 4\n  cutoff_hz: 20.0\n")
    with pytest.raises(LoperInputError, match=r"key 'filter.cutoff_hz' is given twice .* line 3, column 3 and line 5"):
        check_yaml_file(path)
    path.write_text("seed: 1\nitems:\n  - {a: 1, a: 2}\n")
    with pytest.raises(LoperInputError, match=r"key 'items.0.a' is given twice"):
        check_yaml_file(path)
    path.write_text("seed: 1\nfilter: {cutoff_hz: 40.0}\n")
    check_yaml_file(path)  # no repeat: no error


def test_a_second_section_block_in_the_config_or_a_configfile_stops_the_run(tmp_path):
    copy_workflow(tmp_path)
    config = tmp_path / "config" / "config.yaml"
    original = config.read_text()
    config.write_text(original + "\ndynamics:\n  cutoff_hz: 20.0\n")
    res = snakemake(tmp_path, "-n", "-q")
    said = res.stdout + res.stderr
    assert res.returncode != 0 and "config/config.yaml: key 'dynamics' is given twice in the config file" in said
    config.write_text(original)
    (tmp_path / "mine.yaml").write_text("seed: 3\nseed: 4\n")
    res = snakemake(tmp_path, "-n", "-q", "--configfile", "mine.yaml")
    said = res.stdout + res.stderr
    assert res.returncode != 0 and "mine.yaml: key 'seed' is given twice" in said and "line 1, column 1" in said
