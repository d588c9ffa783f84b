"""The report as a PDF on A4 pages, drawn with matplotlib (:class:`~matplotlib.backends.backend_pdf.PdfPages`).

Layout: a title page with the contents (sections, tables and figures with
their pages); each section starts on a new page and its text flows onto
portrait pages; each table starts a page (landscape, a smaller font or
column slices when it is wide; long tables continue with repeated headers,
and a table's last page keeps room for its note, so a note never stands
alone); each figure starts a page with its caption. Text after a table or a
figure continues on its page when it has room for the whole paragraph or
at least ``MIN_LINES`` of it; a paragraph is never split so that fewer
than ``MIN_LINES`` lines stand alone at the bottom or the top of a page.
The pages are first planned as lists of drawing operations, so the
contents can give page numbers, then drawn one by one.
"""

from __future__ import annotations

import datetime
import io
import struct
import textwrap
from dataclasses import dataclass, field
from functools import lru_cache, partial
from pathlib import Path
from typing import Callable

import matplotlib
import matplotlib.image
import numpy as np
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.lines import Line2D
from matplotlib.patches import Rectangle
from matplotlib.textpath import text_to_path

from stochpound import __version__
from stochpound.report.render._document import FigureItem, Paragraph, Report, Table
from stochpound.report.render._layout import Grid, runs, table_grid

PORTRAIT = (8.27, 11.69)
LANDSCAPE = (11.69, 8.27)
MARGIN = 0.75
BODY = 10.0
HEADING = 15.0
NOTE = 8.0
FOOTER = 7.5
TABLE_SIZES = (8.5, 7.5, 7.0)
LEADING = 1.35
CELL_PAD = 4.0 / 72
CELL_CAP = 2.2
HEADER_CAP = 1.1
FIGURE_DPI = 200
GREY = "#555555"
DIFFERENCE_FILL = "#fff1c9"
MIN_LINES = 3
"""The fewest lines of a paragraph at the bottom of a page (fewer move to the next page with the rest)."""

Op = Callable[[Figure], None]


@dataclass
class _Page:
    size: tuple[float, float]
    ops: list[Op] = field(default_factory=list)


@dataclass
class _Flow:
    """Pages being planned, with a cursor ``y`` (inches from the top of the current page)."""

    pages: list[_Page] = field(default_factory=list)
    y: float = 0.0
    open: bool = False
    pending: tuple[str, str] | None = None
    starts: dict[str, int] = field(default_factory=dict)

    @property
    def page(self) -> _Page:
        return self.pages[-1]

    def room(self) -> float:
        """The height left on the current page (inches)."""
        return self.page.size[1] - MARGIN - self.y

    def new_page(self, size: tuple[float, float] = PORTRAIT) -> None:
        """Start a page, headed by the pending section title if there is one."""
        self.pages.append(_Page(size))
        self.y = MARGIN
        self.open = False
        if self.pending is not None:
            key, title = self.pending
            self.pending = None
            self.starts[key] = len(self.pages) - 1
            self.text(_wrap(title, _width(size), HEADING, bold=True), HEADING, weight="bold")
            self.y += 0.12

    def section(self, key: str, title: str) -> None:
        """Start a section: its title heads the next page."""
        self.pending = (key, title)
        self.open = False

    def end_section(self) -> None:
        """Give an empty section its page."""
        if self.pending is not None:
            self.new_page()

    def draw(self, op: Op) -> None:
        self.page.ops.append(op)

    def text(self, lines: list[str], size: float, **style: object) -> None:
        """Lines of text at the cursor, continuing on a new page of the same size when full."""
        for line in lines:
            if self.room() < _line(size):
                self.new_page(self.page.size)
            self.draw(partial(_put, x=MARGIN, y=self.y, text=line, size=size, **style))
            self.y += _line(size)


