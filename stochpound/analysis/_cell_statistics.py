"""What an ensemble's statistics per grid cell show, as numbers: how wide the intervals are, how far the peaks spread, how
P(pounding) falls with a gap axis, and where a sliding base lowers or raises it against the fixed base.

:class:`CellStatistics` takes :func:`~stochpound.analysis.ensemble_statistics`'
result of one ensemble (the studied building selected: :attr:`stochpound.analysis.StoreEnsemble.statistics`)
and reduces it to the records a report states (:class:`Precision`, :class:`Spread`,
:class:`GapEffect`, :class:`IsolationCounts`); "clearly" lower or higher means
with non-overlapping intervals, a conservative test.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from stochpound.analysis._cells import CellLabels
from stochpound.analysis._intervals import MIN_RUNS
from stochpound.analysis._store_ensemble import rare_gap
from stochpound.store import FIXED_BASE, fixed_base, is_fixed_base, isolated_mus

COMPARED = ("pounding_probability", "peak_relative_displacement", "peak_total_displacement")
"""The estimates compared between a sliding and a fixed base, and between ensembles."""


@dataclass(frozen=True)
class Precision:
    """How wide the intervals are over the cells: ``cells``; the half-widths of P(pounding)'s interval, largest and median;
    those of the mean peak total displacement relative to it, median and largest."""

    cells: int
    probability_widest: float
    probability_median: float
    peak_median: float
    peak_widest: float


@dataclass(frozen=True)
class ForceSpread:
    """The spread of the peak impact force over the runs with impacts, from the ``cells`` with at least :data:`MIN_RUNS` of them
    (``fewest``–``most`` runs there): its ``top`` quantile over its median, ``lowest``–``highest``; ``rest`` cells give none,
    ``most_anywhere`` the most runs with impacts of any cell."""

    cells: int
    fewest: int
    most: int
    lowest: float
    highest: float
    rest: int
    most_anywhere: int


@dataclass(frozen=True)
class Spread:
    """How far the peaks spread within a cell: ``top`` (the highest quantile) of the peak total displacement over its median,
    ``lowest``–``highest`` over the cells (NaN with fewer than :data:`MIN_RUNS` runs); in ``between`` of ``cells`` cells
    P(pounding) lies strictly between 0 and 1; ``force`` the peak impact force's (None where the store lacks it)."""

    top: float
    lowest: float
    highest: float
    between: int
    cells: int
    force: ForceSpread | None


@dataclass(frozen=True)
class GapEffect:
    """How P(pounding) falls with a gap axis: over ``lines`` combinations of the other axes, lower at the widest gap than at
    the narrowest in ``lower_at_end``, its range at the first and last gap; ``rare`` the gap from which pounding is rare
    per combination (m, NaN if none: :func:`rare_gap`), reached in ``reached`` of them, from ``rare_low`` to ``rare_high`` m;
    ``missing`` the combinations where it is not reached."""

    lines: int
    lower_at_end: int
    first: tuple[float, float]
    last: tuple[float, float]
    rare: xr.DataArray
    reached: int
    rare_low: float
    rare_high: float
    missing: list[CellLabels]


@dataclass(frozen=True)
class Largest:
    """The cell of the largest clear change of P(pounding) by isolation: its labels (``mu`` included) and the fixed base's."""

    cell: CellLabels
    fixed: CellLabels


@dataclass(frozen=True)
class IsolationCounts:
    """A sliding base against the fixed base, cell by cell: per μ (its value) the cells clearly lower, higher and not clearly
    different for each estimate of :data:`COMPARED` (9 counts in that order); ``cells`` the fixed base's cells; ``hurts`` and
    ``helps`` the cell of the largest clear rise and fall of P(pounding) (None where there is none)."""

    rows: list[tuple[Any, list[int]]]
    cells: int
    hurts: Largest | None
    helps: Largest | None

    def totals(self) -> list[tuple[int, int]]:
        """Per estimate of :data:`COMPARED`, over every μ: the cells clearly lower and clearly higher."""
        return [(sum(row[3 * i] for _, row in self.rows), sum(row[3 * i + 1] for _, row in self.rows)) for i in range(len(COMPARED))]


