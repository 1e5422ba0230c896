# loper-analysis: swing-phase joint impedance from LOPER perturbation experiments.
from snakemake.utils import min_version

min_version("9.0")


configfile: "config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/validation.smk"
include: "workflow/rules/device.smk"
include: "workflow/rules/processing.smk"
include: "workflow/rules/synthetic.smk"
include: "workflow/rules/impedance.smk"
include: "workflow/rules/planning.smk"
include: "workflow/rules/report.smk"


rule all:
    input:
        all_targets(),
    default_target: True
