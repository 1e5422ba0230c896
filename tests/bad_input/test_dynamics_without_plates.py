"""A trial without force platforms asked for inverse dynamics: the run stops before any job with one line naming
the trial and why (the default study's synthetic subjects walk on belts recorded as one vertical force each),
and nothing is written."""

from __future__ import annotations

from tests.workflow_copy import copy_workflow, snakemake


def test_a_synthetic_trial_asked_for_inverse_dynamics_is_refused_naming_it(tmp_path):
    work = copy_workflow(tmp_path)
    run = snakemake(work, "-n", "results/dynamics/S01/walk-nodevice.cycles.tsv")
    assert run.returncode != 0
    said = run.stdout + run.stderr
    assert (
        "S01/walk-nodevice: no inverse dynamics: a synthetic subject's trials hold the belts' vertical forces only "
        "(no centre of pressure); results/dynamics/trials.tsv says which trials have it"
    ) in said
    assert not (work / "results").exists() and not (work / "data").exists()
