# loper-analysis: swing-phase joint impedance from LOPER perturbation experiments.
import os

from snakemake.utils import min_version

min_version("9.0")


# A syntax error or a key given twice in a config file as one line naming the file, line and column (Snakemake's
# own message names neither, and YAML keeps a repeated key's second value silently). Files given with --configfile
# are read by Snakemake while it parses its command line, before this runs: their syntax is Snakemake's to judge,
# their repeated keys are checked here.
if os.path.exists("config/config.yaml"):  # a missing file: Snakemake's own message
    from snakemake.exceptions import WorkflowError

    from loper_analysis.errors import LoperInputError
    from loper_analysis.schema import check_yaml_file

    try:
        for _file in ["config/config.yaml", *map(str, workflow.config_settings.configfiles)]:
            _relative = os.path.relpath(_file)
            check_yaml_file(_file if _relative.startswith("..") else _relative)
    except LoperInputError as exc:
        raise WorkflowError(str(exc)) from None


configfile: "config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/inputs.smk"
include: "workflow/rules/synthetic.smk"
include: "workflow/rules/markers.smk"
include: "workflow/rules/model.smk"
include: "workflow/rules/ik.smk"
include: "workflow/rules/grf.smk"
include: "workflow/rules/events.smk"
include: "workflow/rules/strides.smk"
include: "workflow/rules/transparency.smk"
include: "workflow/rules/device.smk"
include: "workflow/rules/impedance.smk"
include: "workflow/rules/planning.smk"
include: "workflow/rules/validation.smk"
include: "workflow/rules/report.smk"


rule all:
    default_target: True
    input:
        STUDY.all_targets(),
