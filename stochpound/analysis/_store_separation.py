"""How wide the gap must be, from a store's contact-free (or wall-free) runs of one synthetic ensemble.

Before its first impact a run with gap g is the contact-free run, so a case
pounds at gap g exactly when its contact-free twin's peak closure D reaches g
(docs/separation.md); the same holds for a moat's clearance and the wall-free
runs (:data:`WALLS`). :class:`StoreSeparation` holds D per cell and
realization and computes from it what a report states: the separation needed
for target probabilities, the pounding curve P(D ≥ g), each separation rule's
gap and the probability that it is reached, and the check of the identity
against the store's own runs at its finite gaps.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import xarray as xr

from stochpound.analysis._cells import CellLabels
from stochpound.analysis._pounding import pounding_probability
from stochpound.analysis._separation import TARGET_PROBABILITIES, pounding_curve, required_separation, rule_exceedance
from stochpound.analysis._store_ensemble import RARE, StoreEnsemble, rare_gap
from stochpound.codes import separation_rules, store_contact_demands
from stochpound.store import contact_free, contact_gap_dims, wall_free, wall_gap_dims, with_contacts, with_walls

CURVE_PROBABILITIES = tuple(np.round(np.geomspace(0.005, 0.9, 31), 5))
"""Target probabilities of the separation-against-probability curve."""
CURVE_POINTS = 211
"""Gaps at which the pounding curve is drawn, from 0 to 1.05 times the 99.5 % quantile of D over all cells."""
TIE = 1e-9
"""A closure within this of a gap (m) is a tie: neither closing it nor not."""


@dataclass(frozen=True)
class Closure:
    """What a separation separates, and the words for it: buildings from each other, or a building from its moat's walls.

    Attributes
    ----------
    kind : str
        ``contacts`` (between buildings: the separation rules apply) or ``walls``.
    variable : str
        The store's peak closure D of a run (m), per ``contact`` (the largest is taken) or one per run.
    events : str
        The store variable that is positive in a run that closed the gap (impacts, or the wall penetration).
    event : str
        The event, as in "P(pounding)".
    gap : str
        The separation's name ("gap", "clearance"), ``symbol`` its letter.
    free : str
        The runs whose gaps never close ("contact-free", "wall-free").
    free_cases, finite_cases, axes : callable
        The store's runs at ``inf``, its runs at the finite values, and the gap axes concerned
        (:func:`stochpound.store.contact_free` …).
    """

    kind: str
    variable: str
    events: str
    event: str
    gap: str
    symbol: str
    free: str
    free_cases: Callable[[xr.Dataset], xr.Dataset]
    finite_cases: Callable[[xr.Dataset], xr.Dataset]
    axes: Callable[[xr.Dataset], list[str]]

    @property
    def walls(self) -> bool:
        """Whether the gap separates a building from walls (no separation rules then)."""
        return self.kind == "walls"

    def demand(self, data: xr.Dataset) -> xr.DataArray:
        """The run's peak closure D (m) that decides whether it closes a gap: the largest over the contacts (NaN if one is)."""
        demand = data[self.variable].load()
        return demand.max("contact", skipna=False) if "contact" in demand.dims else demand


CONTACTS = Closure("contacts", "peak_contact_closure", "impacts", "pounding", "gap", "g", "contact-free", contact_free, with_contacts, contact_gap_dims)
"""The gap between buildings: gap axes that set contacts, their contact-free runs."""
WALLS = Closure("walls", "largest_wall_closure", "peak_wall_penetration", "wall hit", "clearance", "c", "wall-free", wall_free, with_walls, wall_gap_dims)
"""A moat's clearance: gap axes that set walls only, their wall-free runs (walls never reached, the closure toward them located)."""


def rule_gaps(free: xr.Dataset) -> xr.DataArray:
    """Each separation rule's gap per case of the contact-free runs ``free``, the largest over contacts (m)."""
    return separation_rules(store_contact_demands(free)).max("contact")


@dataclass(frozen=True)
class ValueRange:
    """The smallest and largest finite value of an array (over its cells, NaN ignored)."""

    low: float
    high: float

    @classmethod
    def of(cls, values: xr.DataArray | np.ndarray) -> ValueRange | None:
        """The range of ``values``' finite values; None if there is none."""
        array = np.asarray(values, dtype=float)
        finite = array[np.isfinite(array)]
        return cls(float(finite.min()), float(finite.max())) if finite.size else None


