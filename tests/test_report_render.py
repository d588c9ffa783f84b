"""Rendering a Report to files: the HTML page (also in headless Chromium), the PDF, figures, tables, and ``report build``."""

from __future__ import annotations

import base64
import datetime
import errno
import re
import sys
import types
from html.parser import HTMLParser
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from matplotlib.figure import Figure

from stochpound.cli import main
from stochpound.cli import _report as cli_report
from stochpound._errors import StochpoundError
from stochpound.report.render import output
from stochpound.report.render import _pdf as pdf_layout
from stochpound.report.render._document import FigureItem, Paragraph, Report, Section, Table
from stochpound.report.render._html import render_html
from stochpound.report.render._pdf import render_pdf
from tests.chromium import render_in_chromium, require_chromium

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
TRICKY = "Friction μ < 0.2 & gap → ∞ – see <b>not bold</b>"
# title page, section 1 (text, table, figure), section 2 (table under its heading, figure and the text after it), sources
EXPECTED_PAGES = 7


def _peaks() -> pd.DataFrame:
    rows = pd.MultiIndex.from_product([["peak drift (cm)", "impacts", "difference (%)"], ["study", "simulation"]], names=["statistic", "source"])
    columns = pd.MultiIndex.from_product([["B1", "B2"], ["floor 1", "floor 2"]], names=["building", "floor"])
    frame = pd.DataFrame(np.random.default_rng(3).normal(size=(6, 4)) * 10, index=rows, columns=columns)
    frame.iloc[1, 2] = np.nan
    return frame


def _cases() -> pd.DataFrame:
    return pd.DataFrame(
        {"gap (cm)": [0.5, 1.0, 2.0], "μ": [0.1, 0.2, 0.3], "remark": ["a < b & c", "∞", "–"]},
        index=pd.Index(["case A", "case B", "case C"], name="case"),
    )


def _pyplot_figure() -> Figure:
    figure, axes = plt.subplots(figsize=(6, 3))
    axes.plot([0, 1, 2], [0, 1, 0])
    axes.set_xlabel("time (s)")
    return figure


def _plain_figure() -> Figure:
    figure = Figure(figsize=(6, 3), layout="constrained")
    figure.subplots().hist(np.random.default_rng(1).normal(size=200), bins=20)
    return figure


def make_report() -> Report:
    """Two sections, a MultiIndex table and a plain one, two figures, text to escape."""
    model = Section(
        "Model & data <check>",
        [
            Paragraph(TRICKY),
            Paragraph("Second paragraph: 1 < 2 && 3 > 2."),
            Table("table-peaks", "Peak responses <cm> & impacts", _peaks(), note="difference = (simulation − study) / study"),
            FigureItem("figure-history", "Time history <a> & μ", _pyplot_figure()),
        ],
        key="model",
    )
    results = Section(
        "Results",
        [
            Table("table-cases", "Cases", _cases(), formats={"case A": "{:.2f}"}),
            FigureItem("figure-histogram", "Histogram of ∞ samples", _plain_figure()),
            Paragraph("The cases – all of them."),
        ],
    )
    return Report("Pounding & isolation", "Regenerated <tables>", [model, results], sources=["store-a.nc (sha256 0123abcd)", "store-b.nc"])


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> tuple[Report, dict[str, Path]]:
    report = make_report()
    return report, output.write_report(report, tmp_path_factory.mktemp("report") / "out")


@pytest.fixture(scope="module")
def parsed(built: tuple[Report, dict[str, Path]]) -> _Page:
    parser = _Page()
    parser.feed(built[1]["html"].read_text(encoding="utf-8"))
    return parser


class _Page(HTMLParser):
    """The tables, images, links, ids and paragraphs of an HTML page."""

    def __init__(self) -> None:
        super().__init__()
        self.tables: list[dict] = []
        self.images: list[dict[str, str]] = []
        self.links: list[str] = []
        self.ids: set[str] = set()
        self.paragraphs: list[str] = []
        self._text: list[str] | None = None
        self._part = ""

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        attributes = {name: value or "" for name, value in attrs}
        if "id" in attributes:
            self.ids.add(attributes["id"])
        if tag == "a" and "href" in attributes:
            self.links.append(attributes["href"])
        elif tag == "img":
            self.images.append(attributes)
        elif tag == "table":
            self.tables.append({"caption": "", "head": [], "body": []})
        elif tag in ("thead", "tbody"):
            self._part = "head" if tag == "thead" else "body"
        elif tag == "tr":
            self.tables[-1][self._part].append({"class": attributes.get("class", ""), "cells": []})
        elif tag in ("th", "td"):
            self.tables[-1][self._part][-1]["cells"].append({"tag": tag, **attributes})
        elif tag in ("caption", "p"):
            self._text = []

    def handle_data(self, data: str) -> None:
        if self._text is not None:
            self._text.append(data)

    def handle_endtag(self, tag: str) -> None:
        if tag == "caption":
            self.tables[-1]["caption"] = "".join(self._text or [])
        elif tag == "p":
            self.paragraphs.append("".join(self._text or []))
        if tag in ("caption", "p"):
            self._text = None


