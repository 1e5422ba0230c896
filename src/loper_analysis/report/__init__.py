"""The report: headline tables, figures and the front page (the ``report`` stage).

* :mod:`.headline` - impedance with confidence intervals, truth recovery and verdicts, as tables;
* :mod:`.markdown` - Markdown renderings of the result tables;
* :mod:`.figures` - every figure of the pipeline (matplotlib);
* :mod:`.front_page` - the front page of the Snakemake report.
"""
