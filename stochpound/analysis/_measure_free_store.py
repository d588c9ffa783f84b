"""The answer without an intensity measure for an experiment store's scenes (issue 44, item 4; docs/measure-free.md).

For every configuration of a store (each combination of its grid's axes
other than the gap, the stripe and the motion), the scene its conditioned
answer ran (:func:`~stochpound.risk.configuration_scene`: its contact-free
case, every gap ``inf``) is run under simulated motions of each rupture of
a site (:func:`~stochpound.analysis.measure_free_demands`), and from the
same runs come the rate of exceedance and the level at each target of
its demands: the largest contact-free closure (by the gap identity, the
pounding rate of every gap; its level is g*), the base displacement of
every building on a sliding base and the storey drift of every building
(the largest over its storeys). The extra runs go where the closure's g*
of the rarest target needs them. Every configuration runs the same
motions (the same seed), so their answers differ by the structure alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import pandas as pd
import xarray as xr

from stochpound.analysis._measure_free import MeasureFreeDemand, measure_free_demands
from stochpound.hazard import RuptureSite
from stochpound.model.scene import Scene

MEASURE_FREE_RUNS = 300
"""Runs per configuration of :func:`store_measure_free` by default (half of them the first stage, the rest allocated)."""
CASE_DIMS = ("intensity", "record", "realization", "contact")
"""Dimensions of the contact-free closure that are not a configuration's: the stripe, the motion and the contact."""


@dataclass(frozen=True)
class StoreMeasureFree:
    """The answer without an intensity measure for each configuration of a store (:func:`store_measure_free`).

    Attributes
    ----------
    site : str
        The site of ruptures in words (:meth:`~stochpound.analysis.RuptureSite.describe`).
    site_name : str
        Its name (a bundled site's, or given; "a site of ruptures" without one).
    configurations : tuple of tuple
        Each configuration's labels, as (dimension, label) pairs (empty: a store of one configuration).
    results : tuple of tuple of xarray.Dataset
        For each configuration, one :func:`~stochpound.analysis.measure_free_risk` dataset per demand, the closure first.
    runs, first_stage, extra, seed : int
        Runs per configuration, the first stage's runs of each rupture, those allocated after, and the motions' seed.
    """

    site: str
    site_name: str
    configurations: tuple[tuple[tuple[str, Any], ...], ...]
    results: tuple[tuple[xr.Dataset, ...], ...]
    runs: int
    first_stage: int
    extra: int
    seed: int

    def frame(self) -> pd.DataFrame:
        """One row per configuration, demand and target: ``level`` (m; for the closure g*), ``lower``, ``upper`` (its interval),
        ``runs``, ``beyond`` (the runs at or beyond the level) and the demand's ``units``."""
        rows = []
        for labels, datasets in zip(self.configurations, self.results):
            for result in datasets:
                for t, target in enumerate(result.target.values):
                    rows.append({**dict(labels), "demand": result.attrs["demand"], "target": float(target),
                                 "level": float(result.level.values[t]), "lower": float(result.level_lower.values[t]),
                                 "upper": float(result.level_upper.values[t]), "runs": int(result.attrs["runs"]),
                                 "beyond": int(result.motions_beyond.values[t].sum()), "units": result.attrs["units"]})
        return pd.DataFrame(rows)

    def display_frame(self) -> pd.DataFrame:
        """The answer as text cells: one row per configuration and demand, one column per target with the level (m; for the
        closure g*) and its interval, ``"0.0540 (0.0440-0.0700)"``, and the runs."""
        rows = []
        for labels, datasets in zip(self.configurations, self.results):
            for result in datasets:
                row = {"configuration": configuration_label(labels), "demand": result.attrs["demand"]}
                for t, target in enumerate(result.target.values):
                    level, low, high = (float(result[name].values[t]) for name in ("level", "level_lower", "level_upper"))
                    row[f"{100 * target:g} % in {result.attrs['years']:g} yr ({result.attrs['units']})"] = f"{level:.4f} ({low:.4f}-{high:.4f})"
                row["runs"] = int(result.attrs["runs"])
                rows.append(row)
        return pd.DataFrame(rows).set_index(["configuration", "demand"])

    def conditions(self) -> str:
        """The conditions of the answer in words: the runs, their allocation, the seed, the motions and the intervals."""
        first = self.results[0][0].attrs
        allocation = (f"{self.first_stage} runs of each rupture, then {self.extra} shared out by Neyman allocation at the closure's "
                      "level of the rarest target" if self.extra else f"{self.first_stage} runs of each rupture")
        return (f"{self.runs} runs a configuration ({allocation}), the same motions for every configuration (seed {self.seed}): "
                f"simulated motions of each rupture ({first['model']} site_motions, dt {first['dt']:g} s); "
                f"{100 * first['confidence']:g} % intervals from {first['bootstrap']} stratified bootstrap resamples over the motions "
                "within each rupture (the ruptures' rates taken as given)")