def render_pdf(report: Report, path: Path, date: datetime.date | None = None) -> int:
    """Write ``report`` as a PDF of A4 pages.

    Parameters
    ----------
    report : Report
        The report.
    path : pathlib.Path
        The PDF file to write.
    date : datetime.date, optional
        The generation date on the title page (default: today). The file's
        metadata carry no creation date, so the same report gives the same file.

    Returns
    -------
    int
        The number of pages.
    """
    flow = _plan(report, (date or datetime.date.today()).isoformat())
    metadata = {"Title": report.title, "Subject": report.subtitle, "Creator": f"stochpound {__version__}", "CreationDate": None}
    with matplotlib.rc_context({"pdf.fonttype": 42}), PdfPages(path, metadata=metadata) as pdf:
        for number, page in enumerate(flow.pages, start=1):
            figure = Figure(figsize=page.size)
            for op in page.ops:
                op(figure)
            if number > 1:
                _put(figure, x=page.size[0] / 2, y=page.size[1] - MARGIN / 2, text=f"{report.title} — {number} / {len(flow.pages)}", size=FOOTER, color=GREY, ha="center")
            pdf.savefig(figure)
        return pdf.get_pagecount()


def _plan(report: Report, date: str) -> _Flow:
    flow = _Flow()
    _title_page(flow, report, date)
    tables = figures = 0
    for number, section in enumerate(report.sections, start=1):
        flow.section(_anchor(section.key, number), f"{number}. {section.title}")
        for block in section.blocks:
            if isinstance(block, Paragraph):
                _paragraph(flow, block.text)
            elif isinstance(block, Table):
                tables += 1
                _table(flow, block, tables)
            elif isinstance(block, FigureItem):
                figures += 1
                _figure(flow, block, figures)
        flow.end_section()
    if report.sources:
        flow.section("sources", "Sources")
        for source in report.sources:
            _paragraph(flow, f"• {source}")
    return flow


def _anchor(key: str, number: int) -> str:
    return key or f"section-{number}"


def _title_page(flow: _Flow, report: Report, date: str) -> None:
    flow.new_page()
    width = _width(PORTRAIT)
    flow.y += 1.0
    flow.text(_wrap(report.title, width, 22, bold=True), 22, weight="bold")
    flow.y += 0.1
    flow.text(_wrap(report.subtitle, width, 14), 14, color=GREY)
    flow.y += 0.15
    flow.text([f"Generated on {date} by stochpound {__version__}"], BODY, color=GREY)
    for heading, entries in _contents_entries(report).items():
        if entries:
            flow.y += 0.3
            flow.text([heading], 13, weight="bold")
            flow.y += 0.05
            _contents(flow, entries)


def _contents_entries(report: Report) -> dict[str, list[tuple[str, str]]]:
    """The (key, label) of every section, table and figure, under the contents' headings."""
    sections = [(_anchor(s.key, n), f"{n}. {s.title}") for n, s in enumerate(report.sections, start=1)]
    if report.sources:
        sections.append(("sources", "Sources"))
    return {
        "Contents": sections,
        "Tables": [(t.key, f"{t.name(n)}. {t.caption}") for n, t in enumerate(report.tables(), start=1)],
        "Figures": [(f.key, f"{f.name(n)}. {f.caption}") for n, f in enumerate(report.figures(), start=1)],
    }


def _contents(flow: _Flow, entries: list[tuple[str, str]]) -> None:
    """One line per entry with its page number (looked up when the page is drawn)."""
    width = _width(PORTRAIT) - 0.5
    for key, label in entries:
        if flow.room() < _line(BODY):
            flow.new_page()
        shown = _wrap(label, width, BODY, max_lines=1)[0]
        flow.draw(partial(_contents_line, y=flow.y, label=shown, key=key, starts=flow.starts))
        flow.y += _line(BODY)


def _contents_line(figure: Figure, y: float, label: str, key: str, starts: dict[str, int]) -> None:
    _put(figure, x=MARGIN, y=y, text=label, size=BODY)
    _put(figure, x=PORTRAIT[0] - MARGIN, y=y, text=str(starts[key] + 1), size=BODY, ha="right")


