"""A subject ID too long for the file names built from it is refused by the subject sheet's check before any job,
naming the sheet, the row, the ID's length and the limit; the limit follows from the file patterns.

A name holds at most 255 bytes; the longest name built from an ID is the staging directory of a subject's log
profile, ``.{subject}.log.prof.XXXXXXXX.partial``: 27 characters beside the ID, so an ID holds at most 228.
"""

from __future__ import annotations

import errno
import hashlib
import re
from pathlib import Path

import pytest
import yaml

from loper_analysis.io.atomic import staged
from loper_analysis.layout import fill
from loper_analysis.study_checks import (
    NAME_MAX,
    PROFILE_SUFFIX,
    SUBJECT_LOG_KEYS,
    subject_file_names,
    subject_id_limit,
)

ROOT = Path(__file__).resolve().parents[2]
HEADER = "subject\tsource\tsex\tage_yr\theight_m\tmass_kg\n"


def subject_id(length: int) -> str:
    """A subject ID of ``length`` characters without a repeated tail (Snakemake refuses periodic wildcards)."""
    digits = "".join(hashlib.sha256(str(k).encode()).hexdigest() for k in range(length // 64 + 1))
    return ("S" + digits)[:length]


def test_the_limit_follows_from_every_name_built_from_an_id(tmp_path):
    limit, longest = subject_id_limit()
    assert (limit, longest) == (228, ".{subject}.log.prof.XXXXXXXX.partial")
    names = subject_file_names()
    assert {"{subject}", "{subject}.log", "{subject}.tsv", "{subject}.log.prof", longest} <= set(names)
    for name in names:  # every name with the longest ID fits; one more character and the longest does not
        assert len(fill(name, subject="a" * limit).encode()) <= NAME_MAX, name
    assert len(fill(longest, subject="a" * (limit + 1)).encode()) == NAME_MAX + 1
    # the file system agrees: the longest name is created with the limit, and refused one character past it
    (tmp_path / fill(longest, subject="a" * limit)).mkdir()
    with pytest.raises(OSError) as err:
        (tmp_path / fill(longest, subject="a" * (limit + 1))).mkdir()
    assert err.value.errno == errno.ENAMETOOLONG
    # the staging directory is what the writer creates beside its target
    target = tmp_path / "t" / fill("{subject}.log.prof", subject="a" * limit)
    with staged(target) as tmp:
        stage = tmp.parent.name
        tmp.write_text("x")
    assert re.fullmatch(re.escape(f".{target.name}.") + r".{8}" + re.escape(".partial"), stage)
    assert target.read_text() == "x"


def test_every_log_and_benchmark_key_of_the_rules_is_counted():
    keys = set()
    for rules in [ROOT / "Snakefile", *sorted((ROOT / "workflow" / "rules").glob("*.smk"))]:
        keys |= set(re.findall(r'PATHS\.(?:log|benchmark)\(\s*"[^"]*",\s*(f?"[^"]*")', rules.read_text()))
    with_subject = {k for k in keys if "subject" in k}
    assert with_subject and {k.strip('"') for k in with_subject} <= set(SUBJECT_LOG_KEYS), with_subject
    assert 'prof = f"{path}' + PROFILE_SUFFIX + '"' in (ROOT / "src/loper_analysis/stages/logs.py").read_text()


def test_the_subject_schema_holds_the_same_limit():
    schema = yaml.safe_load((ROOT / "workflow/schemas/subjects.schema.yaml").read_text())
    assert schema["properties"]["subject"]["maxLength"] == subject_id_limit()[0]


def test_a_300_character_id_stops_the_workflow_before_any_job(tmp_path):
    from tests.workflow_copy import copy_workflow, snakemake

    copy_workflow(tmp_path)
    long_id = subject_id(300)
    (tmp_path / "config" / "subjects.tsv").write_text(
        HEADER + "P01\tsynthetic\tfemale\t25\t1.65\t60.0\n" + f"{long_id}\tsynthetic\tmale\t30\t1.80\t75.0\n"
    )
    cfg = yaml.safe_load((tmp_path / "config" / "config.yaml").read_text())
    cfg["device"]["subject"] = "P01"
    (tmp_path / "config" / "config.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False))
    earlier = tmp_path / "results" / "strides" / "summary.tsv"
    earlier.parent.mkdir(parents=True)
    earlier.write_bytes(b"earlier result\n")
    before = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if ".snakemake" not in p.parts)
    res = snakemake(tmp_path, "-n")
    said = res.stdout + res.stderr
    assert res.returncode != 0, said[-2000:]
    assert (
        f"config/subjects.tsv: row 2, column 'subject': the subject ID '{long_id[:24]}...' is 300 "
        "characters long; at most 228 fit: a file name holds at most 255 bytes" in said
    ), said[-2000:]
    assert "File name too long" not in said
    after = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if ".snakemake" not in p.parts)
    assert after == before
    assert earlier.read_bytes() == b"earlier result\n"
    # the longest ID that fits goes through the dry run
    (tmp_path / "config" / "subjects.tsv").write_text(
        HEADER + "P01\tsynthetic\tfemale\t25\t1.65\t60.0\n" + f"{subject_id(228)}\tsynthetic\tmale\t30\t1.80\t75.0\n"
    )
    res = snakemake(tmp_path, "-n", "-q")
    assert res.returncode == 0, (res.stdout + res.stderr)[-2000:]
