"""Write a :class:`~stochpound.report.render._document.Report` to a folder: figures, tables, HTML page, PDF.

Layout of the folder::

    figures/<key>.png   every figure (the same bytes are embedded in index.html)
    tables/<key>.csv    every table's numbers (not rounded)
    index.html          the self-contained page (stochpound.report.render._html)
    report.pdf          the A4 document (stochpound.report.render._pdf)
    .stochpound-report.json   the figure and table files this build wrote

Every file is written to a temporary name and then renamed, so an
interrupted build never leaves a half-written file. A build into a folder
that holds an earlier one removes the earlier figures and tables it does not
write again: only files the earlier build's list names, never another file.
A folder without that list is not an earlier build's: a file there that the
build would write (a user's ``index.html``, say) is refused, not replaced.
"""

from __future__ import annotations

import datetime
import io
import json
import re
from pathlib import Path
from typing import Callable, Sequence

import matplotlib.pyplot as plt

from stochpound._atomic import check_not_input, check_writable
from stochpound._atomic import replacing as _replacing  # a full disk is reported naming the file
from stochpound.report.render._document import Report
from stochpound.report.render._html import render_html
from stochpound.report.render._pdf import render_pdf

FORMATS = ("html", "pdf")
FILE_NAMES = {"html": "index.html", "pdf": "report.pdf"}
FIGURE_DPI = 130
KEY = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]*")
MANIFEST = ".stochpound-report.json"
"""The list of figure and table files (relative paths) the last build wrote into its folder."""
_OWNED = re.compile(r"(figures/[A-Za-z0-9][A-Za-z0-9._-]*\.png|tables/[A-Za-z0-9][A-Za-z0-9._-]*\.csv)")
"""The only paths a list may name for removal (no other folder, no other kind of file)."""

Progress = Callable[[str], None]


def write_report(
    report: Report, out: Path, formats: Sequence[str] = FORMATS, progress: Progress | None = None
) -> dict[str, Path]:
    """Write ``report`` into the folder ``out`` (created if needed).

    Parameters
    ----------
    report : Report
        The report; its figures are closed afterwards.
    out : pathlib.Path
        The output folder.
    formats : sequence of str
        Any of ``"html"`` (``index.html``) and ``"pdf"`` (``report.pdf``).
    progress : callable, optional
        Called with a short message at each step (e.g. ``"figures 3/25"``).

    Returns
    -------
    dict of str to pathlib.Path
        The written document by format, and the ``"figures"`` and ``"tables"`` folders.

    Raises
    ------
    ValueError
        For an unknown format (the message names ``--format`` and the allowed
        values), table/figure keys that are duplicated or unusable as file names,
        or a file in ``out`` that the build would replace but no earlier build wrote.
    """
    formats = _check_formats(formats)
    _check_keys(report)
    say = progress or (lambda message: None)
    out = Path(out)
    date = datetime.date.today()
    written = {"figures": out / "figures", "tables": out / "tables"}
    owned = [f"figures/{item.key}.png" for item in report.figures()] + [f"tables/{table.key}.csv" for table in report.tables()]
    previous = _claim(out, owned, [FILE_NAMES[name] for name in formats])
    try:
        figure_png = _write_figures(report, written["figures"], say)
        _write_tables(report, written["tables"], say)
        _replace_owned(out, previous, owned, [FILE_NAMES[name] for name in formats])
        if "html" in formats:
            say(FILE_NAMES["html"])
            written["html"] = _replace(out / FILE_NAMES["html"], render_html(report, figure_png, date).encode("utf-8"))
        if "pdf" in formats:
            say(f"{FILE_NAMES['pdf']} (drawing pages)")
            with _replacing(out / FILE_NAMES["pdf"]) as temporary:
                pages = render_pdf(report, temporary, date)
            say(f"{FILE_NAMES['pdf']}: {pages} pages")
            written["pdf"] = out / FILE_NAMES["pdf"]
    finally:
        for item in report.figures():
            plt.close(item.figure)
    return written


