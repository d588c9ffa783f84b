"""The labels of one cell of an experiment's grid: each grid dimension's name and the cell's coordinate value on it."""

from __future__ import annotations

from stochpound.store import Label

CellLabels = dict[str, Label]
"""A grid cell's labels, dimension -> value (``{"gap": 0.02, "mu": 0.1}``), as ``xarray``'s ``.sel`` takes them."""
