"""A mechanism's per-cell comparison read cell by cell: which cells ratchet or raise a demand, which lower it, which are too short.

:func:`~stochpound.analysis.ratcheting` and :func:`~stochpound.analysis.amplification`
return one dataset over the grid's cells; :class:`MechanismCells` holds it with
the name of its flag (``ratchets``, ``raises``) and answers what a report
states of it: the cells assessed, those flagged (largest effect first), those
lowered, the counts along each axis, the range of the ratios. :class:`WallPenetration`
is the largest penetration of a moat's walls over an ensemble's runs, and where.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import xarray as xr

from stochpound.analysis._cells import CellLabels

@dataclass(frozen=True)
class MechanismCells:
    """A per-cell comparison of the runs with impacts against their twins without.

    Attributes
    ----------
    found : xarray.Dataset
        :func:`~stochpound.analysis.ratcheting`'s or :func:`~stochpound.analysis.amplification`'s result, computed.
    flag : str
        Its flag of a resolved effect: ``ratchets`` or ``raises``.
    effect : str
        The variable that orders the flagged cells, largest first: ``abs_change_mean`` or ``ratio_mean``.
    count : str
        The variable of the paired runs' count: ``abs_count`` or ``with_count``.
    """

    found: xr.Dataset
    flag: str
    effect: str
    count: str

    def cells(self) -> list[CellLabels]:
        """The labels of every cell, in grid order."""
        data = self.found[self.flag]
        stacked = data.stack(cell=list(data.dims)) if data.dims else data.expand_dims(cell=[0])
        return [{d: stacked[d].values[i].item() for d in data.dims} for i in range(stacked.sizes["cell"])]

    def assessed(self) -> list[CellLabels]:
        """The cells with enough paired runs."""
        return [c for c in self.cells() if bool(self.found["enough"].sel(c))]

    def short(self) -> list[CellLabels]:
        """The cells with too few paired runs."""
        return [c for c in self.cells() if not bool(self.found["enough"].sel(c))]

    def flagged(self) -> list[CellLabels]:
        """The assessed cells where the effect is resolved, the largest effect first."""
        return sorted((c for c in self.assessed() if bool(self.found[self.flag].sel(c))), key=lambda c: -float(self.found[self.effect].sel(c)))

    def lowered(self) -> list[CellLabels]:
        """The assessed cells where the impacts resolve the opposite effect (``lowers``)."""
        return [c for c in self.assessed() if bool(self.found["lowers"].sel(c))]

    def pushed_away(self) -> xr.DataArray:
        """Cells where the impacts move the residual away from the neighbour (interval above 0) without a resolved change of its size
        (ratcheting only): neither ratcheting (size up) nor lowering it (size down, :meth:`lowered`), so that a cell is in one class."""
        return self.found["enough"] & ~self.found["ratchets"] & ~self.found["lowers"] & (self.found["away_change_lower"] > 0)

    def pushed(self) -> list[CellLabels]:
        """The assessed cells of :meth:`pushed_away`."""
        return [c for c in self.assessed() if bool(self.pushed_away().sel(c))]

    @property
    def most_runs(self) -> int:
        """The most paired runs of a cell."""
        return int(self.found[self.count].max())

    @property
    def flagged_count(self) -> int:
        """How many cells the effect is resolved in."""
        return int(self.found[self.flag].sum())

    @property
    def assessed_count(self) -> int:
        """How many cells have enough paired runs."""
        return int(self.found["enough"].sum())

    def ratio_range(self) -> tuple[float, float] | None:
        """The smallest and largest mean per-run ratio over the cells that raise (amplification only); None where none does."""
        if not bool(self.found["raises"].any()):
            return None
        raised = self.found["ratio_mean"].where(self.found["raises"])
        return float(raised.min()), float(raised.max())

    def by_axis(self) -> list[tuple[str, list[tuple[Any, int, int]]]]:
        """Along each axis of more than one value: per value, the assessed cells where the effect is resolved and the assessed cells."""
        flags, enough = self.found[self.flag], self.found["enough"]
        counted = []
        for dim in (d for d in flags.dims if flags.sizes[d] > 1):
            others = [d for d in flags.dims if d != dim]
            held, assessed = (flags & enough).sum(others), enough.sum(others)
            counted.append((dim, [(v.item(), int(h), int(a)) for v, h, a in zip(flags[dim].values, held.values, assessed.values)]))
        return counted


@dataclass(frozen=True)
class WallPenetration:
    """The largest penetration of the walls over an ensemble's runs with a wall.

    Attributes
    ----------
    runs : int
        The runs with a wall.
    largest : float
        The largest penetration, m (NaN without a run).
    at : CellLabels
        The labels of its cell and realization (empty without a run).
    per_value : list of (value, float)
        The largest per value of the wall axis (m; empty without one).
    realization : int or None
        The realization of the largest (None without a run, or runs without a realization dimension).
    """

    runs: int
    largest: float
    at: CellLabels
    per_value: list[tuple[Any, float]]
    realization: int | None = None

    @classmethod
    def of(cls, penetration: xr.DataArray, walls: str | None) -> WallPenetration:
        """From the runs' ``peak_wall_penetration`` (m, NaN for a run without a wall) and the axis that sets the walls (if any)."""
        runs = int(penetration.notnull().sum())
        if runs == 0:
            return cls(0, float("nan"), {}, [])
        where = penetration.where(penetration == penetration.max(), drop=True)
        at = {d: where[d].values[0].item() for d in where.dims}
        per_value = [] if walls is None else [(v.item(), float(penetration.sel({walls: v}).max())) for v in penetration[walls].values]
        realization = int(where["realization"].values[0]) if "realization" in where.dims else None
        return cls(runs, float(penetration.max()), at, per_value, realization)
