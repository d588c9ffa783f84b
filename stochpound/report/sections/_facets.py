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

import itertools
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from stochpound.experiment import is_fixed_base, is_gap_axis

#: Most panels in one figure.
MAX_PANELS = 16
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


def labels_text(labels: Mapping[str, Any]) -> str:
    """``neighbour stiff, gap 2 cm, μ fixed`` (empty for no labels)."""
    return ", ".join(f"{dim_text(dim)} {value_text(dim, value)}" for dim, value in labels.items())


def cell_gid(labels: Mapping[str, Any]) -> str:
    """The ``gid`` of an artist that draws the cell with these labels (sorted JSON, ∞ as "inf")."""

    def jsonable(value: Any) -> Any:
        value = plain(value)
        return "inf" if isinstance(value, float) and math.isinf(value) else value

    return "cell:" + json.dumps({dim: jsonable(value) for dim, value in labels.items()}, sort_keys=True)


@dataclass(frozen=True)
class Layout:
    """One figure of a family: its panels (labels of the panel dimensions) and the labels it shares."""

    panels: list[dict[str, Any]]
    shared: dict[str, Any]

    @property
    def title(self) -> str:
        """The shared labels, for the figure's title and caption."""
        return labels_text(self.shared)


def layouts(grid: Mapping[str, Sequence[Any]], max_panels: int = MAX_PANELS) -> list[Layout]:
    """Spread every combination of ``grid`` over figures of at most ``max_panels`` panels.

    The outermost dimensions are split off into separate figures until the
    rest fits; an empty grid gives one figure with one panel.
    """
    dims = list(grid)
    split = 0
    while split < len(dims) and math.prod(len(grid[d]) for d in dims[split:]) > max_panels:
        split += 1
    outer, inner = dims[:split], dims[split:]
    result = []
    for shared in itertools.product(*(grid[d] for d in outer)):
        panels = [dict(zip(inner, combination)) for combination in itertools.product(*(grid[d] for d in inner))]
        result.append(Layout(panels, dict(zip(outer, shared))))
    return result


def line_colours(dim: str | None, values: Sequence[Any]) -> list[Any]:
    """One colour per value of the line dimension: a sequential map for numbers (∞, a fixed base, in black), a qualitative one otherwise."""
    from matplotlib import colormaps

    if dim is None:
        return ["C0"] * len(values)
    numeric = [plain(v) for v in values]
    if all(isinstance(v, float) for v in numeric):
        finite = [v for v in numeric if not math.isinf(v)]
        scale = colormaps["viridis"]
        positions = np.linspace(0.0, 0.9, len(finite)) if len(finite) > 1 else [0.0]
        ranks = {v: p for v, p in zip(sorted(finite), positions)}
        return ["black" if math.isinf(v) else scale(ranks[v]) for v in numeric]
    return [f"C{i % 10}" for i in range(len(values))]
