# Transparency of the device in minimal-impedance mode: RMSD with vs without it against ISV_ave.

from loper_analysis.stages.transparency.files import transparency_files, transparency_inputs


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    transparency,


rule transparency:
    input:
        lambda wc: transparency_inputs(STUDY),
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
        **settings_params(SETTINGS["transparency"]),
        files=transparency_files(STUDY),
    script:
        "../scripts/transparency.py"