@dataclass(frozen=True)
class Needed:
    """The separation needed for target probabilities (:func:`~stochpound.analysis.required_separation`'s result, computed)."""

    data: xr.Dataset

    def __getitem__(self, variable: str) -> xr.DataArray:
        return self.data[variable]

    @property
    def fewest_runs(self) -> int:
        """The fewest realizations of a cell."""
        return int(self.data["realizations"].min())

    @property
    def most_runs(self) -> int:
        """The most realizations of a cell."""
        return int(self.data["realizations"].max())

    @property
    def cells(self) -> int:
        """The grid's cells."""
        return int(self.data["separation"].isel(probability=0).size)

    def extreme_cells(self, probability: float) -> tuple[CellLabels, CellLabels]:
        """Labels of the cells with the smallest and largest separation needed for ``probability`` (NaN ignored; the first
        cell twice when none is finite)."""
        values = self.data["separation"].sel(probability=probability)
        flat = values.stack(cell=values.dims) if values.dims else values.expand_dims(cell=[0])
        order = np.argsort(np.where(np.isnan(flat.values), np.inf, flat.values))
        finite = [i for i in order if np.isfinite(flat.values[i])] or [int(order[0])]

        def labels(i: int) -> CellLabels:
            return {d: flat[d].values[i].item() for d in values.dims}

        return labels(finite[0]), labels(finite[-1])

    def extremes(self, probability: float) -> tuple[CellLabels, CellLabels] | None:
        """Labels of the first cells with the smallest and the largest finite separation needed for ``probability``; None
        with fewer than two finite cells."""
        values = self.data["separation"].sel(probability=probability)
        finite = values.where(np.isfinite(values))
        if finite.size < 2 or int(finite.notnull().sum()) < 2:
            return None
        stacked = finite.stack(cell=finite.dims)

        def labels(i: int) -> CellLabels:
            return {d: stacked[d].values[i].item() for d in finite.dims}

        return labels(int(np.nanargmin(stacked.values))), labels(int(np.nanargmax(stacked.values)))

    def missing_upper(self, probability: float) -> int:
        """The cells without an upper bound of the separation for ``probability`` (too few runs)."""
        return int(self.data["upper"].sel(probability=probability).isnull().sum())


@dataclass(frozen=True)
class IdentityCheck:
    """The store's runs at its finite gaps against the free runs' closures: at gaps ``gaps`` (m), ``compared`` runs, of which
    ``disagree`` close a gap where D does not reach it or the reverse, and ``ties`` (D within :data:`TIE` of the gap) not counted."""

    gaps: np.ndarray
    compared: int
    disagree: int
    ties: int


@dataclass(frozen=True)
class RuleReach:
    """How often a separation rule's gap is reached: the probability's range over the cells, and the share of cells whose
    upper bound is at most the target."""

    rule: str
    lowest: float
    highest: float
    share_within: float


@dataclass(frozen=True)
class GridRare:
    """The grid's own answer to "which gap makes pounding rare" (:func:`rare_gap` per cell, m, NaN where none) against the
    quantile of D: in how many cells it is known, and at or above the estimate and the upper bound."""

    gap: xr.DataArray
    known: int
    cells: int
    above_estimate: int
    above_bound: int


