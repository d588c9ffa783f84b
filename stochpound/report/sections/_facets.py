"""Laying the cells of a grid out over figures, panels and lines, so that every cell is drawn.

A grid is a mapping of dimension names to their values (e.g. ``neighbour``,
``gap``, ``mu``, ``record``). A figure family chooses the dimension drawn on
the x axis or as lines; every combination of the other dimensions becomes a
panel, and the panels are spread over as many figures as needed (at most
:data:`MAX_PANELS` each), split along the outermost dimensions. Nothing is
dropped.

Every artist that draws a cell carries the cell's labels as its ``gid``
(:func:`cell_gid`), so a test can read back from the figures which cells
they show.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochpound.analysis import CellLabels
from stochpound.experiment import is_fixed_base, is_gap_axis
from stochpound.report.render import figures

MAX_PANELS = figures.MAX_PANELS
#: Dimensions whose values are lengths in m, shown in cm.
CM = 100.0


def plain(value: Any) -> Any:
    """A coordinate value as a plain Python value (float, int or str)."""
    value = value.item() if isinstance(value, np.generic) else value
    return float(value) if isinstance(value, float) else value


def value_text(dim: str, value: Any) -> str:
    """A coordinate value for a label: gaps in cm, μ = ∞ as "fixed"."""
    value = plain(value)
    if is_gap_axis(dim):
        return f"{value * CM:g} cm"
    if dim == "mu":
        return "fixed" if is_fixed_base(value) else f"{value:g}"
    return f"{value:g}" if isinstance(value, float) else str(value)


def dim_text(dim: str) -> str:
    """A dimension's name for a label (μ for ``mu``)."""
    return "μ" if dim == "mu" else dim


def labels_text(labels: CellLabels) -> str:
    """``neighbour stiff, gap 2 cm, μ fixed`` (empty for no labels)."""
    return ", ".join(f"{dim_text(dim)} {value_text(dim, value)}" for dim, value in labels.items())


def cell_gid(labels: CellLabels) -> str:
    """The ``gid`` of an artist that draws the cell with these labels (sorted JSON, ∞ as "inf")."""

    def jsonable(value: Any) -> Any:
        value = plain(value)
        return "inf" if isinstance(value, float) and math.isinf(value) else value

    return "cell:" + json.dumps({dim: jsonable(value) for dim, value in labels.items()}, sort_keys=True)


@dataclass(frozen=True)
class Layout:
    """One figure of a family: its panels (labels of the panel dimensions) and the labels it shares."""

    panels: list[CellLabels]
    shared: CellLabels

    @property
    def title(self) -> str:
        """The shared labels, for the figure's title and caption."""
        return labels_text(self.shared)


def layouts(grid: Mapping[str, Sequence[Any]], max_panels: int = MAX_PANELS) -> list[Layout]:
    """Spread every combination of ``grid`` over figures of at most ``max_panels`` panels
    (:func:`stochpound.report.render.figures.spread_panels`): the outermost dimensions are split off into separate
    figures until the rest fits; an empty grid gives one figure with one panel.
    """
    return [Layout(panels, shared) for panels, shared in figures.spread_panels(grid, max_panels)]


line_colours = figures.line_colours
