"""The damage yielding buildings take: ductility, residual drift and drift demands per stripe, runs beyond the model, the governing limit state.

Read from a stripes store of yielding buildings (the storey summaries,
``stochpound.store.STOREY_SUMMARIES``), over its contact-free runs where it
has them (the runs the separations come from), else over every run:

* the median and 84 % fractile over each stripe's motions of every
  building's peak storey ductility, residual storey drift and peak storey
  drift ratio (empirical quantiles, linear interpolation);
* per stripe, the runs whose peak storey drift ratio exceeds
  ``MODEL_DRIFT_LIMIT``: the bilinear storeys never lose strength, so
  such a run's drifts are beyond what the model represents and are counted,
  not taken as credible;
* the limit states' mean annual frequencies (:func:`~stochpound.risk.limit_state_risk`),
  each building's own (a limit state of any building is judged per building),
  each against its performance objective λ_target (its ``target``, a
  probability in 50 years), and per configuration the one that governs: the
  largest ratio λ/λ_target among the structural limit states and pounding at
  the risk-targeted separation g* (whose ratio is 1 by construction). Without
  any objective nothing is said to govern.

The limit states are the experiment's ``[limit_states]`` table (not part of
its runs' identity: docs/risk.md), else ``DEFAULT_LIMIT_STATES``, the
drift ratios of ``DEFAULT_SOURCE``; a caller may give others.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
import xarray as xr

from stochpound.hazard import rate_from_probability, return_period
from stochpound.risk import _inputs
from stochpound.risk._limit_states import (KINDS, OBJECTIVE_YEARS, POUNDING, LimitState, default_target, governing_disagreement,
                                           governing_limit_state, limit_state_fits, limit_state_risk, limit_states_of, objective_ratio)
from stochpound.risk._maf import TARGETS
from stochpound.risk._chain import YEARS
from stochpound.risk._collapse import MODEL_DRIFT_LIMIT
from stochpound.risk._stripe_coverage import at_lowest_stripe, stripes_only_maf

QUANTILES = (0.5, 0.84)
"""The fractiles over each stripe's motions of ``StoreDamage.demands``."""
DEFAULT_LIMIT_STATES = tuple(LimitState(kind, capacity, target=default_target(kind, capacity)) for kind, capacity in (
    ("drift_ratio", 0.007), ("drift_ratio", 0.025), ("residual_drift_ratio", 0.01), ("drift_ratio", 0.05)))
"""The default limit states: peak storey drift ratios 0.7 %, 2.5 %, 5 % and a residual storey drift ratio of 1 % (``DEFAULT_SOURCE``),
with the objectives of ``stochpound.risk._limit_states.DEFAULT_TARGETS`` (50 %, 10 %, 10 % and 2 % in 50 yr)."""
PER_BUILDING = ("drift_ratio", "residual_drift_ratio")
"""The kinds a limit state of any building is split into one per building for (each building judged by its own demand)."""
DEFAULT_SOURCE = ("FEMA 356 (2000), Table C1-3, steel moment frames: immediate occupancy at 0.7 % transient storey drift, life safety at "
                  "2.5 % transient or 1 % permanent, collapse prevention at 5 % transient or permanent")
"""Where ``DEFAULT_LIMIT_STATES`` come from."""
EXPERIMENT_SOURCE = "the experiment's [limit_states] table"
"""The source of limit states an experiment's ``[limit_states]`` gives without a ``source``."""
#: The demands of ``StoreDamage.demands``: store summary -> its words.
DAMAGE_DEMANDS = {"peak_ductility": "peak storey ductility", "residual_drift": "residual storey drift", "peak_drift_ratio": "peak storey drift ratio"}


