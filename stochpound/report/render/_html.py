"""The report as one self-contained HTML page (jinja2 template ``reports/templates/report.html.j2``).

The page makes no request of its own: the style sheet is inline, figures are
embedded as base64 PNG and a Content-Security-Policy forbids anything else.
Tables are real ``<table>`` elements: the column levels become grouped header
rows, the index levels row headers (:mod:`stochpound.report.render._layout`).
"""

from __future__ import annotations

import base64
import datetime
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import jinja2

from stochpound import __version__
from stochpound._data_files import bundled_data_dir
from stochpound.report.render._document import FigureItem, Paragraph, Report, Section, Table
from stochpound.report.render._layout import Grid, runs, table_grid

TEMPLATE = "report.html.j2"


@dataclass(frozen=True)
class Cell:
    """One ``<th>`` or ``<td>`` of a rendered table."""

    text: str
    header: bool = False
    scope: str = ""
    colspan: int = 1
    rowspan: int = 1
    css: str = ""


@dataclass(frozen=True)
class Row:
    """One ``<tr>``: its cells and CSS classes."""

    cells: list[Cell]
    css: str = ""


@dataclass(frozen=True)
class TableView:
    """A numbered table as the template shows it."""

    key: str
    label: str
    caption: str
    note: str
    head: list[Row]
    body: list[Row]
    kind: str = "table"


@dataclass(frozen=True)
class FigureView:
    """A numbered figure with its PNG as a ``data:`` URI."""

    key: str
    label: str
    caption: str
    src: str
    kind: str = "figure"


@dataclass(frozen=True)
class ParagraphView:
    """A paragraph of plain text."""

    text: str
    kind: str = "paragraph"


@dataclass
class SectionView:
    """A numbered section with its anchor and its rendered blocks."""

    anchor: str
    number: int
    title: str
    blocks: list[ParagraphView | TableView | FigureView] = field(default_factory=list)


def render_html(report: Report, figure_png: dict[str, bytes], date: datetime.date | None = None) -> str:
    """Render ``report`` as one self-contained HTML5 page.

    Parameters
    ----------
    report : Report
        The report.
    figure_png : dict[str, bytes]
        The PNG file of every figure, by figure key (embedded as base64).
    date : datetime.date, optional
        The generation date shown on the page (default: today).

    Returns
    -------
    str
        The page.

    Raises
    ------
    ValueError
        If a figure of the report has no PNG in ``figure_png``.
    """
    template = _environment().get_template(TEMPLATE)
    return template.render(
        title=report.title,
        subtitle=report.subtitle,
        sections=_section_views(report.sections, figure_png),
        sources=report.sources,
        date=(date or datetime.date.today()).isoformat(),
        version=__version__,
    )


@lru_cache(maxsize=1)
def _environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(_template_dir()),
        autoescape=True,
        trim_blocks=True,
        lstrip_blocks=True,
        undefined=jinja2.StrictUndefined,
    )


def _template_dir() -> Path:
    """The wheel's ``stochpound/_data/templates`` or, in a source tree, ``reports/templates``."""
    folder = bundled_data_dir("templates", TEMPLATE, repository_folder="reports")
    if folder is None:
        raise FileNotFoundError(f"the report template {TEMPLATE} is not installed (reports/templates/ in the repository)")
    return folder


def _section_views(sections: list[Section], figure_png: dict[str, bytes]) -> list[SectionView]:
    views = []
    tables = figures = 0
    for number, section in enumerate(sections, start=1):
        view = SectionView(anchor=section.key or f"section-{number}", number=number, title=section.title)
        for block in section.blocks:
            if isinstance(block, Table):
                tables += 1
                view.blocks.append(_table_view(block, tables))
            elif isinstance(block, FigureItem):
                figures += 1
                view.blocks.append(_figure_view(block, figures, figure_png))
            elif isinstance(block, Paragraph):
                view.blocks.append(ParagraphView(block.text))
        views.append(view)
    return views


def _figure_view(item: FigureItem, number: int, figure_png: dict[str, bytes]) -> FigureView:
    if item.key not in figure_png:
        raise ValueError(f"figure {item.key!r} has no PNG to embed")
    encoded = base64.b64encode(figure_png[item.key]).decode("ascii")
    return FigureView(key=item.key, label=item.name(number), caption=item.caption, src=f"data:image/png;base64,{encoded}")


def _table_view(table: Table, number: int) -> TableView:
    grid = table_grid(table)
    return TableView(
        key=table.key, label=table.name(number), caption=table.caption, note=table.note, head=_head_rows(grid), body=_body_rows(grid)
    )


def _head_rows(grid: Grid) -> list[Row]:
    levels = grid.column_levels
    corner = [Cell(name, header=True, scope="col", rowspan=levels) for name in grid.index_names]
    rows = []
    for level in range(levels):
        last = level == levels - 1
        cells = [
            Cell(
                grid.column_labels[start][level],
                header=True,
                scope="col" if last else "colgroup",
                colspan=length,
                css="num" if last and grid.numeric_column(start) else "",
            )
            for start, length in runs(grid.column_labels, level)
        ]
        rows.append(Row(corner + cells if level == 0 else cells))
    return rows


def _body_rows(grid: Grid) -> list[Row]:
    spans = [dict(runs(grid.row_labels, level)) for level in range(len(grid.index_names))]
    rows = []
    for position, (labels, texts, numeric) in enumerate(zip(grid.row_labels, grid.cells, grid.numeric)):
        headers = [
            Cell(label, header=True, scope="row", rowspan=span[position])
            for label, span in zip(labels, spans)
            if position in span
        ]
        data = [Cell(text, css="num" if number else "") for text, number in zip(texts, numeric)]
        rows.append(Row(headers + data, css=_row_css(grid, spans[0], position)))
    return rows


def _row_css(grid: Grid, outer_groups: dict[int, int], position: int) -> str:
    """``difference`` rows are highlighted; ``group-start`` rows open a new outer-level group."""
    css = []
    if grid.is_difference(position):
        css.append("difference")
    if len(grid.index_names) > 1 and position > 0 and position in outer_groups:
        css.append("group-start")
    return " ".join(css)