def store_measure_free(store: xr.Dataset, site: RuptureSite, *, runs: int = MEASURE_FREE_RUNS, seed: int = 0, targets: Sequence[float] | None = None,
                       years: float = 50.0, confidence: float = 0.95, bootstrap: int = 1000, workers: int = 1,
                       outside: str = "refuse") -> StoreMeasureFree:
    """The answer without an intensity measure for every configuration of a store at a site of ruptures (module docstring).

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store with contact-free cases (``gap = inf``), as the risk chain reads it.
    site : RuptureSite
        The site's ruptures and their annual rates.
    runs : int
        Runs per configuration (>= 2 a rupture): ``max(2, runs // (2 × ruptures))`` of each rupture first, the rest
        shared out by Neyman allocation.
    seed : int
        The motions' seed (the same for every configuration; the result does not depend on ``workers``).
    targets, years, confidence, bootstrap, workers, outside
        As :func:`~stochpound.analysis.measure_free_risk` (the targets default to the risk chain's, 10 % and 2 % in 50 years).

    Returns
    -------
    StoreMeasureFree

    Raises
    ------
    ValueError
        ``runs`` below two a rupture (one line naming it), or as :func:`~stochpound.analysis.measure_free_risk`;
        (``RiskInputError``) a store without contact-free cases.
    """
    from stochpound.risk import configuration_scene, contact_free_closure  # the risk chain, imported when used (the statistics do not import it)

    if isinstance(runs, bool) or not isinstance(runs, int) or runs < 2 * len(site):
        raise ValueError(f"runs: must be an integer >= {2 * len(site)} (two runs of each of the site's {len(site)} ruptures), got {runs!r}")
    first = max(2, runs // (2 * len(site)))
    extra = runs - first * len(site)
    closure = contact_free_closure(store)
    dims = [dim for dim in closure.dims if dim not in CASE_DIMS]
    configurations = tuple(tuple(zip(dims, labels)) for labels in _labels(closure, dims))
    results = []
    for labels in configurations:
        scene = configuration_scene(store, dict(labels))
        results.append(measure_free_demands(scene, site, scene_demands(scene), motions=first, extra=extra, seed=seed, targets=targets,
                                            years=years, confidence=confidence, bootstrap=bootstrap, outside=outside, workers=workers))
    return StoreMeasureFree(site.describe(), site.name or "a site of ruptures", configurations, tuple(results), first * len(site) + extra, first, extra, int(seed))


def configuration_label(labels: tuple[tuple[str, Any], ...]) -> str:
    """A configuration's labels in words, e.g. ``"neighbour stiff, mu 0.05"`` (``mu inf``: a fixed base; "-" without labels)."""
    words = [f"{dim} {'fixed' if dim == 'mu' and value == math.inf else (f'{value:g}' if isinstance(value, float) else value)}" for dim, value in labels]
    return ", ".join(words) or "-"


def _labels(closure: xr.DataArray, dims: list[str]) -> list[tuple[Any, ...]]:
    """Every combination of the labels on ``dims`` (one empty combination without any)."""
    combinations: list[tuple[Any, ...]] = [()]
    for dim in dims:
        combinations = [labels + (_plain(value),) for labels in combinations for value in closure[dim].values]
    return combinations


def _plain(value: Any) -> Any:
    """A label as a plain Python value (a float axis stays a float, inf included)."""
    item = value.item() if hasattr(value, "item") else value
    return float(item) if isinstance(item, float) and not math.isnan(item) else item


def scene_demands(scene: Scene) -> list[MeasureFreeDemand]:
    """The demands of a scene's answer: its closure (with contacts), each sliding base's displacement and each building's storey
    drift (the largest over its storeys), the closure first (the extra runs are allocated for it)."""
    demands = [MeasureFreeDemand("closure")] if scene.contacts else []
    demands += [MeasureFreeDemand("base_displacement", building.name) for building in scene.buildings if building.base is not None]
    demands += [MeasureFreeDemand("peak_storey_drift", building.name) for building in scene.buildings]
    return demands
