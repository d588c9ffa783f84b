"""Demand hazard curves of a store's stripes at its site, and moat-wall contact as a limit state.

From the contact-free runs (the contacts between buildings open; with a
moat wall on a variant axis, the walled runs, whose base displacement the
wall caps near its clearance) of a store with intensity stripes: the studied building's peak base
displacement (when it slides) and, with ``[output] demands = true``, every
building's peak storey drift and floor acceleration, each as a demand
hazard curve (:func:`~stochpound.risk.demand_hazard_curve`) over
:data:`DEMAND_LEVELS` levels from the 1 % quantile of its positive values
to its largest (and, for the base displacement, the moat clearances:
:func:`demand_levels`). When the scene has moat walls at the studied building's
base, the rate with which its base reaches each wall's clearance (before
the first wall impact a run with the wall equals the run without).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import xarray as xr

from collections.abc import Hashable, Sequence

from stochpound.hazard import HazardCurve, rate_from_probability
from stochpound.risk import _inputs
from stochpound.risk._fragility_ensemble import BOOTSTRAP
from stochpound.risk._maf import demand_hazard_curve, target_text
from stochpound.risk._chain import CONFIDENCE, YEARS, non_increasing_along
from stochpound.risk._collapse import beyond_model, collapse_fit, rate_collapses_apart

DEMAND_LEVELS = 40
"""Levels of each demand hazard curve."""
MOAT_REACHED = "base reaches the wall"
"""The moat table's row of a configuration with the wall: the rate its base reaches it."""
MOAT_PASSED = "no wall: base passes the walled twin's clearance (no stop modelled)"
"""The moat table's row of a configuration without the wall: the rate its base passes that clearance, with nothing there."""


