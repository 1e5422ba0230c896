# Transparency of the device in minimal-impedance mode: RMSD with vs without it against ISV_ave.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    transparency,


rule transparency:
    input:
        transparency_inputs,
    output:
        rmsd=report(
            "results/transparency/rmsd.tsv",
            caption="../report/transparency_rmsd.rst",
            category="Transparency",
            labels={"table": "RMSD vs ISV_ave"},
        ),
        force=report(
            "results/transparency/force.tsv",
            caption="../report/transparency_force.rst",
            category="Transparency",
            labels={"table": "interaction force"},
        ),
        figure=report(
            "results/transparency/transparency.png",
            caption="../report/transparency_figure.rst",
            category="Transparency",
            labels={"figure": "gait cycle with and without LOPER"},
        ),
    log:
        "results/logs/transparency/transparency.log",
    benchmark:
        "results/benchmarks/transparency/transparency.tsv"
    params:
        **settings_params(TRANSPARENCY_SETTINGS),
        files=transparency_files(),
    script:
        "../scripts/transparency.py"