# --- HTML ---------------------------------------------------------------------


def test_html_tables_have_the_frames_shape(built: tuple[Report, dict[str, Path]], parsed: _Page) -> None:
    report, _ = built
    assert len(parsed.tables) == len(report.tables()) == 2
    for number, (table, rendered) in enumerate(zip(report.tables(), parsed.tables), start=1):
        frame = table.frame
        assert rendered["caption"] == f"Table {number}. {table.caption}"
        assert len(rendered["head"]) == frame.columns.nlevels
        for level, row in enumerate(rendered["head"]):
            corner = frame.index.nlevels if level == 0 else 0
            assert sum(int(cell.get("colspan", 1)) for cell in row["cells"]) == frame.shape[1] + corner
        assert len(rendered["body"]) == frame.shape[0]
        for row in rendered["body"]:
            assert sum(cell["tag"] == "td" for cell in row["cells"]) == frame.shape[1]
            assert all(cell.get("scope") == "row" for cell in row["cells"] if cell["tag"] == "th")
        row_headers = sum(int(cell.get("rowspan", 1)) for row in rendered["body"] for cell in row["cells"] if cell["tag"] == "th")
        assert row_headers == frame.shape[0] * frame.index.nlevels


def test_html_groups_headers_and_marks_difference_rows(parsed: _Page) -> None:
    peaks = parsed.tables[0]
    assert [cell.get("colspan") for cell in peaks["head"][0]["cells"] if cell.get("scope") == "colgroup"] == ["2", "2"]
    assert [cell.get("rowspan") for cell in peaks["body"][0]["cells"] if cell["tag"] == "th"] == ["2", None]
    marked = ["difference" in row["class"].split() for row in peaks["body"]]
    assert marked == [False, False, False, False, True, True]
    assert all("num" in cell.get("class", "") for row in peaks["body"] for cell in row["cells"] if cell["tag"] == "td")


def test_html_images_are_embedded_pngs(built: tuple[Report, dict[str, Path]], parsed: _Page) -> None:
    report, written = built
    assert len(parsed.images) == len(report.figures()) == 2
    for image, item in zip(parsed.images, report.figures()):
        prefix = "data:image/png;base64,"
        assert image["src"].startswith(prefix)
        data = base64.b64decode(image["src"][len(prefix) :], validate=True)
        assert data.startswith(PNG_MAGIC)
        assert data == (written["figures"] / f"{item.key}.png").read_bytes()
        assert image["alt"] == item.caption


def test_html_is_self_contained(built: tuple[Report, dict[str, Path]], parsed: _Page) -> None:
    text = built[1]["html"].read_text(encoding="utf-8")
    for forbidden in ("http://", "https://", 'src="file', "<script", "<link", "url("):
        assert forbidden not in text
    assert parsed.links and all(link.startswith("#") and link[1:] in parsed.ids for link in parsed.links)
    assert {"model", "section-2", "table-peaks", "table-cases", "figure-history", "figure-histogram", "sources"} <= parsed.ids


def test_html_escapes_text(built: tuple[Report, dict[str, Path]], parsed: _Page) -> None:
    text = built[1]["html"].read_text(encoding="utf-8")
    assert "<check>" not in text and "&lt;check&gt;" in text
    assert "<b>" not in text and "<tables>" not in text
    assert TRICKY in parsed.paragraphs
    assert "a &lt; b &amp; c" in text
    assert "Generated on" in text


def test_render_html_needs_every_figure_png() -> None:
    with pytest.raises(ValueError, match="figure-history"):
        render_html(make_report(), {}, datetime.date(2024, 1, 2))


# --- files ------------------------------------------------------------------


def test_figure_and_table_files(built: tuple[Report, dict[str, Path]]) -> None:
    report, written = built
    for item in report.figures():
        png = (written["figures"] / f"{item.key}.png").read_bytes()
        assert png.startswith(PNG_MAGIC) and len(png) > 1000
    open_figures = [plt.figure(number) for number in plt.get_fignums()]
    assert not any(item.figure is figure for item in report.figures() for figure in open_figures)
    for table in report.tables():
        frame = table.frame
        back = pd.read_csv(
            written["tables"] / f"{table.key}.csv",
            index_col=list(range(frame.index.nlevels)),
            header=list(range(frame.columns.nlevels)),
        )
        pd.testing.assert_frame_equal(back, frame)
    assert not list(written["html"].parent.rglob("*.tmp"))


