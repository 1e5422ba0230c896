# loper-analysis: swing-phase joint impedance from LOPER perturbation experiments.
import os

from snakemake.utils import min_version

min_version("9.0")


# Every config file read before Snakemake's loader builds its values (which runs a YTE template's expressions as
# Python): a syntax error or a key given twice as one line naming the file, line and column (Snakemake's own message
# names neither, and YAML keeps a repeated key's second value silently); a YTE template (__use_yte__), a Python tag
# (!!python/object...) or an alias bomb refused, naming the file and the construct. This stands before the
# configfile: directive, so config/config.yaml is judged before Snakemake reads it. Files given with --configfile
# are read by Snakemake 9 while it parses its command line, before this runs: a template among them has been
# rendered by then, and is refused here all the same, before any rule or job.
from snakemake.exceptions import WorkflowError

from loper_analysis.errors import LoperInputError
from loper_analysis.schema import check_yaml_file
from loper_analysis.stages import STAGES, all_targets

try:
    for _file in ["config/config.yaml", *map(str, workflow.config_settings.configfiles)]:
        if os.path.exists(_file):  # a missing file: Snakemake's own message
            _relative = os.path.relpath(_file)
            check_yaml_file(_file if _relative.startswith("..") else _relative)
except LoperInputError as exc:
    raise WorkflowError(str(exc)) from None


# the package's bytecode, once, before any job (each job of a package without it compiles it again, about 0.5 s);
# up to date in a few milliseconds, and nothing where the package's folder is not writable
import compileall
import loper_analysis

try:
    compileall.compile_dir(os.path.dirname(loper_analysis.__file__), quiet=2)
except OSError:
    pass


configfile: "config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/inputs.smk"


# every stage's rules, in the order of the workflow's graph (loper_analysis.stages.STAGES)
for _stage in STAGES:

    include: _stage.rule_file


rule all:
    default_target: True
    input:
        all_targets(STUDY),