@dataclasses.dataclass
class StoreDemands:
    """The demand hazard curves of one store at one site (:func:`store_demands`), with the moat table.

    ``moat_frame()`` is the moat table (per clearance: λ with its interval,
    the return period, the probability in ``years``);
    ``non_increasing_maf(label)`` a curve made non-increasing along its levels.

    Attributes
    ----------
    curves : dict of str to xarray.Dataset
        Per demand (e.g. ``"peak base displacement of B1"``), its
        :func:`~stochpound.risk.demand_hazard_curve` over ``level``.
    units : dict of str to str
        The display units of each demand's levels (``m`` or ``g``).
    moat : xarray.Dataset or None
        The studied building's base reaching each moat wall's clearance
        (``level``: the clearances, m), with its bootstrap interval; None
        without moat walls at its base.
    years : float
        The exposure time of the probabilities (yr).
    apart : {str: xarray.DataArray}
        Per demand (by label), its exceedance rate over ``level`` with the runs beyond
        the model counted apart as collapses (:func:`~stochpound.risk.rate_collapses_apart`:
        a collapse exceeds every level; 1/yr); empty where no run is beyond the model.
    beyond_model : xarray.DataArray or None
        The runs beyond the model per stripe and configuration (those counted apart); None where there are none.
    runs : xarray.DataArray or None
        The runs per stripe and configuration the demands come from (beside ``beyond_model``).
    walled : xarray.DataArray or None
        Per configuration, whether its runs have a moat wall (``stochpound.risk._inputs.walled_configurations``); in one
        without, ``moat`` is the rate its base passes the walled twin's clearance, where no stop is modelled. None: every
        configuration of ``moat`` has its wall.
    """

    curves: dict[str, xr.Dataset]
    units: dict[str, str]
    moat: xr.Dataset | None
    years: float = YEARS
    apart: dict[str, xr.DataArray] = dataclasses.field(default_factory=dict)
    beyond_model: xr.DataArray | None = None
    runs: xr.DataArray | None = None
    walled: xr.DataArray | None = None

    def levels_at(self, targets: Sequence[float], years: float) -> pd.DataFrame:
        """Per demand (its units in its name), configuration and target (a probability in ``years``): the level exceeded at the
        target's rate, ``as run`` and ``collapses apart`` (each curve made non-increasing, interpolated in ln level and ln λ; ``inf`` where the
        rate stays above the target at every level: the collapses alone are more frequent; NaN below the curve's lowest level)."""
        rows = []
        for label, curve in self.curves.items():
            ways = {"as run": self.non_increasing_maf(label)}
            if label in self.apart:
                ways["collapses apart"] = self.non_increasing_apart(label)
            for labels in _configurations(curve["maf"]):
                for target in targets:
                    allowed = float(rate_from_probability(float(target), years))
                    row = {"demand": f"{label} ({self.units[label]})", **labels, "target": target_text(float(target), years)}
                    for way, maf in ways.items():
                        row[way] = _level_at(curve["level"].values, maf.sel(labels).values, allowed)
                    rows.append(row)
        return pd.DataFrame(rows)

    def non_increasing_maf(self, label: str) -> xr.DataArray:
        """A demand's exceedance rate made non-increasing along its levels (isotonic regression in ln λ, pool-adjacent-violators; 1/yr)."""
        return non_increasing_along(self.curves[label]["maf"], "level")

    def beyond_model_per_stripe(self) -> list[tuple[float, int, int]]:
        """Per stripe, over every configuration: (its level in IM units, the runs counted apart as collapses, the runs); [] without any."""
        if self.beyond_model is None or self.runs is None:
            return []
        beyond = self.beyond_model.sum([d for d in self.beyond_model.dims if d != "intensity"])
        runs = self.runs.sum([d for d in self.runs.dims if d != "intensity"])
        return [(float(level), int(b), int(n)) for level, b, n in zip(beyond["intensity"].values, beyond.values, runs.values)]

    def non_increasing_apart(self, label: str) -> xr.DataArray:
        """A demand's exceedance rate with the collapses counted apart (``apart``), made non-increasing along its levels (1/yr)."""
        return non_increasing_along(self.apart[label], "level")

    def wall_exceedances(self, targets: Sequence[float], years: float) -> list[tuple[float, float, list[dict[str, Hashable]], int, float, float]]:
        """Per target and moat clearance, over the configurations that have the wall (``walled``; every configuration where it
        is None): (target, clearance m, those whose base reaches it more often than the target allows, the number of them, the
        largest rate of reaching it 1/yr, the rate the target allows 1/yr); [] without a moat. A configuration without the wall
        has no stop there (its base passes the clearance and slides on), so it limits nothing and is not counted."""
        if self.moat is None:
            return []
        rows = []
        for target in targets:
            allowed = float(rate_from_probability(float(target), years))
            for clearance in self.moat["level"].values:
                maf = self.moat["maf"].sel(level=clearance)
                every = [labels for labels in _configurations(maf) if self.has_wall(labels)]
                over = [labels for labels in every if float(maf.sel(labels)) > allowed]
                worst = max((float(maf.sel(labels)) for labels in every), default=math.nan)
                rows.append((float(target), float(clearance), over, len(every), worst, allowed))
        return rows

    def has_wall(self, labels: dict[str, Hashable]) -> bool:
        """Whether the configuration ``labels`` (of ``moat``) has its moat wall (True where ``walled`` is None)."""
        if self.walled is None:
            return True
        return bool(self.walled.sel({dim: value for dim, value in labels.items() if dim in self.walled.dims}).all())

    def wall_interval(self, clearance: float) -> tuple[float, float] | None:
        """The interval (yr) of the return period of reaching the wall at ``clearance`` in its worst configuration; None without a bootstrap."""
        if self.moat is None or "return_period_lower" not in self.moat:
            return None
        at = self.moat.sel(level=clearance)
        worst = at["maf"].fillna(-1.0).argmax(...)
        return float(at["return_period_lower"].isel(worst)), float(at["return_period_upper"].isel(worst))

    def moat_frame(self) -> pd.DataFrame:
        """The moat table: per clearance (m), the MAF of reaching it with its interval, the return period and the probability."""
        if self.moat is None:
            return pd.DataFrame()
        names = {"maf": "λ (1/yr)", "maf_lower": "λ lower", "maf_upper": "λ upper", "return_period": "once in (yr)",
                 "return_period_lower": "once in, lower (yr)", "return_period_upper": "once in, upper (yr)",
                 "probability": f"P in {self.years:g} yr", "probability_lower": "P lower", "probability_upper": "P upper"}
        frame = self.moat[[name for name in names if name in self.moat]].reset_coords(drop=True).to_dataframe().rename(columns=names)
        if self.walled is not None:  # what the rate is of, per row: a wall reached, or a clearance passed with nothing there
            rows = frame.index.to_frame(index=False)
            labels = [{dim: row[dim] for dim in self.walled.dims} for _, row in rows.iterrows()]
            frame.insert(0, "what it is", [MOAT_REACHED if self.has_wall(one) else MOAT_PASSED for one in labels])
        return frame.rename_axis(index={"level": "moat clearance (m)"})  # a plain index (one configuration) or a MultiIndex


