"""File steps of the report: the result tables in Markdown (``results/report/tables.md``), the front page of
the Snakemake report (``results/report/front_page.html``) and the report itself (``results/report.html``),
written beside its target and moved over it whole."""

from __future__ import annotations

import logging
import signal
import subprocess
import sys
import threading
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from loper_analysis.io.atomic import PathLike, write_text
from loper_analysis.io.readers import read_bytes, read_tsv
from loper_analysis.report.front_page_settings import FrontPageSettings

__all__ = [
    "markdown_tables",
    "software_versions",
    "FrontPageFiles",
    "front_page",
    "snakemake_report_command",
    "configfiles_given",
    "check_report_complete",
    "missing_results",
    "write_report",
]

log = logging.getLogger(__name__)


def markdown_tables(headings: Sequence[str], tsvs: Sequence[PathLike], out_md: PathLike) -> str:
    """Render every table (one TSV per heading, in order) into one Markdown file; an empty TSV says so."""
    from loper_analysis.report.markdown import markdown_document

    sections = [(heading, str(path), read_tsv(path, "table")) for heading, path in zip(headings, tsvs, strict=True)]
    text = markdown_document(sections)
    write_text(out_md, text, "Markdown file")
    log.info("rendered %d tables", len(sections))
    return text


def software_versions() -> dict[str, str]:
    """Python and the installed version of every package of :data:`loper_analysis.report.front_page.SOFTWARE`."""
    import importlib.metadata
    import platform

    from loper_analysis.report.front_page import SOFTWARE

    versions = {"Python": platform.python_version()}
    for label, distribution in SOFTWARE.items():
        try:
            versions[label] = importlib.metadata.version(distribution)
        except importlib.metadata.PackageNotFoundError:
            versions[label] = "not installed"
    return versions


@dataclass(frozen=True)
class FrontPageFiles:
    """The result files the front page reads.

    ``validation``: ``results/validation/summary.tsv`` (None: no validation study, a study without
    perturbation trials); ``device``: ``results/device/summary.tsv`` (None:
    no device tests); ``impedance``, ``summary`` and ``figure``: the impedance table, its across-subject
    summary and the main figure (None: the run had no perturbation trials; the table and its summary come
    together); ``calibration``: the calibration table of the truth verdicts
    (:data:`loper_analysis.report.calibration.CALIBRATION_COLUMNS`; None: none named, or no synthetic subject);
    ``rmsd``: the transparency table (None: no subject walked both trials of the pair);
    ``strides``: the strides summary and ``quality`` the recorded subjects' scale reports, IK summaries,
    agreement tables and figures (named in :func:`front_page`'s ``recorded``).
    """

    validation: PathLike | None = None
    device: PathLike | None = None
    impedance: PathLike | None = None
    summary: PathLike | None = None
    figure: PathLike | None = None
    calibration: PathLike | None = None
    rmsd: PathLike | None = None
    strides: PathLike | None = None
    quality: Sequence[PathLike] = ()