def _paragraph(flow: _Flow, text: str) -> None:
    """A paragraph at the cursor; on a new page when the section has none yet or when fewer than ``MIN_LINES`` of it would fit."""
    if flow.open:
        lines = _wrap(text, _width(flow.page.size), BODY)
        if _fits(len(lines), int((flow.room() - 0.35 * _line(BODY)) // _line(BODY))):
            flow.y += 0.35 * _line(BODY)
            flow.text(lines, BODY)
            return
    flow.new_page()
    flow.text(_wrap(text, _width(PORTRAIT), BODY), BODY)
    flow.open = True


def _fits(lines: int, room: int) -> bool:
    """True when a paragraph of ``lines`` lines may start with ``room`` lines left on the page: whole, or split with at least ``MIN_LINES`` lines on each side."""
    return lines <= room or (room >= MIN_LINES and lines - room >= MIN_LINES)


def _figure(flow: _Flow, item: FigureItem, number: int) -> None:
    """The figure, as a PNG decoded only when its page is drawn, scaled to the page, and its caption."""
    buffer = io.BytesIO()
    item.figure.savefig(buffer, format="png", dpi=FIGURE_DPI)
    png = buffer.getvalue()
    flow.new_page()
    flow.starts[item.key] = len(flow.pages) - 1
    caption = _wrap(f"{item.name(number)}. {item.caption}", _width(PORTRAIT), BODY)
    box_width, box_height = _width(PORTRAIT), flow.room() - 0.15 - len(caption) * _line(BODY)
    natural_width, natural_height = (pixels / FIGURE_DPI for pixels in struct.unpack(">II", png[16:24]))  # IHDR
    scale = min(1.0, box_width / natural_width, box_height / natural_height)
    width, height = natural_width * scale, natural_height * scale
    flow.draw(partial(_image, x=MARGIN + (box_width - width) / 2, y=flow.y, width=width, height=height, png=png))
    flow.y += height + 0.15
    flow.text(caption, BODY)
    flow.open = True


def _image(figure: Figure, x: float, y: float, width: float, height: float, png: bytes) -> None:
    page_width, page_height = figure.get_size_inches()
    axes = figure.add_axes((x / page_width, (page_height - y - height) / page_height, width / page_width, height / page_height))
    axes.imshow(matplotlib.image.imread(io.BytesIO(png), format="png"), interpolation="none", aspect="auto")
    axes.set_axis_off()


# --- tables ------------------------------------------------------------------


@dataclass
class _TableLayout:
    """Where a table's cells go: font size, page size, column widths and wrapped texts."""

    grid: Grid
    size: float
    page: tuple[float, float]
    label_widths: list[float]
    column_widths: list[float]
    names: list[list[str]]
    header: list[list[list[str]]]
    labels: list[list[list[str]]]
    cells: list[list[list[str]]]

    def slices(self) -> list[list[int]]:
        """The data columns of each page across (all of them when the table fits the width)."""
        available = _width(self.page) - sum(self.label_widths)
        slices: list[list[int]] = [[]]
        used = 0.0
        for column, width in enumerate(self.column_widths):
            if slices[-1] and used + width > available:
                slices.append([])
                used = 0.0
            slices[-1].append(column)
            used += width
        return slices

    def row_height(self, row: int) -> float:
        """The height (inches) of body row ``row``."""
        return max((len(text) for text in self.labels[row] + self.cells[row]), default=1) * _line(self.size) + CELL_PAD

    def header_heights(self) -> list[float]:
        """The height (inches) of each header row; the last one also holds the index names."""
        texts = self.header[:-1] + [self.header[-1] + self.names]
        return [max((len(text) for text in level), default=1) * _line(self.size) + CELL_PAD for level in texts]


def _table(flow: _Flow, table: Table, number: int) -> None:
    """The table from a new page, continued over as many pages as it needs, then its note (kept with its last rows)."""
    layout = _table_layout(table_grid(table))
    rows = len(layout.grid.cells)
    note = _wrap(table.note, _width(layout.page), NOTE) if table.note else []
    slices = layout.slices()
    first = True
    for slice_number, columns in enumerate(slices, start=1):
        start = 0
        while first or start < rows:
            flow.new_page(layout.page)
            if first:
                flow.starts[table.key] = len(flow.pages) - 1
            title = f"{table.name(number)}. {table.caption}" if first else f"{table.name(number)} (continued). {table.caption}"
            flow.text(_wrap(title, _width(layout.page), BODY), BODY)
            flow.y += 0.08
            first = False
            reserve = 0.1 + len(note) * _line(NOTE) if slice_number == len(slices) else 0.0
            start = _table_page(flow, layout, columns, start, reserve)
    if note:
        flow.y += 0.1
        flow.text(note, NOTE, style="italic", color=GREY)
    flow.open = True


def _table_layout(grid: Grid) -> _TableLayout:
    """The first (page, font size) at which the table fits the width; else landscape, smallest font, sliced."""
    for page in (PORTRAIT, LANDSCAPE):
        for size in TABLE_SIZES:
            layout = _measure(grid, size, page)
            if len(layout.slices()) == 1:
                return layout
    return layout


def _measure(grid: Grid, size: float, page: tuple[float, float]) -> _TableLayout:
    labels = [[_wrap_to(label, CELL_CAP, size) for label in row] for row in grid.row_labels]
    cells = [[_wrap_to(text, CELL_CAP, size) for text in row] for row in grid.cells]
    data_widths = [max((_widest(row[column], size) for row in cells), default=0.0) for column in range(len(grid.column_labels))]
    last = grid.column_levels - 1
    bottom = [_wrap_to(label[last], max(width, HEADER_CAP), size, bold=True) for label, width in zip(grid.column_labels, data_widths)]
    column_widths = [max(width, _widest(text, size, bold=True)) + 2 * CELL_PAD for width, text in zip(data_widths, bottom)]
    names = [_wrap_to(name, HEADER_CAP, size, bold=True) for name in grid.index_names]
    label_widths = [
        max([_widest(row[level], size) for row in labels] + [_widest(names[level], size, bold=True)]) + 2 * CELL_PAD
        for level in range(len(grid.index_names))
    ]
    header = [[_wrap_to(label[level], CELL_CAP, size, bold=True) for label in grid.column_labels] for level in range(last)]
    for level, texts in enumerate(header):
        _widen_groups(column_widths, runs(grid.column_labels, level), [_widest(text, size, bold=True) + 2 * CELL_PAD for text in texts])
    return _TableLayout(grid, size, page, label_widths, column_widths, names, header + [bottom], labels, cells)


def _widen_groups(widths: list[float], groups: list[tuple[int, int]], needed: list[float]) -> None:
    """Widen the columns of each group evenly so that the group's label (``needed[start]``) fits over them."""
    for start, length in groups:
        missing = needed[start] - sum(widths[start : start + length])
        for column in range(start, start + length):
            widths[column] += max(missing, 0.0) / length


def _table_page(flow: _Flow, layout: _TableLayout, columns: list[int], start: int, reserve: float = 0.0) -> int:
    """Draw the header and as many rows from ``start`` as fit; return the next row.

    ``reserve`` (inches) is kept free below the table's last row (for its
    note): when every remaining row fits but the reserve does not, the last
    row moves to a continuation page.
    """
    x_labels = np.cumsum([MARGIN] + layout.label_widths)
    x_columns = np.cumsum([x_labels[-1]] + [layout.column_widths[c] for c in columns])
    right = x_columns[-1]
    flow.draw(partial(_rule, x0=MARGIN, x1=right, y=flow.y, width=1.0))
    _table_header(flow, layout, columns, x_labels, x_columns)
    flow.draw(partial(_rule, x0=MARGIN, x1=right, y=flow.y, width=0.6))
    stop, used = start, 0.0
    rows = len(layout.grid.cells)
    while stop < rows and (stop == start or used + layout.row_height(stop) <= flow.room()):
        used += layout.row_height(stop)
        stop += 1
    if stop == rows and stop - start > 1 and used + reserve > flow.room():
        stop -= 1
    stop = _group_break(layout.grid, start, stop)
    labels = layout.grid.row_labels[start:stop]
    spans = [dict(runs(labels, level)) for level in range(len(layout.grid.index_names))]
    for offset, row in enumerate(range(start, stop)):
        height = layout.row_height(row)
        if layout.grid.is_difference(row):
            flow.draw(partial(_fill, x0=MARGIN, x1=right, y=flow.y, height=height))
        if offset > 0 and len(spans) > 1 and offset in spans[0]:
            flow.draw(partial(_rule, x0=MARGIN, x1=right, y=flow.y, width=0.4, color="#999999"))
        style = "italic" if layout.grid.is_difference(row) else "normal"
        for level, span in enumerate(spans):
            if offset in span:
                _cell(flow, layout.labels[row][level], x_labels[level], x_labels[level + 1], False, layout.size, style=style)
        for column, x0, x1 in zip(columns, x_columns[:-1], x_columns[1:]):
            _cell(flow, layout.cells[row][column], x0, x1, layout.grid.numeric[row][column], layout.size, style=style)
        flow.y += height
    flow.draw(partial(_rule, x0=MARGIN, x1=right, y=flow.y, width=1.0))
    return stop


def _group_break(grid: Grid, start: int, stop: int) -> int:
    """``stop`` moved back to the start of the outer-level group it would cut, if that leaves rows on the page."""
    if stop == len(grid.row_labels) or len(grid.index_names) < 2:
        return stop
    starts = [group for group, _ in runs(grid.row_labels, 0) if start < group <= stop]
    return starts[-1] if starts else stop


def _table_header(flow: _Flow, layout: _TableLayout, columns: list[int], x_labels: np.ndarray, x_columns: np.ndarray) -> None:
    heights = layout.header_heights()
    last = len(heights) - 1
    labels = [layout.grid.column_labels[c] for c in columns]
    for level, height in enumerate(heights):
        if level == last:
            for name, x0, x1 in zip(layout.names, x_labels[:-1], x_labels[1:]):
                _cell(flow, name, x0, x1, False, layout.size, weight="bold")
        for start, length in runs(labels, level):
            x0, x1 = x_columns[start], x_columns[start + length]
            text = layout.header[level][columns[start]]
            if level == last:
                _cell(flow, text, x0, x1, layout.grid.numeric_column(columns[start]), layout.size, weight="bold")
            else:
                _cell(flow, text, x0, x1, None, layout.size, weight="bold")
                flow.draw(partial(_rule, x0=x0 + CELL_PAD, x1=x1 - CELL_PAD, y=flow.y + height - CELL_PAD / 2, width=0.5))
        flow.y += height


def _cell(flow: _Flow, lines: list[str], x0: float, x1: float, numeric: bool | None, size: float, **style: object) -> None:
    """A cell's lines at the cursor: right-aligned when numeric, centred when None, else left-aligned."""
    if numeric is None:
        x, align = (x0 + x1) / 2, "center"
    elif numeric:
        x, align = x1 - CELL_PAD, "right"
    else:
        x, align = x0 + CELL_PAD, "left"
    for index, line in enumerate(lines):
        flow.draw(partial(_put, x=x, y=flow.y + CELL_PAD / 2 + index * _line(size), text=line, size=size, ha=align, **style))


# --- drawing primitives (inches from the page's top-left corner) -----------------


def _put(figure: Figure, x: float, y: float, text: str, size: float, **style: object) -> None:
    height = figure.get_size_inches()[1]
    figure.text(x, height - y, text, transform=figure.dpi_scale_trans, fontsize=size, va="top", parse_math=False, **style)


def _rule(figure: Figure, x0: float, x1: float, y: float, width: float, color: str = "black") -> None:
    height = figure.get_size_inches()[1]
    figure.add_artist(Line2D([x0, x1], [height - y, height - y], transform=figure.dpi_scale_trans, linewidth=width, color=color))


def _fill(figure: Figure, x0: float, x1: float, y: float, height: float) -> None:
    page_height = figure.get_size_inches()[1]
    figure.add_artist(Rectangle((x0, page_height - y - height), x1 - x0, height, transform=figure.dpi_scale_trans, facecolor=DIFFERENCE_FILL, edgecolor="none", zorder=-1))


# --- text measurement ---------------------------------------------------------


def _line(size: float) -> float:
    """The line height (inches) of text of ``size`` points."""
    return LEADING * size / 72


def _width(page: tuple[float, float]) -> float:
    """The text width (inches) of a page."""
    return page[0] - 2 * MARGIN


@lru_cache(maxsize=None)
def _text_width(text: str, size: float, bold: bool = False) -> float:
    """The width (inches) of ``text`` set in the default font at ``size`` points."""
    font = FontProperties(size=size, weight="bold" if bold else "normal")
    return text_to_path.get_text_width_height_descent(text, font, ismath=False)[0] / 72


def _widest(lines: list[str], size: float, bold: bool = False) -> float:
    return max((_text_width(line, size, bold) for line in lines), default=0.0)


def _wrap(text: str, width: float, size: float, bold: bool = False, max_lines: int | None = None) -> list[str]:
    """``text`` wrapped with :mod:`textwrap` to ``width`` inches (column count from the font's average character width)."""
    sample = "Pounding of adjacent buildings, 0.25 m gap: μ = 0.1 (B1–B2)"
    columns = max(1, int(width / (_text_width(sample, size, bold) / len(sample))))
    return textwrap.wrap(text, columns, max_lines=max_lines, placeholder=" …") or [""]


def _wrap_to(text: str, width: float, size: float, bold: bool = False) -> list[str]:
    """``text`` on one line when it fits ``width`` inches, else wrapped."""
    return [text] if _text_width(text, size, bold) <= width else _wrap(text, width, size, bold)