@dataclass(frozen=True)
class SignFlip:
    """Where isolation lowers and where it raises P(pounding), along the axis ``dim`` that separates the two best: per value,
    the cells clearly lowered and raised (values with neither left out)."""

    dim: str
    counts: list[tuple[Any, int, int]]


class CellStatistics:
    """The statistics of an ensemble's cells, reduced to what a report states of them.

    Parameters
    ----------
    statistics : xarray.Dataset
        :func:`~stochpound.analysis.ensemble_statistics`' result, computed, the studied building selected.
    """

    def __init__(self, statistics: xr.Dataset) -> None:
        self.statistics = statistics

    def _half_widths(self, name: str) -> np.ndarray:
        return ((self.statistics[f"{name}_upper"] - self.statistics[f"{name}_lower"]) / 2.0).values.ravel()

    def precision(self) -> Precision:
        """How wide the intervals of P(pounding) and of the mean peak total displacement are."""
        stats = self.statistics
        p = self._half_widths("pounding_probability")
        relative = self._half_widths("peak_total_displacement") / stats["peak_total_displacement_mean"].values.ravel()
        return Precision(int(stats["pounding_probability"].size), float(np.nanmax(p)), float(np.nanmedian(p)), float(np.nanmedian(relative)),
                         float(np.nanmax(relative)))

    def spread(self, size: int) -> Spread:
        """How far the peaks spread within the cells of ``size`` realizations (the ratio only from :data:`MIN_RUNS`)."""
        stats = self.statistics
        quantile = stats["peak_total_displacement_quantile"]
        top = float(quantile["quantile"].max())
        between = ((stats["pounding_probability_lower"] > 0) & (stats["pounding_probability_upper"] < 1)).values
        lowest = highest = float("nan")
        if size >= MIN_RUNS:
            ratio = (quantile.sel(quantile=top) / quantile.sel(quantile=0.5)).values.ravel()
            lowest, highest = float(np.nanmin(ratio)), float(np.nanmax(ratio))
        force = self._force_spread(top) if "peak_impact_force_quantile" in stats else None
        return Spread(top, lowest, highest, int(between.sum()), int(between.size), force)

    def _force_spread(self, top: float) -> ForceSpread:
        force, count = self.statistics["peak_impact_force_quantile"], self.statistics["peak_impact_force_count"]
        enough = (count >= MIN_RUNS).values.ravel()
        most_anywhere = int(count.max())
        if not enough.any():
            return ForceSpread(0, 0, 0, float("nan"), float("nan"), int((~enough).sum()), most_anywhere)
        ratio = (force.sel(quantile=top) / force.sel(quantile=0.5)).values.ravel()[enough]
        counts = count.values.ravel()[enough]
        return ForceSpread(int(enough.sum()), int(counts.min()), int(counts.max()), float(np.nanmin(ratio)), float(np.nanmax(ratio)),
                           int((~enough).sum()), most_anywhere)

    def gap_effect(self, dim: str, others: list[str]) -> GapEffect:
        """How P(pounding) falls along gap axis ``dim`` over the combinations of the ``others`` axes."""
        p = self.statistics["pounding_probability"]
        first, last = p.isel({dim: 0}), p.isel({dim: -1})
        needed = rare_gap(self.statistics["pounding_probability_upper"], dim)
        reached = needed.notnull()
        low = high = float("nan")
        if bool(reached.any()):
            low, high = needed.min().item(), needed.max().item()
        missing = [cell for cell in _cells(needed, others) if not bool(reached.sel(cell))]
        return GapEffect(int(first.size), int((last < first).sum()), (float(first.min()), float(first.max())), (float(last.min()), float(last.max())),
                         needed, int(reached.sum()), low, high, missing)

    def isolation(self, mus: list[Any]) -> IsolationCounts:
        """Where each sliding base of ``mus`` gives a clearly lower or higher estimate than the fixed base, cell by cell."""
        stats = self.statistics
        fixed = fixed_base(stats)
        rows = []
        extremes: dict[str, list[tuple[float, xr.DataArray]]] = {"hurts": [], "helps": []}
        for mu in isolated_mus(mus):
            isolated = stats.sel(mu=mu)
            row = []
            for name in COMPARED:
                lower, higher = clearly(isolated, fixed, name)
                row += [int(lower.sum()), int(higher.sum()), int((~lower & ~higher).sum())]
            rows.append((mu, row))
            difference = isolated["pounding_probability"] - fixed["pounding_probability"]
            extremes["hurts"].append((mu, difference.where(isolated["pounding_probability_lower"] > fixed["pounding_probability_upper"])))
            extremes["helps"].append((mu, -difference.where(isolated["pounding_probability_upper"] < fixed["pounding_probability_lower"])))
        return IsolationCounts(rows, int(fixed["pounding_probability"].size), _largest(extremes["hurts"]), _largest(extremes["helps"]))

    def isolation_changes(self, mus: list[Any]) -> tuple[xr.DataArray, xr.DataArray]:
        """Per isolated cell (μ finite of ``mus``, every other label): where isolation clearly lowers and where it clearly raises
        P(pounding) against the fixed base."""
        finite = [m for m in mus if not is_fixed_base(m)]
        return clearly(self.statistics.sel(mu=finite), self.statistics.sel(mu=FIXED_BASE, drop=True), "pounding_probability")

    def isolation_totals(self, mus: list[Any]) -> tuple[int, int, int]:
        """The isolated cells where isolation clearly lowers P(pounding), where it clearly raises it, and all of them."""
        lower, higher = self.isolation_changes(mus)
        return int(lower.sum()), int(higher.sum()), int(lower.size)

    def sign_flip(self, mus: list[Any]) -> SignFlip | None:
        """Where isolation lowers and where it raises P(pounding), by the axis that separates the two best (None when it does not flip)."""
        lower, higher = self.isolation_changes(mus)
        if not (bool(lower.any()) and bool(higher.any())):
            return None
        best, purity = None, -1.0
        for dim in (d for d in lower.dims if lower.sizes[d] > 1):
            lowered, raised = lower.sum([d for d in lower.dims if d != dim]), higher.sum([d for d in higher.dims if d != dim])
            score = float(np.maximum(lowered, raised).sum() / (lowered + raised).sum())
            if score > purity:
                best, purity = (dim, lowered, raised), score
        if best is None:
            return None
        dim, lowered, raised = best
        return SignFlip(dim, [(v, int(lo), int(hi)) for v, lo, hi in zip(lowered[dim].values, lowered.values, raised.values) if lo + hi])

    def against(self, other: CellStatistics) -> list[tuple[str, int, int]]:
        """Cell by cell, per estimate of :data:`COMPARED`: the cells where ``other``'s is clearly higher and clearly lower than this one's."""
        a, b = self.statistics, other.statistics
        return [(name, int((b[f"{name}_lower"] > a[f"{name}_upper"]).sum()), int((b[f"{name}_upper"] < a[f"{name}_lower"]).sum())) for name in COMPARED]

    @property
    def cells(self) -> int:
        """The grid's cells."""
        return int(self.statistics["pounding_probability"].size)


def clearly(isolated: xr.Dataset, fixed: xr.Dataset, name: str) -> tuple[xr.DataArray, xr.DataArray]:
    """Cells where the isolated estimate of ``name`` is lower, and where it is higher, than the fixed base's with non-overlapping intervals."""
    return isolated[f"{name}_upper"] < fixed[f"{name}_lower"], isolated[f"{name}_lower"] > fixed[f"{name}_upper"]


def _largest(candidates: list[tuple[float, xr.DataArray]]) -> Largest | None:
    """The cell with the largest clear change of P(pounding) among each μ's changes (NaN where not clear), None if none."""
    found = [(float(change.max()), mu, change) for mu, change in candidates if bool(change.notnull().any())]
    if not found:
        return None
    _, mu, change = max(found, key=lambda item: item[0])
    where = change.where(change == change.max(), drop=True)
    labels = {d: where[d].values[0].item() for d in where.dims}
    return Largest({**labels, "mu": mu}, labels)


def _cells(data: xr.DataArray, dims: list[str]) -> list[CellLabels]:
    stacked = data.transpose(*dims).to_series() if dims else pd.Series([data.item()])
    return [dict(zip(dims, label if isinstance(label, tuple) else (label,))) for label in stacked.index] if dims else [{}]
