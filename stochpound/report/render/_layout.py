"""A table as a grid of text cells with grouped labels, shared by the HTML and PDF renderers.

Both renderers show a :class:`~stochpound.report.render._document.Table` the same way:
the index levels become leading label columns, the column levels become
stacked header rows, and a label repeated on consecutive rows (or columns)
is shown once over its group (:func:`runs`).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Sequence

from stochpound.report.render._document import Table

DIFFERENCE = "difference"


@dataclass(frozen=True)
class Grid:
    """The text of a table, ready for layout.

    Attributes
    ----------
    index_names : tuple of str
        One name per index level ("" when unnamed).
    column_labels : list of tuple of str
        One label per column, one string per column level.
    row_labels : list of tuple of str
        One label per row, one string per index level.
    cells : list of list of str
        The formatted cells, row by row.
    numeric : list of list of bool
        Whether each cell holds a number (right-aligned).
    """

    index_names: tuple[str, ...]
    column_labels: list[tuple[str, ...]]
    row_labels: list[tuple[str, ...]]
    cells: list[list[str]]
    numeric: list[list[bool]]

    @property
    def column_levels(self) -> int:
        """The number of header rows."""
        return len(self.column_labels[0]) if self.column_labels else 1

    def numeric_column(self, column: int) -> bool:
        """Whether every cell of ``column`` is a number (its header is right-aligned too)."""
        return bool(self.cells) and all(row[column] for row in self.numeric)

    def is_difference(self, row: int) -> bool:
        """Whether the row's label mentions a difference (highlighted)."""
        return any(DIFFERENCE in label.lower() for label in self.row_labels[row])


def table_grid(table: Table) -> Grid:
    """The :class:`Grid` of ``table`` (cells from :meth:`Table.cell_text`)."""
    frame = table.frame
    text = table.cell_text()
    return Grid(
        index_names=tuple(label_text(name) for name in frame.index.names),
        column_labels=[_as_labels(label) for label in frame.columns],
        row_labels=[_as_labels(label) for label in frame.index],
        cells=[[str(cell) for cell in row] for row in text.itertuples(index=False, name=None)],
        numeric=[[_is_number(value) for value in row] for row in frame.itertuples(index=False, name=None)],
    )


def runs(labels: Sequence[tuple[str, ...]], level: int) -> list[tuple[int, int]]:
    """Groups of consecutive labels equal on levels ``0..level``, as ``(start, length)``.

    Parameters
    ----------
    labels : sequence of tuple of str
        Row or column labels (one string per level).
    level : int
        The level whose groups are wanted; a group never crosses a change of
        an outer level.

    Returns
    -------
    list of (int, int)
        The groups in order; their lengths add up to ``len(labels)``.
    """
    groups: list[tuple[int, int]] = []
    for position, label in enumerate(labels):
        if groups and labels[groups[-1][0]][: level + 1] == label[: level + 1]:
            start, length = groups[-1]
            groups[-1] = (start, length + 1)
        else:
            groups.append((position, 1))
    return groups


def label_text(value: object) -> str:
    """A row or column label as text: floats compactly (``0.02``), missing as ""."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    if isinstance(value, numbers.Real) and not isinstance(value, numbers.Integral):
        return f"{value:g}"
    return str(value)


def _as_labels(label: object) -> tuple[str, ...]:
    parts = label if isinstance(label, tuple) else (label,)
    return tuple(label_text(part) for part in parts)


def _is_number(value: object) -> bool:
    return isinstance(value, numbers.Number) and not isinstance(value, bool)