def check_output_folder(out: Path, stores: Sequence[Path] = ()) -> None:
    """Raise the ``OSError`` that writing into the folder ``out`` would raise (it is created if needed), before any work.

    Also a ``ValueError`` if one of the ``stores`` the report reads is a file the build would write.
    """
    out = Path(out)
    for store in stores:
        for name in (*FILE_NAMES.values(), MANIFEST):
            check_not_input(out / name, [(store, "a store of this report")], "--out")
        if Path(store).resolve().parent in ((out / "figures").resolve(), (out / "tables").resolve()):
            raise ValueError(f"{store}: a store of this report, in the folder the report writes its figures and tables to: give --out another folder")
    check_writable(out / MANIFEST)


def _claim(out: Path, owned: list[str], documents: list[str]) -> list | None:
    """Before any file is written: refuse a file the build would replace in a folder of no earlier build; list this build's files beside an earlier build's.

    The list is written first, so that a build interrupted midway leaves a folder
    whose files a later build recognises as its own. Returns the earlier build's
    list (None: no earlier build), as it was before.
    """
    previous = _previous(out)
    if previous is None:
        for name in [*owned, *documents]:
            if (out / name).exists():
                raise ValueError(f"{out / name}: exists, and {out} holds no earlier report ({MANIFEST}): give --out a new or empty folder "
                                 "(or one of an earlier report), or move the file")
    listed = {name for name in previous or [] if isinstance(name, str) and _OWNED.fullmatch(name)}
    _replace(out / MANIFEST, json.dumps(sorted(listed | set(owned)), indent=0).encode("utf-8"))
    return previous


def _previous(out: Path) -> list | None:
    """The file list of the earlier build in ``out``, or None when there was none (no list, or an unreadable one)."""
    try:
        previous = json.loads((out / MANIFEST).read_text())
    except (OSError, ValueError):
        return None
    return previous if isinstance(previous, list) else None


def _replace_owned(out: Path, previous: list | None, owned: list[str], documents: list[str]) -> None:
    """Remove the files the previous build's list (``previous``, from :func:`_claim`) names and this build did not write; list this build's files.

    A folder with a list is an earlier build's: its document (``index.html``,
    ``report.pdf``) that this build does not write (``documents``) is stale
    and removed too (an HTML-only rebuild leaves no PDF of the old one).
    """
    kept = set(owned)
    for name in previous or []:
        if isinstance(name, str) and name not in kept and _OWNED.fullmatch(name):
            (out / name).unlink(missing_ok=True)
    if previous is not None:  # a folder of an earlier build: its document not written again is stale (an HTML-only rebuild's PDF)
        for name in FILE_NAMES.values():
            if name not in documents:
                (out / name).unlink(missing_ok=True)
    _replace(out / MANIFEST, json.dumps(owned, indent=0).encode("utf-8"))


def _check_formats(formats: Sequence[str]) -> list[str]:
    unknown = [name for name in formats if name not in FORMATS]
    if unknown:
        raise ValueError(f"--format: unknown format {unknown[0]!r}; allowed values: {', '.join(FORMATS)}")
    return list(dict.fromkeys(formats))


def _check_keys(report: Report) -> None:
    for kind, keys in (("table", [t.key for t in report.tables()]), ("figure", [f.key for f in report.figures()])):
        for key in keys:
            if not KEY.fullmatch(key):
                raise ValueError(f"{kind} key {key!r} is not usable as a file name (letters, digits, '.', '_', '-')")
            if keys.count(key) > 1:
                raise ValueError(f"{kind} key {key!r} is used more than once")


def _write_figures(report: Report, folder: Path, say: Progress) -> dict[str, bytes]:
    figures = report.figures()
    png = {}
    for number, item in enumerate(figures, start=1):
        say(f"figures {number}/{len(figures)}")
        buffer = io.BytesIO()
        item.figure.savefig(buffer, format="png", dpi=FIGURE_DPI)
        png[item.key] = buffer.getvalue()
        _replace(folder / f"{item.key}.png", png[item.key])
    return png


def _write_tables(report: Report, folder: Path, say: Progress) -> None:
    tables = report.tables()
    for number, table in enumerate(tables, start=1):
        say(f"tables {number}/{len(tables)}")
        _replace(folder / f"{table.key}.csv", table.frame.to_csv().encode("utf-8"))


def _replace(path: Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically; return ``path``."""
    with _replacing(path) as temporary:
        temporary.write_bytes(data)
    return path
