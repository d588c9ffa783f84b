"""One synthetic ensemble of an experiment store: its realizations per grid cell, and the statistics a report states of them.

An ensemble is one label of a store's ``record`` dimension whose realizations
are random motions; a grid cell is one combination of the store's other axes
(gaps, μ, …). :class:`StoreEnsemble` selects the realizations that ran, the
studied building's values, and computes what the report formats: the
statistics of every cell (:func:`~stochpound.analysis.ensemble_statistics`),
the probability of pounding and the means with their intervals per cell, and
the running estimates over the first n realizations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
import xarray as xr

from stochpound.analysis._ensemble_statistics import ensemble_statistics
from stochpound.analysis._intervals import MIN_RUNS, mean_interval, of_first
from stochpound.analysis._mechanism_cells import MechanismCells, WallPenetration
from stochpound.analysis.mechanisms import amplification, ratcheting
from stochpound.analysis._pounding import pounding_probability
from stochpound.stats import kernels
from stochpound.store import isolated_mus, walls_only

CONVERGENCE_POINTS = 8
"""Sample sizes, from :data:`MIN_RUNS` to the ensemble's size (geometrically spaced), at which running estimates are taken."""
RARE = 0.05
"""The probability of pounding below which (its upper Clopper–Pearson bound) pounding is rare."""
CONVERGENCE_PANELS = 4
"""Most panels of a convergence figure: the cells slowest to settle (P(pounding) nearest 0.5), not every cell."""


@dataclass(frozen=True)
class ProbabilityAt:
    """P(pounding) (or of another event) over the cells at one value of an axis: ``value``, ``cells``, ``fewest`` runs of a cell,
    ``lowest`` and ``highest`` probability, and the ``highest_upper`` bound of its interval."""

    value: Any
    cells: int
    fewest: int
    lowest: float
    highest: float
    highest_upper: float


