"""The report as data: sections of paragraphs, tables and figures, rendered to HTML and PDF.

The builders (the sections of :mod:`stochpound.report.sections`, and the studies'
sections, :mod:`stochpound.studies`) produce a :class:`Report`; the renderers (:mod:`stochpound.report.render._html`,
:mod:`stochpound.report.render._pdf`) turn the same object into each format, so the
two formats always carry the same tables, figures and text.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Union

import pandas as pd
from matplotlib.figure import Figure


@dataclass
class Paragraph:
    """A paragraph of plain text (no markup)."""

    text: str


@dataclass
class Table:
    """A numbered table.

    Attributes
    ----------
    key : str
        Short identifier, unique in the report (e.g. ``"table-4.1"``); also the
        HTML anchor.
    caption : str
        What the table shows, with units.
    frame : pandas.DataFrame
        The cells; a MultiIndex on rows or columns is rendered as grouped
        headers. Numbers are formatted by ``formats`` (per column level-0 name)
        or with 4 significant digits.
    note : str
        Text under the table (sources, substitutes, what "difference" means).
    formats : dict[str, str]
        Optional format strings (``"{:.3f}"``) by row label (level 0) or
        column label (last level); a row's format wins.
    label : str
        The table's own name (e.g. the study's ``"Table 4.1"``); empty: the
        renderers number it ("Table 3"). A caption that starts with its
        own name and a colon (``"Table 4.1: ..."``) gives the label.
    per_cell : bool
        One row per cell (case) of an experiment's grid: a reference table,
        which the report of an experiment moves to its appendix.
    """

    key: str
    caption: str
    frame: pd.DataFrame
    note: str = ""
    formats: dict[str, str] = field(default_factory=dict)
    label: str = ""
    per_cell: bool = False

    def __post_init__(self) -> None:
        self.label, self.caption = _own_label(self.label, self.caption)

    def name(self, number: int) -> str:
        """The label shown before the caption: ``label`` or "Table <number>"."""
        return self.label or f"Table {number}"

    def cell_text(self) -> pd.DataFrame:
        """The cells as strings: numbers formatted, missing values as an en dash."""
        text = self.frame.astype(object).copy()
        column_patterns = [self.formats.get(str(_last(label)), "{:.4g}") for label in self.frame.columns]
        for position, label in enumerate(self.frame.index):
            row_pattern = self.formats.get(str(label[0] if isinstance(label, tuple) else label))
            patterns = [row_pattern or pattern for pattern in column_patterns]
            text.iloc[position] = [_format(value, pattern) for value, pattern in zip(self.frame.iloc[position], patterns)]
        return text


@dataclass
class FigureItem:
    """A numbered figure.

    Attributes
    ----------
    key : str
        Short identifier, unique in the report; the PNG file is ``figures/<key>.png``.
    caption : str
        What the figure shows (record named, substitutes labelled).
    figure : matplotlib.figure.Figure
        The figure itself.
    label : str
        The figure's own name (e.g. the study's ``"Figure 3.6"``); empty: the
        renderers number it ("Figure 3"). A caption that starts with its
        own name and a colon (``"Figures 4.8–4.15 (...): ..."``) gives the label.
    """

    key: str
    caption: str
    figure: Figure
    label: str = ""

    def __post_init__(self) -> None:
        self.label, self.caption = _own_label(self.label, self.caption)

    def name(self, number: int) -> str:
        """The label shown before the caption: ``label`` or "Figure <number>"."""
        return self.label or f"Figure {number}"


Block = Union[Paragraph, Table, FigureItem]


@dataclass
class Section:
    """A titled section: an ordered list of blocks."""

    title: str
    blocks: list[Block] = field(default_factory=list)
    key: str = ""

    def add(self, block: Block) -> Block:
        """Append a block and return it."""
        self.blocks.append(block)
        return block


@dataclass
class Report:
    """A whole report.

    Attributes
    ----------
    title : str
    subtitle : str
    sections : list of Section
    sources : list of str
        What the report was built from (store names and definition hashes).
    """

    title: str
    subtitle: str = ""
    sections: list[Section] = field(default_factory=list)
    sources: list[str] = field(default_factory=list)

    def tables(self) -> list[Table]:
        """Every table, in order."""
        return [block for section in self.sections for block in section.blocks if isinstance(block, Table)]

    def figures(self) -> list[FigureItem]:
        """Every figure, in order."""
        return [block for section in self.sections for block in section.blocks if isinstance(block, FigureItem)]


#: A caption's leading own name: "Table 3.2: ", "Tables 4.9 and 4.10: ", "Figures 4.8–4.15 (both isolated): ".
_OWN_LABEL = re.compile(r"^((?:Tables?|Figures?) [0-9][0-9.–\- and]*)(?: \(([^)]*)\))?: (.*)$", re.DOTALL)


def _own_label(label: str, caption: str) -> tuple[str, str]:
    match = None if label else _OWN_LABEL.match(caption)
    if match is None:
        return label, caption
    name, qualifier, rest = match.groups()
    return name.strip(), (f"{qualifier[0].upper()}{qualifier[1:]}: {rest}" if qualifier else f"{rest[0].upper()}{rest[1:]}")


def _last(label: object) -> object:
    return label[-1] if isinstance(label, tuple) else label


def _format(value: object, pattern: str) -> str:
    if value is None or (isinstance(value, float) and value != value):
        return "–"
    if isinstance(value, str):
        return value
    try:
        return pattern.format(value)
    except (TypeError, ValueError):
        return str(value)
