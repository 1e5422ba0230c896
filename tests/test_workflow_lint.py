"""Snakemake's linter on the workflow: nothing to say but its request for a conda environment or container per rule
(the project installs with pip by design: requirements.txt)."""

from __future__ import annotations

import re

import pytest

from tests.workflow_copy import snakemake

pytestmark = pytest.mark.slow  # parses the whole workflow (a few seconds)

#: The one lint the project keeps: it installs with pip, not with a conda environment per rule.
KEPT = "Specify a conda environment or container for each rule."


def test_the_linter_only_asks_for_conda_environments(workflow_dir):
    res = snakemake(workflow_dir, "--lint", timeout=300)
    lints = re.findall(r"^\s+\* (.+?):?$", res.stdout + res.stderr, re.MULTILINE)
    assert lints, res.stdout[-2000:] + res.stderr[-2000:]  # the linter ran and said something
    assert {lint.rstrip(":") for lint in lints} == {KEPT}, sorted(set(lints))