def test_unknown_format_names_the_allowed_values(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"--format.*'docx'.*html, pdf"):
        output.write_report(make_report(), tmp_path, ["html", "docx"])
    assert not tmp_path.joinpath("index.html").exists()


def test_interrupted_pdf_leaves_no_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def failing(report: Report, path: Path, date: datetime.date) -> int:
        path.write_bytes(b"%PDF-1.4 half")
        raise KeyboardInterrupt

    monkeypatch.setattr(output, "render_pdf", failing)
    with pytest.raises(KeyboardInterrupt):
        output.write_report(make_report(), tmp_path, ["pdf"])
    assert not (tmp_path / "report.pdf").exists()
    assert not list(tmp_path.rglob("*.tmp"))


def test_a_full_disk_names_the_file_and_keeps_the_old_one(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """ENOSPC while the PDF is written (an OSError naming no file, as write() raises it): the error names report.pdf; the old one stays."""
    output.write_report(make_report(), tmp_path, ["html", "pdf"])
    before = (tmp_path / "report.pdf").read_bytes()

    def full(report: Report, path: Path, date: datetime.date) -> int:
        path.write_bytes(b"%PDF-1.4 half")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(output, "render_pdf", full)
    with pytest.raises(OSError) as caught:
        output.write_report(make_report(), tmp_path, ["pdf"])
    assert caught.value.filename == str(tmp_path / "report.pdf") and caught.value.errno == errno.ENOSPC
    assert (tmp_path / "report.pdf").read_bytes() == before and not list(tmp_path.rglob("*.tmp"))


def test_an_html_only_rebuild_removes_the_stale_pdf(tmp_path: Path) -> None:
    (tmp_path / "report.pdf").write_bytes(b"%PDF the user's")  # a folder without an earlier build: its files are not the build's
    output.write_report(make_report(), tmp_path, ["html"])
    assert (tmp_path / "report.pdf").read_bytes() == b"%PDF the user's"
    output.write_report(make_report(), tmp_path, ["html", "pdf"])
    assert (tmp_path / "report.pdf").is_file()
    output.write_report(make_report(), tmp_path, ["html"])
    assert (tmp_path / "index.html").is_file() and not (tmp_path / "report.pdf").exists()
    (tmp_path / "mine.pdf").write_bytes(b"%PDF")  # not a document of the build: kept
    output.write_report(make_report(), tmp_path, ["pdf"])
    assert (tmp_path / "mine.pdf").is_file() and (tmp_path / "report.pdf").is_file() and not (tmp_path / "index.html").exists()


# --- PDF --------------------------------------------------------------------


def _pdf_pages(data: bytes) -> int:
    return len(re.findall(rb"/Type\s*/Page(?![A-Za-z])", data))


def test_pdf_pages_and_metadata(built: tuple[Report, dict[str, Path]]) -> None:
    data = built[1]["pdf"].read_bytes()
    assert data.startswith(b"%PDF")
    assert _pdf_pages(data) == EXPECTED_PAGES
    assert b"/Creator (stochpound " in data
    assert b"/CreationDate" not in data


def test_pdf_is_reproducible(tmp_path: Path) -> None:
    date = datetime.date(2024, 1, 2)
    pages = [render_pdf(make_report(), tmp_path / f"{name}.pdf", date) for name in ("a", "b")]
    assert pages == [EXPECTED_PAGES, EXPECTED_PAGES]
    assert (tmp_path / "a.pdf").read_bytes() == (tmp_path / "b.pdf").read_bytes()
    plt.close("all")


def test_pdf_splits_long_and_wide_tables(tmp_path: Path) -> None:
    rows = pd.MultiIndex.from_product([[f"record {i}" for i in range(30)], ["mean", "std", "difference"]])
    columns = pd.MultiIndex.from_product([[f"building {i}" for i in range(6)], ["peak drift (cm)", "impacts", "p"]])
    frame = pd.DataFrame(np.arange(90 * 18, dtype=float).reshape(90, 18) * 1.234567, index=rows, columns=columns)
    report = Report("Long", sections=[Section("Only", [Table("table-long", "Long and wide", frame, note="note")])])
    pages = render_pdf(report, tmp_path / "long.pdf")
    assert pages == _pdf_pages((tmp_path / "long.pdf").read_bytes())
    assert pages >= 1 + 2 * 3  # title page; at least two column slices of at least three pages each


def _page_texts(page: pdf_layout._Page) -> list[str]:
    """The texts a planned PDF page draws, in order."""
    return [op.keywords["text"] for op in page.ops if getattr(op, "func", None) is pdf_layout._put]


def _page_has_rows(page: pdf_layout._Page) -> bool:
    """True when the page draws a body row of the tests' tables (labelled "row i")."""
    return any(text.startswith("row ") for text in _page_texts(page))


@pytest.mark.parametrize("rows", range(20, 61, 2))
def test_pdf_table_note_stays_with_its_rows(rows: int) -> None:
    note = "A note long enough to wrap onto several lines of the page. " * 6
    frame = pd.DataFrame({"value": np.arange(rows, dtype=float)}, index=pd.Index([f"row {i}" for i in range(rows)], name="row"))
    flow = pdf_layout._plan(Report("Notes", sections=[Section("Only", [Table("table-note", "Rows", frame, note=note)])]), "2024-01-02")
    pages_with_note = [page for page in flow.pages if any(text in note for text in _page_texts(page) if text.strip())]
    assert len(pages_with_note) == 1
    assert _page_has_rows(pages_with_note[0])


def test_pdf_text_after_a_table_continues_on_its_page() -> None:
    frame = pd.DataFrame({"value": [1.0, 2.0]}, index=pd.Index(["a", "b"], name="row"))
    report = Report("After", sections=[Section("Only", [Table("table-short", "Short", frame), Paragraph("The words after the table.")])])
    flow = pdf_layout._plan(report, "2024-01-02")
    assert len(flow.pages) == 2  # the title page; the section's heading, the table and the paragraph
    assert "The words after the table." in _page_texts(flow.pages[1])


@pytest.mark.parametrize("filler", range(24, 48))
def test_pdf_paragraphs_leave_no_orphan_or_widow_lines(filler: int) -> None:
    words = " ".join(f"word{i}" for i in range(120))  # about ten lines
    blocks = [Paragraph("Filler line.") for _ in range(filler)] + [Paragraph(words)]
    flow = pdf_layout._plan(Report("Lines", sections=[Section("Only", blocks)]), "2024-01-02")
    for page in flow.pages[1:]:
        mine = [text for text in _page_texts(page) if "word" in text]
        assert not mine or len(mine) >= pdf_layout.MIN_LINES


# --- CLI --------------------------------------------------------------------


def test_cli_help() -> None:
    runner = CliRunner()
    for arguments in (["report", "--help"], ["report", "build", "--help"]):
        result = runner.invoke(main, arguments)
        assert result.exit_code == 0, result.output
    assert "--out" in result.output and "--format" in result.output
    assert cli_report.FORMAT_CHOICES == output.FORMATS


def test_cli_missing_store(tmp_path: Path) -> None:
    result = CliRunner().invoke(main, ["report", "build", str(tmp_path / "missing.nc"), "--out", str(tmp_path / "out")])
    assert result.exit_code != 0
    assert "missing.nc" in result.output and "does not exist" in result.output


@pytest.fixture
def fake_assemble(monkeypatch: pytest.MonkeyPatch) -> types.ModuleType:
    """A stand-in ``stochpound.report.assemble`` (the real builders are tested elsewhere)."""
    module = types.ModuleType("stochpound.report.assemble")
    module.assemble_report = lambda paths, progress=None, partial=False, edited="warn", **ruptures: make_report()
    monkeypatch.setitem(sys.modules, "stochpound.report.assemble", module)
    return module


def test_cli_build(tmp_path: Path, fake_assemble: types.ModuleType, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    Path("store.nc").write_bytes(b"")
    result = CliRunner().invoke(main, ["report", "build", "store.nc", "--out", "out", "--format", "html"])
    assert result.exit_code == 0, result.output
    assert Path("out/index.html").is_file() and not Path("out/report.pdf").exists()
    assert result.stdout.splitlines() == ["figures: out/figures (2 PNG files)", "tables: out/tables (2 CSV files)", "html: out/index.html"]
    assert "figures 2/2" in result.stderr


def test_cli_build_reports_store_errors(tmp_path: Path, fake_assemble: types.ModuleType) -> None:
    def unreadable(paths: list[Path], progress: object = None, partial: bool = False, edited: str = "warn", **ruptures: object) -> Report:
        raise StochpoundError(f"{paths[0].name}: not an experiment store")

    fake_assemble.assemble_report = unreadable
    store = tmp_path / "store.nc"
    store.write_bytes(b"")
    result = CliRunner().invoke(main, ["report", "build", str(store), "--out", str(tmp_path / "out")])
    assert result.exit_code == 1
    assert "Error: store.nc: not an experiment store" in result.stderr


@pytest.mark.slow
def test_html_renders_in_headless_chromium(built: tuple[Report, dict[str, Path]], tmp_path: Path) -> None:
    executable = require_chromium()
    report, written = built
    verdict, problems = render_in_chromium(written["html"], tmp_path / "screenshot.png", executable)
    assert verdict["readyState"] == "complete"
    assert verdict["title"] == report.title
    assert verdict["tables"] == len(report.tables())
    assert len(verdict["images"]) == len(report.figures()) and all(width > 0 for width in verdict["images"])
    assert problems == []
    assert (tmp_path / "screenshot.png").read_bytes().startswith(PNG_MAGIC)