class StoreEnsemble:
    """One synthetic ensemble of a store, its grid and its statistics.

    Parameters
    ----------
    name : str
        The experiment's name.
    store : xarray.Dataset
        The store.
    label : str
        The ensemble's label on the ``record`` dimension.
    confidence : float
        Level of every interval.
    """

    def __init__(self, name: str, store: xr.Dataset, label: str, confidence: float = 0.95) -> None:
        self.name, self.label, self.confidence = name, label, confidence
        status = store["case_status"].sel(record=label)
        realizations = (status >= 0).any([d for d in status.dims if d != "realization"]).values
        self.data = store.sel(record=label).isel(realization=np.flatnonzero(realizations))
        self.studied = store.pound.provenance.studied_building
        self.grid = {d: self.data[d].values.tolist() for d in status.dims if d not in ("record", "realization")}

    @property
    def mus(self) -> list[float]:
        """The friction coefficients of the ensemble's ``mu`` axis (none without one; ∞: the fixed base)."""
        return self.data["mu"].values.tolist() if "mu" in self.grid else []

    @property
    def size(self) -> int:
        """Realizations per cell."""
        return self.data.sizes["realization"]

    @cached_property
    def statistics(self) -> xr.Dataset:
        """:func:`stochpound.analysis.ensemble_statistics` of every cell, computed, the studied building selected."""
        return self._studied(ensemble_statistics(self.data, confidence=self.confidence)).compute()

    def _studied(self, data: Any) -> Any:
        return data.sel(building=self.studied, drop=True) if "building" in data.dims else data

    def sample(self, variable: str) -> xr.DataArray:
        """A summary's values per cell and realization (the studied building's), loaded."""
        return self._studied(self.data[variable]).load()

    def twin_sample(self, variable: str) -> xr.DataArray | None:
        """The fixed-base twin's values of ``variable`` (the studied building's), loaded; None if the store lacks it."""
        return self._studied(self.data[variable]).load() if variable in self.data else None

    @property
    def walls_only(self) -> bool:
        """Whether the store's only impact elements are walls (no contact): every impact is a wall hit, which has no phase."""
        return walls_only(self.data)

    @property
    def sliding(self) -> bool:
        """Whether any case of the ensemble slides."""
        return "peak_sliding_displacement" in self.data and bool((self.sample("peak_sliding_displacement") > 0).any())

    def pounding(self) -> xr.Dataset:
        """P(pounding) of every cell with its Clopper–Pearson interval: ``estimate``, ``lower``, ``upper``, ``count``."""
        result = pounding_probability(self.sample("impacts")).compute()
        return xr.Dataset({"estimate": result["probability"], "lower": result["lower"], "upper": result["upper"], "count": result["realizations"]})

    def means(self, variable: str, factor: float = 1.0, pounding_only: bool = False) -> xr.Dataset:
        """The mean of ``variable`` × ``factor`` (over the runs that pound, with ``pounding_only``) in every cell with its
        percentile-bootstrap interval over the runs (:func:`stochpound.analysis.mean_interval`; NaN from fewer than MIN_RUNS):
        ``estimate``, ``lower``, ``upper``, ``count``."""
        values = self.sample(variable) * factor
        if pounding_only:
            values = values.where(self.sample("impacts") > 0)
        result = mean_interval(values, "realization", method="bootstrap").compute()
        enough = result["count"] >= MIN_RUNS
        return xr.Dataset({"estimate": result["mean"].where(enough), "lower": result["lower"].where(enough),
                           "upper": result["upper"].where(enough), "count": result["count"]})

    @property
    def convergence_counts(self) -> np.ndarray:
        """The sample sizes of the running estimates: :data:`CONVERGENCE_POINTS` from :data:`MIN_RUNS` to the size, geometrically spaced."""
        return np.unique(np.round(np.geomspace(MIN_RUNS, self.size, CONVERGENCE_POINTS)).astype(int))

    def running_pounding(self) -> xr.Dataset:
        """P(pounding) with its Clopper–Pearson interval from the first n realizations, n of :attr:`convergence_counts`."""
        return of_first(lambda first: pounding_probability(first, confidence=self.confidence), self.sample("impacts"),
                        self.convergence_counts).compute()

    def running_mean(self, variable: str) -> xr.Dataset:
        """The mean of ``variable`` with its percentile-bootstrap interval from the first n realizations, n of :attr:`convergence_counts`."""
        return of_first(lambda first: mean_interval(first, confidence=self.confidence, method="bootstrap"), self.sample(variable),
                        self.convergence_counts).compute()

    def probability_along(self, axis: str, events: str = "impacts") -> tuple[list[str], list[ProbabilityAt]]:
        """The fraction of runs with ``events`` (impacts, a wall's penetration) > 0 in every cell, with its Clopper–Pearson
        interval, summarised at each value of ``axis`` over the other axes: those other axes, and per value of ``axis``
        its cells, fewest runs, lowest and highest probability and highest upper bound."""
        probability = pounding_probability(self.data[events], confidence=self.confidence).compute()
        others = [d for d in probability["probability"].dims if d != axis]
        rows = []
        for value in probability[axis].values:
            at = probability.sel({axis: value})
            rows.append(ProbabilityAt(value.item(), int(at["probability"].size), int(at["realizations"].min()), float(at["probability"].min()),
                                      float(at["probability"].max()), float(at["upper"].max())))
        return others, rows

    @property
    def none_upper_bound(self) -> float:
        """The upper Clopper–Pearson bound of P(pounding) when none of the ensemble's runs pounds (the smallest probability it resolves)."""
        return float(kernels.clopper_pearson(0, self.size, self.confidence)[1])

    def rare_gap(self, dim: str) -> xr.DataArray:
        """The smallest gap of gap axis ``dim`` from which on pounding is rare in every cell (:func:`rare_gap` of the statistics' upper bound)."""
        return rare_gap(self.statistics["pounding_probability_upper"], dim)

    def slowest_panels(self, line_dim: str | None) -> dict[str, list[Any]]:
        """The grid's axes other than ``line_dim``, the longest cut (repeatedly) to its values with P(pounding) nearest 0.5, to at
        most :data:`CONVERGENCE_PANELS` combinations."""
        panels = {d: list(v) for d, v in self.grid.items() if d != line_dim}
        probability = self.statistics["pounding_probability"]
        while math.prod(len(v) for v in panels.values()) > CONVERGENCE_PANELS:
            dim = max(panels, key=lambda d: len(panels[d]))
            if len(panels[dim]) == 1:
                break
            others = math.prod(len(v) for d, v in panels.items() if d != dim)
            keep = max(1, min(len(panels[dim]) - 1, CONVERGENCE_PANELS // others))
            distance = abs(probability.mean([d for d in probability.dims if d != dim]).sel({dim: panels[dim]}).values - 0.5)
            kept = sorted(np.argsort(distance, kind="stable")[:keep])
            panels[dim] = [panels[dim][i] for i in kept]
        return panels


    def ratcheting_against(self, free: StoreEnsemble, away: int) -> MechanismCells:
        """:func:`stochpound.analysis.ratcheting` of the studied building's residual sliding in this ensemble's cells on a sliding
        base (a μ axis's fixed-base cells left out) against ``free`` (the contact-free twins), from :data:`MIN_RUNS` paired runs."""
        residual, twin = self.sample("residual_sliding"), free.sample("residual_sliding")
        if "mu" in residual.dims:
            sliding = isolated_mus(residual["mu"].values)
            residual, twin = residual.sel(mu=sliding), twin.sel(mu=sliding)
        found = ratcheting(residual, twin, away, MIN_RUNS, confidence=self.confidence).compute()
        return MechanismCells(found, "ratchets", "abs_change_mean", "abs_count")

    def amplification_over(self, twins: StoreEnsemble, variable: str) -> MechanismCells:
        """:func:`stochpound.analysis.amplification` of the studied building's demand ``variable`` in this ensemble's cells over
        ``twins`` (the same motions without impacts), from :data:`MIN_RUNS` paired runs."""
        found = amplification(self.sample(variable), twins.sample(variable), MIN_RUNS, confidence=self.confidence).compute()
        return MechanismCells(found, "raises", "ratio_mean", "with_count")

    def wall_penetration(self, walls: str | None = None) -> WallPenetration:
        """The largest wall penetration over the runs (and per value of ``walls``, the axis that sets the walls, if any)."""
        return WallPenetration.of(self.sample("peak_wall_penetration"), walls)


def rare_gap(upper: xr.DataArray, dim: str) -> xr.DataArray:
    """The smallest value of gap axis ``dim`` from which on every larger gap has P(pounding)'s upper bound ``upper`` below :data:`RARE` (m, NaN if none)."""
    rare = (upper < RARE).transpose(dim, ...)
    # rare from this gap on: a reversed cumulative "all"
    from_here = rare.isel({dim: slice(None, None, -1)}).cumprod(dim).isel({dim: slice(None, None, -1)}).astype(bool)
    gaps = xr.DataArray(np.asarray(upper[dim].values, dtype=float), dims=dim, coords={dim: upper[dim]})
    return gaps.where(from_here).min(dim)
