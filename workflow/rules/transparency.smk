# Transparency of the device in minimal-impedance mode: RMSD with vs without it against ISV_ave.

from loper_analysis.stages.transparency.files import transparency_files


def transparency_inputs(wildcards) -> list[str]:
    """Every table of the transparency pairs."""
    return [path for files in transparency_files(STUDY).values() for path in dataclasses.astuple(files)]


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    transparency,


rule transparency:
    input:
        transparency_inputs,
    output:
        rmsd=report(
            PATHS.transparency.rmsd,
            caption="../report/transparency_rmsd.rst",
            category="Transparency",
            labels={"table": "RMSD vs ISV_ave"},
        ),
        force=report(
            PATHS.transparency.force,
            caption="../report/transparency_force.rst",
            category="Transparency",
            labels={"table": "interaction force"},
        ),
        figure=report(
            PATHS.transparency.figure,
            caption="../report/transparency_figure.rst",
            category="Transparency",
            labels={"figure": "gait cycle with and without LOPER"},
        ),
    log:
        PATHS.log("transparency", "transparency"),
    benchmark:
        PATHS.benchmark("transparency", "transparency")
    params:
        **settings_params(TRANSPARENCY_SETTINGS),
        files=transparency_files(STUDY),
    script:
        "../scripts/transparency.py"