@dataclasses.dataclass(frozen=True)
class StoreDamage:
    """What the runs of a store of yielding buildings did to them (:func:`store_damage`).

    Attributes
    ----------
    demands : xarray.Dataset
        ``DAMAGE_DEMANDS`` present in the store with a value in some run (``peak_ductility`` 1,
        ``residual_drift`` m, ``peak_drift_ratio`` 1) over ``quantile``
        (``QUANTILES``), ``building``, ``intensity`` and the store's other
        grid dimensions (contact axes dropped where the runs are contact-free).
    runs, beyond_model : xarray.DataArray
        Per stripe and configuration: the runs done, and those whose peak
        storey drift ratio (any building) exceeds ``MODEL_DRIFT_LIMIT``
        (0 without storey heights).
    design_stripes : dict
        Probability of exceedance in 50 yr (``stochpound.risk.TARGETS``)
        -> the stripe nearest (in ln IM) to the hazard's intensity of that rate.
    risk : xarray.Dataset or None
        :func:`~stochpound.risk.limit_state_risk` of ``limit_states`` on
        the same runs (None when the store holds none of their demands).
    limit_states : tuple of LimitState
        Those evaluated (the given ones the store holds the demand of).
    source : str
        Where the limit states' capacities come from.
    contact_free : bool
        Whether the runs are the contact-free ones.
    elastic : tuple of str
        The buildings whose storeys never yield in any run (no yield force:
        no ductility; their ``peak_ductility`` is NaN, and absent from
        ``demands`` when no building yields).
    bound : xarray.DataArray or None
        Over ``risk``'s dimensions: where a limit state's fit is a step at
        the lowest stripe (:func:`~stochpound.risk.at_lowest_stripe`), the
        lower bound of λ the runs give
        (:func:`~stochpound.risk.stripes_only_maf`, 1/yr); NaN elsewhere.
    """

    demands: xr.Dataset
    runs: xr.DataArray
    beyond_model: xr.DataArray
    design_stripes: dict[float, float]
    risk: xr.Dataset | None
    limit_states: tuple[LimitState, ...]
    source: str
    contact_free: bool
    elastic: tuple[str, ...] = ()
    bound: xr.DataArray | None = None

    def collapses_apart(self) -> bool:
        """Whether the limit states are given both ways: some run is beyond the model (``risk`` holds ``maf_collapses_apart``)."""
        return self.risk is not None and "maf_collapses_apart" in self.risk

    def judged_both_ways(self) -> bool:
        """Whether what governs is judged both ways: some run of these runs is beyond the model and λ is given with them counted
        apart as collapses (:meth:`collapses_apart`)."""
        return self.collapses_apart() and self.beyond_model_total()[0] > 0

    def beyond_model_per_stripe(self) -> list[tuple[float, int, int]]:
        """Per stripe, over every configuration: (its level in IM units, the runs beyond the model, the runs done)."""
        beyond = self.beyond_model.sum([d for d in self.beyond_model.dims if d != "intensity"])
        runs = self.runs.sum([d for d in self.runs.dims if d != "intensity"])
        return [(float(level), int(b), int(n)) for level, b, n in zip(beyond["intensity"].values, beyond.values, runs.values)]

    def beyond_model_total(self) -> tuple[int, int]:
        """The runs beyond the model and the runs done, over every stripe and configuration."""
        return int(self.beyond_model.sum()), int(self.runs.sum())

    def return_period(self) -> xr.DataArray | None:
        """Each limit state's mean return period 1/λ (yr; inf where no run reaches it), over ``risk``'s dimensions; None without ``risk``."""
        if self.risk is None:
            return None
        return xr.apply_ufunc(return_period, self.risk["maf"])

    def ratio(self, apart: bool = False) -> xr.DataArray | None:
        """λ/λ_target of each limit state over ``risk``'s dimensions (NaN where it has no objective); None without ``risk``.
        With ``apart``, of λ with the runs beyond the model counted apart as collapses (as run where none is)."""
        return None if self.risk is None else objective_ratio(self.risk, apart)

    def bounds(self, apart: bool = False) -> xr.DataArray | None:
        """``bound`` (1/yr), or with ``apart`` the same bound with the collapses counted as reaching the limit state
        (``risk``'s ``bound_collapses_apart`` where ``bound`` is one); None without ``bound`` (or without collapses apart)."""
        if self.bound is None or (apart and not self.collapses_apart()):
            return None
        return self.risk["bound_collapses_apart"].where(self.bound.notnull()) if apart else self.bound

    def bound_ratio(self, apart: bool = False) -> xr.DataArray | None:
        """:meth:`bounds`/λ_target over ``risk``'s dimensions: the lower bound of λ/λ_target where a fit is a step at the
        lowest stripe (NaN elsewhere or without an objective); None without a bound."""
        bound = self.bounds(apart)
        if bound is None:
            return None
        target = self.risk["target"]
        return bound / xr.apply_ufunc(rate_from_probability, target.fillna(0.5), OBJECTIVE_YEARS).where(target.notnull())

    def has_objectives(self) -> bool:
        """Whether any limit state has a performance objective (without one, nothing is said to govern)."""
        return self.risk is not None and bool(self.risk["target"].notnull().any())

    def governing_counts(self, apart: bool = False) -> tuple[dict[str, int], int] | None:
        """The configurations each structural limit state governs (:meth:`governing`, with ``apart`` on λ with the collapses
        counted apart), in the order first met, and the number of configurations; None without ``risk`` or without any objective."""
        governing = self.governing(apart)
        if governing is None:
            return None
        names = [str(v) for v in governing.values.ravel()]
        structural = {str(state) for state in self.risk["limit_state"].values}
        return {n: names.count(n) for n in names if n in structural}, len(names)

    def governing(self, apart: bool = False) -> xr.DataArray | None:
        """Per configuration, what governs at the risk-targeted separation g* of any target: the largest λ/λ_target.

        Pounding at g* has the target's rate (ratio 1); a structural limit
        state governs where its ratio is the largest and exceeds 1 (it misses
        its objective), else ``POUNDING``. The answer is the same at every
        target: each limit state has its own objective. With ``apart``,
        judged on λ with the runs beyond the model counted apart as
        collapses (``stochpound.risk.governing_limit_state``). None
        without ``risk`` or without any objective (nothing is said to govern).
        """
        return None if self.risk is None else governing_limit_state(self.risk, apart, POUNDING)

    def disagreement(self) -> xr.DataArray | None:
        """Per configuration, whether what governs as run differs from what governs with the collapses counted apart; None
        without ``risk``, objectives or runs beyond the model."""
        return None if self.risk is None else governing_disagreement(self.risk, POUNDING)

    def disagreements(self) -> tuple[int, int]:
        """The configurations where the two treatments name different governing limit states (:meth:`disagreement`), and the
        configurations; (0, 0) where there is one treatment only."""
        differ = self.disagreement()
        return (0, 0) if differ is None else (int(differ.sum()), int(differ.size))

    def largest_ratio(self, apart: bool = False) -> tuple[xr.DataArray, xr.DataArray] | None:
        """Per configuration, the largest λ/λ_target and the limit state that has it (None without ``risk``); ``apart`` as in :meth:`ratio`."""
        ratio = self.ratio(apart)
        if ratio is None:
            return None
        index = ratio.fillna(-1.0).argmax("limit_state")
        return ratio.isel(limit_state=index), ratio["limit_state"][index].drop_vars("limit_state", errors="ignore")

    def fits(self, apart: bool = False) -> xr.DataArray | None:
        """Each limit state's fit in words over ``risk``'s dimensions (``stochpound.risk.limit_state_fits``; with ``apart``, the
        credible runs' fit behind λ with the runs beyond the model counted apart); None without ``risk``."""
        return None if self.risk is None or "status" not in self.risk else limit_state_fits(self.risk, apart)

    def unpinned(self, apart: bool = False) -> xr.DataArray | None:
        """Whether each limit state's fit (:meth:`fits`) is one the runs do not pin (``stochpound.risk.unpinned_fit``), over the same
        dimensions; None without ``risk``."""
        fits = self.fits(apart)
        return None if fits is None else fits.copy(data=np.vectorize(unpinned_fit, otypes=[bool])(fits.values))

    def governing_unidentified(self, apart: bool = False) -> dict[str, str]:
        """The governing limit states (:meth:`governing`) whose fit, in some configuration they govern, the runs do not pin (a
        lognormal not identified, or a step at the lowest stripe: its λ a bound), each with that fit in words; {} where none is."""
        governing, fits = self.governing(apart), self.fits(apart)
        if governing is None or fits is None:
            return {}
        found: dict[str, str] = {}
        for index in np.ndindex(governing.shape):
            state = str(governing.values[index])
            if state == POUNDING or state in found:
                continue
            labels = {dim: governing[dim].values[i] for dim, i in zip(governing.dims, index)}
            fit = str(fits.sel(labels).sel(limit_state=state).item())
            if unpinned_fit(fit):
                found[state] = fit
        return found

    def misses_objective(self, apart: bool = False) -> xr.DataArray | None:
        """Per limit state and configuration, whether λ exceeds its objective's rate (λ/λ_target > 1; False without an objective)."""
        ratio = self.ratio(apart)
        return None if ratio is None else ratio > 1.0