def store_demands(store: xr.Dataset, hz: HazardCurve | None = None, confidence: float = CONFIDENCE, bootstrap: int = BOOTSTRAP,
                  seed: int = 0) -> StoreDemands | None:
    """The demand hazard curves of a store with intensity stripes at a site (None for IDA runs or a store without demands).

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store with intensity stripes.
    hz : HazardCurve, optional
        The site's hazard; default the one the store carries.
    confidence : float
        Confidence of the moat table's interval.
    bootstrap : int
        Resamples of the motions for the moat table's interval (the curves have none).
    seed : int
        Seed of the resamples.
    """
    if _inputs.stripes(store) is None:
        return None
    hz = _inputs.site_hazard(store) if hz is None else hz
    studied = _inputs.studied_building(store)
    demands: dict[str, tuple[xr.DataArray, str]] = {}
    sliding = _inputs.base_displacement(store, studied, walls_free=True)
    base = f"peak base displacement of {studied}"
    if sliding is not None:
        demands[base] = (sliding, "m")
    demands.update(_inputs.stored_demands(store))
    if not demands:
        return None
    collapsed = _inputs.demand_drift(store)
    collapsed = None if collapsed is None else beyond_model(collapsed)
    collapsed = collapsed if collapsed is not None and bool((collapsed == 1.0).any()) else None
    collapse = None if collapsed is None else collapse_fit(collapsed, hz)  # P(C | IM) once: every demand's runs are the same runs
    clearances = _inputs.moat_clearances(store, studied)
    curves, apart = {}, {}
    for label, (demand, _) in demands.items():
        levels = demand_levels(demand, clearances if label == base else ())
        curves[label] = demand_hazard_curve(demand, levels, hz, confidence=confidence, bootstrap=0)
        if collapsed is not None:
            apart[label] = rate_collapses_apart(demand, collapsed, levels, "level", hz, collapse)[0].assign_coords(level=levels)
    moat = (demand_hazard_curve(sliding, clearances, hz, confidence=confidence, bootstrap=bootstrap, seed=seed)
            if sliding is not None and clearances else None)
    counts = (None, None) if collapsed is None else (collapsed.sum("record"), collapsed.notnull().sum("record"))
    return StoreDemands(curves, {label: units for label, (_, units) in demands.items()}, moat, apart=apart, beyond_model=counts[0], runs=counts[1],
                        walled=_inputs.walled_configurations(store) if moat is not None else None)


def demand_levels(demand: xr.DataArray, clearances: Sequence[float] = ()) -> np.ndarray:
    """The levels of a demand's hazard curve: ``DEMAND_LEVELS`` log-spaced from the 1 % quantile of its positive values to its
    largest, with the moat clearances inside that range added (a walled run's base displacement stops at its clearance, so
    its curve drops there: read between coarser levels, the displacement at a target's rate would fall short of a wall the
    base reaches more often than the target allows)."""
    values = demand.values[np.isfinite(demand.values) & (demand.values > 0)]
    levels = np.geomspace(np.quantile(values, 0.01), values.max(), DEMAND_LEVELS)
    inside = [c for c in clearances if levels[0] < c < levels[-1]]
    return np.union1d(levels, inside) if inside else levels


def _configurations(data: xr.DataArray) -> list[dict[str, Hashable]]:
    """Every combination of ``data``'s labels other than ``level``."""
    dims = [d for d in data.dims if d != "level"]
    index = pd.MultiIndex.from_product([data[d].values for d in dims], names=dims) if dims else [()]
    return [dict(zip(dims, labels if isinstance(labels, tuple) else (labels,))) for labels in index]


def _level_at(levels: np.ndarray, maf: np.ndarray, rate: float) -> float:
    """The level at which a non-increasing exceedance curve ``maf`` falls to ``rate`` (log-log interpolation); inf where it never
    does, NaN where it is below ``rate`` already at the lowest level."""
    above = maf > rate
    if above.all():
        return math.inf
    if not above[0]:
        return math.nan
    i = int(np.argmin(above))  # the first level at or below the rate
    if maf[i] <= 0.0:
        return float(levels[i - 1])
    fraction = (np.log(rate) - np.log(maf[i - 1])) / (np.log(maf[i]) - np.log(maf[i - 1]))
    return float(np.exp(np.log(levels[i - 1]) + fraction * (np.log(levels[i]) - np.log(levels[i - 1]))))
