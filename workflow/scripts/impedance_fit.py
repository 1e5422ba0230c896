from _logging import setup

from loper_analysis.impedance import fit_subject_onset

log = setup(snakemake.log[0])
inp, out, p = snakemake.input, snakemake.output, snakemake.params
trials = [
    {"name": t, "angles": inp[f"angles_{t}"], "strides": inp[f"strides_{t}"], "force": inp[f"force_{t}"],
     "markers": inp[f"markers_{t}"]}
    for t in p.trials
]
null_trials = [{"name": t, "angles": inp.get(f"null_angles_{t}", inp.get(f"angles_{t}")),
                "strides": inp.get(f"null_strides_{t}", inp.get(f"strides_{t}"))} for t in p.null_trials]
rows = fit_subject_onset(
    trials, inp.segments, int(snakemake.wildcards.onset), snakemake.wildcards.subject, out.response, out.counts,
    out.fit, out.curves, inp.get("truth"), null_trials=null_trials, **p.settings,
)
log.info("impedance:\n%s", rows.to_string(index=False))