def unpinned_fit(fit: str) -> bool:
    """Whether a limit state's fit in words (``stochpound.risk.limit_state_fits``) is one the runs do not pin: a lognormal not
    identified, a step at the lowest stripe (its λ a bound) or a flat fit (a fraction held down to the hazard's lowest intensity)."""
    return "not identified" in fit or "lowest stripe" in fit or fit.startswith("flat")



def store_damage(store: xr.Dataset, limit_states: Sequence[LimitState] | None = None, source: str | None = None) -> StoreDamage | None:
    """The ductility, residual drift and drift demands per stripe, runs beyond the model, and limit states of a store of yielding buildings.

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store with intensity stripes and a site hazard.
    limit_states : sequence of LimitState, optional
        Default: the experiment's ``[limit_states]`` table, else
        ``DEFAULT_LIMIT_STATES`` (then ``source`` is ``DEFAULT_SOURCE``,
        and those whose demand the store lacks are left out).
    source : str, optional
        Where the given limit states come from.

    Returns
    -------
    StoreDamage or None
        None for a store without yielding storeys (``peak_ductility``) or without stripes.

    Raises
    ------
    ValueError
        (``RiskInputError``) A given limit state the store cannot evaluate (its demand or building missing).
    """
    if "peak_ductility" not in store or _inputs.stripes(store) is None:
        return None
    given = limit_states is not None
    table = _inputs.limit_states_table(store)
    if limit_states is None and table is not None:
        limit_states, source, given = limit_states_of(table), table.source or EXPERIMENT_SOURCE, True
    if limit_states is None:
        limit_states, source = DEFAULT_LIMIT_STATES, DEFAULT_SOURCE
    per_building, free = _inputs.run_summaries(store, list(DAMAGE_DEMANDS))
    ductility = per_building["peak_ductility"]
    yields = ductility.notnull().any([d for d in ductility.dims if d != "building"])
    elastic = tuple(str(b) for b, flag in zip(ductility["building"].values, yields.values) if not flag)
    # an elastic building has no ductility: its fractiles NaN (a placeholder 0 in the quantile, not an all-NaN slice); a demand no run has: left out
    demands = xr.Dataset({name: data.where(yields, 0.0).quantile(list(QUANTILES), dim="record", keep_attrs=True).where(yields)
                          if name == "peak_ductility" else data.quantile(list(QUANTILES), dim="record", keep_attrs=True)
                          for name, data in per_building.items() if bool(data.notnull().any())})
    done = xr.concat([data.notnull().any("building") for data in per_building.values()], "demand").any("demand")
    drift = per_building.get("peak_drift_ratio")
    beyond = (drift.max("building") > MODEL_DRIFT_LIMIT) if drift is not None else xr.zeros_like(done)
    hz = _inputs.site_hazard(store)
    levels = _inputs.stripe_levels(store)
    design_stripes = {p: float(levels[np.argmin(np.abs(np.log(levels) - np.log(float(hz.intensity_at(rate_from_probability(p, YEARS))))))])
                      for p in TARGETS}
    held = tuple(state for state in limit_states  # the defaults the store can evaluate; every given one (an error where it cannot)
                 if given or _inputs.holds(store, KINDS[state.kind].variable))
    buildings = [str(b) for b in ductility["building"].values]
    held = tuple(one for state in held for one in ([state.for_building(b) for b in buildings]
                                                   if state.building is None and state.kind in PER_BUILDING else [state]))
    risk = None
    if held:
        risk = limit_state_risk(store, held, hz)
        risk = _inputs.contact_free_part(risk) if free else risk
    bound = None if risk is None else stripes_only_maf(risk, hz).where(at_lowest_stripe(risk))
    return StoreDamage(demands, done.sum("record"), (beyond & done).sum("record"), design_stripes, risk, held, source or "", free, elastic,
                       bound)