class StoreSeparation:
    """The contact-free (wall-free) cells of one synthetic ensemble and the separation (clearance) they call for.

    Parameters
    ----------
    name : str
        The experiment's name.
    store : xarray.Dataset
        The whole store (its free runs and its runs at finite gaps).
    label : str
        The ensemble's label on the ``record`` dimension.
    confidence : float
        Level of every interval.
    closure : Closure
        :data:`CONTACTS` or :data:`WALLS`.
    """

    def __init__(self, name: str, store: xr.Dataset, label: str, confidence: float = 0.95, closure: Closure = CONTACTS) -> None:
        self.ensemble = StoreEnsemble(name, closure.free_cases(store), label, confidence)
        self.name, self.label, self.confidence, self.closure = name, label, confidence, closure
        self.demand = closure.demand(self.ensemble.data)
        # the runs at the grid's finite gaps, compared with D when one gap axis sets every gap
        axes = closure.axes(store)
        finite = store[axes[0]].values[np.isfinite(store[axes[0]].values)] if len(axes) == 1 else []
        self.gap_axis = axes[0] if len(finite) else None
        self.impacts = StoreEnsemble(name, closure.finite_cases(store), label, confidence).data[closure.events].load() if self.gap_axis else None

    def needed(self, probabilities: Sequence[float] = TARGET_PROBABILITIES) -> Needed:
        """The separation needed for each target probability, with its order-statistic interval, computed."""
        return Needed(required_separation(self.demand, probabilities, confidence=self.confidence, contact_dim=None).compute())

    def rule_gaps(self) -> xr.DataArray:
        """Each separation rule's gap per case (m), loaded."""
        return rule_gaps(self.ensemble.data).load()

    @staticmethod
    def rule_gaps_of(free: xr.Dataset) -> xr.DataArray:
        """Each separation rule's gap per case of the contact-free runs ``free`` (records, say), the largest over contacts (m)."""
        return rule_gaps(free)

    @staticmethod
    def mean_rule_gaps(rules: xr.DataArray) -> xr.DataArray:
        """Each rule's gap ``rules`` averaged over the realizations (m)."""
        return rules.mean("realization")

    def exceedance(self, rules: xr.DataArray) -> xr.Dataset:
        """The probability that each rule's gap ``rules`` is reached, P(D ≥ the rule's gap), with its interval, computed."""
        return rule_exceedance(self.demand, rules, confidence=self.confidence, contact_dim=None).compute()

    def rule_reach(self, exceedance: xr.Dataset, target: float) -> list[RuleReach]:
        """Per rule of ``exceedance``: its probability's range over the cells and the share of cells with an upper bound ≤ ``target``."""
        return [RuleReach(str(rule), float(exceedance["probability"].sel(rule=rule).min()), float(exceedance["probability"].sel(rule=rule).max()),
                          float((exceedance["upper"].sel(rule=rule) <= target).mean())) for rule in exceedance["rule"].values]

    def hit_probability(self) -> xr.Dataset:
        """The fraction of the store's runs at its finite gaps that closed one (P(pounding), P(wall hit)) with its interval, computed."""
        return pounding_probability(self.impacts, confidence=self.confidence).compute()

    def curve_at_grid(self) -> xr.Dataset:
        """P(D ≥ g) from the contact-free (wall-free) runs at the grid's finite gaps, on the gap axis, with its interval, computed
        (call when :attr:`gap_axis` is not None)."""
        axis = self.gap_axis
        curve = pounding_curve(self.demand, self.impacts[axis].values, confidence=self.confidence, contact_dim=None).compute()
        return curve.rename(gap=axis) if axis != "gap" else curve

    def curve_agreement(self) -> tuple[int, int]:
        """In how many cells, of how many, the runs at the grid's gaps closed one in a fraction within the interval of
        P(D ≥ g) (call when :attr:`gap_axis` is not None)."""
        curve, direct = self.curve_at_grid(), self.hit_probability()
        inside = ((direct["probability"] >= curve["lower"]) & (direct["probability"] <= curve["upper"])) | direct["probability"].isnull()
        return int(inside.sum()), int(inside.size)

    def curve_gaps(self) -> np.ndarray:
        """The gaps of the drawn pounding curve (m): :data:`CURVE_POINTS` from 0 to 1.05 times the 99.5 % quantile of D over all
        cells (the far tail of one cell would squeeze the others), to 0.105 m without a finite D."""
        finite = self.demand.values[np.isfinite(self.demand.values)]
        top = float(np.quantile(finite, 0.995)) if finite.size else 0.1
        return np.linspace(0.0, 1.05 * top, CURVE_POINTS)

    def curve(self, gaps: np.ndarray) -> xr.Dataset:
        """P(D ≥ g) at ``gaps`` (m) in every cell, with its interval, computed."""
        return pounding_curve(self.demand, gaps, confidence=self.confidence, contact_dim=None).compute()

    def curve_probabilities(self) -> list[float]:
        """The target probabilities of :data:`CURVE_PROBABILITIES` an ensemble of this size can answer (p ≥ 1/n)."""
        return [p for p in CURVE_PROBABILITIES if p >= 1.0 / max(self.ensemble.size, 1)]

    def identity_check(self) -> IdentityCheck | None:
        """The runs at the store's finite gaps against the free closures of the same cells and realizations (None without them)."""
        if self.gap_axis is None:
            return None
        axis, impacts = self.gap_axis, self.impacts
        pounded = (impacts > 0).where(impacts.notnull())
        gaps = xr.DataArray(impacts[axis].values, dims=axis)
        reached = (self.demand >= gaps).where(self.demand.notnull())
        both = pounded.notnull() & reached.notnull()
        ties = both & (abs(self.demand - gaps) <= TIE)
        return IdentityCheck(gaps.values, int((both & ~ties).sum()), int(((pounded != reached) & both & ~ties).sum()), int(ties.sum()))

    def grid_rare(self, needed: Needed, probability: float) -> GridRare | None:
        """The grid's own gap from which pounding is rare, per cell, against the separation needed for ``probability``
        (None without finite gaps or unless ``probability`` is :data:`RARE`)."""
        if self.gap_axis is None or probability != RARE:
            return None
        upper = pounding_probability(self.impacts, confidence=self.confidence)["upper"].compute()
        grid = rare_gap(upper, self.gap_axis)
        estimate, bound = needed["separation"].sel(probability=probability), needed["upper"].sel(probability=probability)
        known = grid.notnull()
        return GridRare(grid, int(known.sum()), int(known.size), int((known & (grid >= estimate)).sum()), int((known & (grid >= bound)).sum()))