def front_page(
    files: FrontPageFiles,
    out_html: PathLike,
    subjects: Mapping[str, str],
    trials: Mapping[str, Sequence[str]],
    settings: FrontPageSettings,
    versions: Mapping[str, str] | None = None,
    recorded: Mapping[str, Mapping] | None = None,
) -> str:
    """The front page of the report (:func:`loper_analysis.report.front_page.front_page_html`) from the result files.

    ``files``: the result tables and figure (:class:`FrontPageFiles`); ``subjects``: subject -> source;
    ``trials``: processed subject -> its walking trials; ``settings``: the run's settings
    (:class:`loper_analysis.report.front_page_settings.FrontPageSettings`); ``versions``: software -> version
    (default :func:`software_versions`);
    ``recorded``: recorded subject -> ``{"scale": path or None, "trials": {trial: {"ik", "agreement",
    "angles_png", "grf_png": path or None}}}``, the files of the section on recorded subjects
    (:func:`loper_analysis.report.subject_quality.recorded_subjects_html`).
    The headline tables come from :mod:`loper_analysis.report.headline`, the calibration run the truth verdicts
    rest on from :func:`loper_analysis.report.calibration.calibration_from_table` (compared with the run's design
    fingerprint, ``settings.design_fingerprint``). Writes ``out_html`` and returns the fragment.
    """
    import pandas

    from loper_analysis.errors import LoperInputError
    from loper_analysis.report.calibration import calibration_from_table
    from loper_analysis.report.front_page import front_page_html
    from loper_analysis.report.headline import (
        device_comparison,
        impedance_summary_ci,
        transparency_verdict,
        truth_recovery,
        validation_verdict,
    )

    impedance_tsv, summary_tsv, device_tsv = files.impedance, files.summary, files.device
    if (impedance_tsv is None) != (summary_tsv is None):
        raise LoperInputError(
            f"front page: the impedance table ({impedance_tsv}) and its summary ({summary_tsv}) come together"
        )
    summary = truth = status = figure = transparency = None
    if impedance_tsv is not None:
        table = read_tsv(impedance_tsv, "impedance table")
        summary = impedance_summary_ci(read_tsv(summary_tsv, "impedance summary"), str(summary_tsv))
        truth = truth_recovery(table, str(impedance_tsv))
        status = table["status"].value_counts(sort=False).to_dict() if "status" in table else {}
    if files.figure is not None:
        figure = read_bytes(files.figure, "figure")
    calibration = None
    if files.calibration is not None:
        text_cells = read_tsv(files.calibration, "calibration table", dtype=str, keep_default_na=False)
        calibration = calibration_from_table(text_cells, str(files.calibration))
    if files.rmsd is not None:
        transparency = transparency_verdict(read_tsv(files.rmsd, "transparency table"), str(files.rmsd))
    text = front_page_html(
        subjects,
        trials,
        settings.run,
        software_versions() if versions is None else versions,
        device=(
            pandas.DataFrame()
            if device_tsv is None
            else device_comparison(read_tsv(device_tsv, "device summary"), str(device_tsv))
        ),
        validation=(
            None
            if files.validation is None
            else validation_verdict(read_tsv(files.validation, "validation summary"), str(files.validation))
        ),
        summary=summary,
        truth=truth,
        impedance_status=status,
        figure_png=figure,
        transparency=transparency,
        recorded_html=_recorded_html(recorded or {}, files.strides),
        calibration=calibration,
        design_fingerprint=settings.design_fingerprint,
    )
    write_text(out_html, text, "front page")
    log.info("front page: %d bytes (%d kB of figure)", len(text.encode()), len(figure or b"") // 1024)
    return text


def _recorded_html(recorded: Mapping[str, Mapping], strides_tsv: PathLike | None) -> str:
    """The section on recorded subjects from their files (:func:`front_page`'s ``recorded``)."""
    from loper_analysis.report.subject_quality import SubjectQuality, TrialQuality, recorded_subjects_html

    if not recorded:
        return ""
    strides = None
    if strides_tsv is not None:
        strides = read_tsv(strides_tsv, "strides summary", ("subject", "trial"), keep_default_na=False, na_values=[""])
        strides = strides.set_index(["subject", "trial"])
    subjects = []
    for subject, entry in recorded.items():
        trials = []
        for trial, paths in entry["trials"].items():
            ik = read_tsv(paths["ik"], "IK summary", keep_default_na=False, na_values=[""]).iloc[0]
            row = None if strides is None or (subject, trial) not in strides.index else strides.loc[(subject, trial)]
            trials.append(
                TrialQuality(
                    trial,
                    ik,
                    read_tsv(paths["agreement"], "lab agreement"),
                    row,
                    None if paths.get("angles_png") is None else read_bytes(paths["angles_png"], "figure"),
                    None if paths.get("grf_png") is None else read_bytes(paths["grf_png"], "figure"),
                )
            )
        scale = entry.get("scale")
        table = None if scale is None else read_tsv(scale, "scale report", keep_default_na=False, na_values=[""])
        subjects.append(SubjectQuality(subject, table, trials))
    return recorded_subjects_html(subjects)


#: Bytes read from the end of a finished HTML report to find its closing tag.
_HTML_TAIL_BYTES = 256


def snakemake_report_command(snakemake_args: Sequence[str] = ()) -> Callable[[Path], list[str]]:
    """The command that writes the Snakemake report to a given path: ``python -m snakemake --report PATH ARGS``.

    The interpreter is this one (:data:`sys.executable`), so the report is
    made by the Snakemake installed beside this package. ``snakemake_args``
    (e.g. ``["--configfile", "my.yaml"]``) are passed on after the path.
    """
    extra = [str(a) for a in snakemake_args]
    return lambda path: [sys.executable, "-m", "snakemake", "--report", str(path), *extra]


def check_report_complete(path: PathLike, target: PathLike | None = None) -> None:
    """Refuse a report that is not whole: an empty file, an HTML file that does not end with ``</html>``, a
    ``.zip`` that is not a readable zip archive.

    ``target`` names the report in the message (default ``path``).

    Raises
    ------
    LoperInputError
        The report is missing, empty or cut short (the message names it and its size).
    """
    from loper_analysis.errors import LoperInputError

    path = Path(path)
    shown = path if target is None else target
    if not path.is_file():
        raise LoperInputError(f"{shown}: the report command wrote no file")
    size = path.stat().st_size
    if size == 0:
        raise LoperInputError(f"{shown}: the report command wrote an empty file")
    if path.suffix.lower() == ".zip":
        import zipfile

        try:
            with zipfile.ZipFile(path) as archive:
                broken = archive.testzip()
        except (zipfile.BadZipFile, OSError) as exc:
            raise LoperInputError(f"{shown}: the report ({size} bytes) is no complete zip archive: {exc}") from None
        if broken is not None:
            raise LoperInputError(f"{shown}: the report's zip archive has a damaged member {broken!r}")
        return
    with open(path, "rb") as f:
        f.seek(max(size - _HTML_TAIL_BYTES, 0))
        tail = f.read().rstrip()
    if not tail.lower().endswith(b"</html>"):
        raise LoperInputError(f"{shown}: the report ({size} bytes) does not end with </html>: it was cut short")


def _stop_on_sigterm(signum: int, frame) -> None:
    """SIGTERM as an exception, so that the staging directory is removed and the report command stopped."""
    raise SystemExit(f"stopped by {signal.Signals(signum).name}")


def configfiles_given(snakemake_args: Sequence[str]) -> list[str]:
    """The files given with ``--configfile``/``--configfiles`` (one or more each, or ``--configfile=FILE``)."""
    files, taking = [], False
    for arg in map(str, snakemake_args):
        name, eq, value = arg.partition("=")
        if name in ("--configfile", "--configfiles"):
            taking = not eq
            if eq:
                files.append(value)
        elif taking and not arg.startswith("-"):
            files.append(arg)
        else:
            taking = False
    return files


#: Result files named in the message when the workflow has not built them all.
_MISSING_SHOWN = 3


def missing_results(snakemake_args: Sequence[str] = (), cwd: PathLike | None = None) -> list[str]:
    """The workflow's result files not built yet, in Snakemake's order: the rows of
    ``python -m snakemake --summary ARGS`` (run in ``cwd``) whose status is ``missing`` (temporary files the
    run removed are not). Empty when the summary cannot be made: the report command then says why."""
    argv = [sys.executable, "-m", "snakemake", "--summary", *(str(a) for a in snakemake_args)]
    run = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, check=False)
    if run.returncode != 0:
        return []
    rows = [line.split("\t") for line in run.stdout.splitlines()]
    if not rows or rows[0][:1] != ["output_file"] or "status" not in rows[0]:
        return []
    status = rows[0].index("status")
    return [row[0] for row in rows[1:] if len(row) > status and row[status] == "missing"]


