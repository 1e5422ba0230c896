"""File steps of the report: the result tables in Markdown (``results/tables/tables.md``) and the front page of
the Snakemake report (``results/report/front_page.html``)."""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence

from ..io.atomic import PathLike, write_text
from ..io.readers import read_bytes, read_tsv

__all__ = ["markdown_tables", "software_versions", "front_page"]

log = logging.getLogger(__name__)


def markdown_tables(headings: Sequence[str], tsvs: Sequence[PathLike], out_md: PathLike) -> str:
    """Render every table (one TSV per heading, in order) into one Markdown file; an empty TSV says so."""
    from ..markdown import markdown_document

    sections = [(heading, str(path), read_tsv(path, "table")) for heading, path in zip(headings, tsvs, strict=True)]
    text = markdown_document(sections)
    write_text(out_md, text, "Markdown file")
    log.info("rendered %d tables", len(sections))
    return text


def software_versions() -> dict[str, str]:
    """Python and the installed version of every package of :data:`loper_analysis.front_page.SOFTWARE`."""
    import importlib.metadata
    import platform

    from ..front_page import SOFTWARE

    versions = {"Python": platform.python_version()}
    for label, distribution in SOFTWARE.items():
        try:
            versions[label] = importlib.metadata.version(distribution)
        except importlib.metadata.PackageNotFoundError:
            versions[label] = "not installed"
    return versions


def front_page(out_html: PathLike, device_tsv: PathLike | None, validation_tsv: PathLike, subjects: Mapping[str, str],
               trials: Mapping[str, Sequence[str]], settings: Mapping, impedance_tsv: PathLike | None = None,
               summary_tsv: PathLike | None = None, figure_png: PathLike | None = None,
               rmsd_tsv: PathLike | None = None, versions: Mapping[str, str] | None = None) -> str:
    """The front page of the report (:func:`loper_analysis.front_page.front_page_html`) from the result files.

    ``device_tsv``: ``results/device/summary.tsv`` (None: no device tests); ``validation_tsv``:
    ``results/validation/summary.tsv``; ``impedance_tsv``, ``summary_tsv`` and
    ``figure_png``: the impedance table, its across-subject summary and the
    main figure (None: the run had no perturbation trials); ``rmsd_tsv``: the
    transparency table (None: no subject walked both trials of the pair).
    ``subjects``: subject -> source; ``trials``: processed subject -> its
    walking trials; ``settings``: the keyword arguments of
    :class:`~loper_analysis.front_page.RunSettings`; ``versions``: software ->
    version (default :func:`software_versions`). The headline tables come
    from :mod:`loper_analysis.headline`. Writes ``out_html`` and returns the
    fragment.
    """
    import pandas

    from ..errors import LoperInputError
    from ..front_page import RunSettings, front_page_html
    from ..headline import (device_comparison, impedance_summary_ci, transparency_verdict, truth_recovery,
                            validation_verdict)

    if (impedance_tsv is None) != (summary_tsv is None):
        raise LoperInputError(f"front page: the impedance table ({impedance_tsv}) and its summary ({summary_tsv}) "
                              "come together")
    try:
        run = RunSettings(**settings)
    except TypeError as exc:
        raise LoperInputError(f"front page: settings: {exc}") from None
    summary = truth = status = figure = transparency = None
    if impedance_tsv is not None:
        table = read_tsv(impedance_tsv, "impedance table")
        summary = impedance_summary_ci(read_tsv(summary_tsv, "impedance summary"), str(summary_tsv))
        truth = truth_recovery(table, str(impedance_tsv))
        status = table["status"].value_counts(sort=False).to_dict() if "status" in table else {}
    if figure_png is not None:
        figure = read_bytes(figure_png, "figure")
    if rmsd_tsv is not None:
        transparency = transparency_verdict(read_tsv(rmsd_tsv, "transparency table"), str(rmsd_tsv))
    text = front_page_html(
        subjects, trials, run, software_versions() if versions is None else versions,
        device=(pandas.DataFrame() if device_tsv is None
                else device_comparison(read_tsv(device_tsv, "device summary"), str(device_tsv))),
        validation=validation_verdict(read_tsv(validation_tsv, "validation summary"), str(validation_tsv)),
        summary=summary, truth=truth, impedance_status=status, figure_png=figure, transparency=transparency,
    )
    write_text(out_html, text, "front page")
    log.info("front page: %d bytes (%d kB of figure)", len(text.encode()), len(figure or b"") // 1024)
    return text