def _require_results(target: Path, snakemake_args: Sequence[str], cwd: PathLike | None, kept: str) -> None:
    """Stop, naming the first missing result files and the command that builds them, before a report on a
    workflow that has not run to the end (Snakemake's own message names one file and no remedy)."""
    from loper_analysis.errors import LoperInputError

    missing = missing_results(snakemake_args, cwd)
    if not missing:
        return
    shown = ", ".join(missing[:_MISSING_SHOWN]) + (", ..." if len(missing) > _MISSING_SHOWN else "")
    configs = "".join(f" --configfile {path}" for path in configfiles_given(snakemake_args))
    raise LoperInputError(
        f"{target}: the workflow has not built {len(missing)} of its result files ({shown}): "
        f"run the whole workflow first (snakemake -j2{configs}), then the report again: {kept}"
    )


def write_report(
    target: PathLike,
    command: Callable[[Path], Sequence[str]] | None = None,
    snakemake_args: Sequence[str] = (),
    cwd: PathLike | None = None,
) -> Path:
    """Write the Snakemake report beside ``target`` and move it over ``target`` only when it is complete.

    ``command(path)`` is the command line that writes the report to ``path``
    (default :func:`snakemake_report_command` of ``snakemake_args``); it runs
    in ``cwd`` (default: the working directory) with this process's standard
    output and error, and ``path`` is a temporary file with ``target``'s own
    name in a hidden directory beside ``target``
    (:func:`loper_analysis.io.atomic.staged`: Snakemake picks the report's
    format, HTML or zip, from that name). When the command succeeds and its
    file is complete (:func:`check_report_complete`) the file is moved over
    ``target`` with :func:`os.replace`; otherwise (a failed command, a
    truncated file, an interruption, SIGTERM) the previous report stays
    byte for byte and the temporary file is removed. Returns ``target``.
    Config files among ``snakemake_args`` are checked first
    (:func:`loper_analysis.schema.check_yaml_file`): Snakemake's own message
    for a syntax error names neither the file nor the line. Then the workflow's
    result files must all be there (:func:`missing_results`): after building one
    subject's targets only, the message names the first missing files and the
    command that builds them (``snakemake -j2`` with the same config files).

    Raises
    ------
    LoperInputError
        A config file given in ``snakemake_args`` does not parse; result files
        of the workflow are missing; the command
        failed (its exit status is named), wrote no file or an incomplete one;
        the report cannot be moved into place.
    """
    from loper_analysis.errors import LoperInputError
    from loper_analysis.io.atomic import staged
    from loper_analysis.schema import check_yaml_file

    target = Path(target)
    kept = "the previous report is kept" if target.exists() else "no report was written"
    if command is None:
        for path in configfiles_given(snakemake_args):
            check_yaml_file(Path(cwd or ".") / path)
        _require_results(target, snakemake_args, cwd, kept)
        command = snakemake_report_command(snakemake_args)
    main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _stop_on_sigterm) if main_thread else None
    try:
        with staged(target, "report") as tmp:
            argv = [str(a) for a in command(tmp if cwd is None else tmp.resolve())]
            status = subprocess.run(argv, cwd=cwd).returncode  # the command is killed if this raises
            if status != 0:
                raise LoperInputError(
                    f"{target}: the report command failed with exit status {status} (its messages are above): {kept}"
                )
            try:
                check_report_complete(tmp, target)
            except LoperInputError as exc:
                raise LoperInputError(f"{exc}: {kept}") from None
    finally:
        if main_thread:
            signal.signal(signal.SIGTERM, previous)
    log.info("%s: report written (%d bytes)", target, target.stat().st_size)
    return target


def run_warnings(strides_summary: PathLike, scale_reports: Sequence[PathLike] = ()) -> list[str]:
    """The warnings a finished run leaves in its tables, one line each, for the console: each trial's warnings
    and a status other than ``ok`` (``results/strides/summary.tsv``), each scaling's warnings (the scale
    reports). Tables not (yet) there are skipped."""
    lines = []
    for path in scale_reports:
        if Path(path).is_file():
            report = read_tsv(path, "scale report", keep_default_na=False)
            if "kind" in report:
                lines += [f"{path}: {text}" for text in report.loc[report["kind"] == "warning", "source"]]
    if Path(strides_summary).is_file():
        table = read_tsv(strides_summary, "strides summary", keep_default_na=False)
        for row in table.to_dict("records"):
            said = [str(row.get("status", "ok"))] if str(row.get("status", "ok")) != "ok" else []
            said += [str(row["warnings"])] if str(row.get("warnings", "")) else []
            if said:
                lines.append(f"{row['subject']} {row['trial']}: {'; '.join(said)}")
    return lines
