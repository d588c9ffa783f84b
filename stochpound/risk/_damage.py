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
  the risk-targeted separation g* (whose ratio is 1 by construction). Where the
  runs do not pin a limit state's fit (a step, a flat fit, a lognormal not
  identified) its λ is bounded by the stripes' fractions alone, [λ⁻, λ⁺], and
  it misses its objective only where λ⁻ does (``stochpound.risk.judged_ratio``);
  where the bounds straddle the objective the runs leave it open. Without
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
from stochpound.risk._limit_states import (KINDS, POUNDING, LimitState, default_target, governing_disagreement, governing_limit_state,
                                           judged_ratio, limit_state_bounds, limit_state_fits, limit_state_pinned, limit_state_risk,
                                           limit_states_of, objective_ratio, undecided)
from stochpound.risk._maf import TARGETS
from stochpound.risk._chain import YEARS
from stochpound.risk._collapse import MODEL_DRIFT_LIMIT

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
    walls : tuple of float
        The moat walls' clearances at the studied building's base (m; () without walls).
    walled : xarray.DataArray or None
        Per configuration, whether its runs have those walls (None: no configuration has a wall).
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
    walls: tuple[float, ...] = ()
    walled: xr.DataArray | None = None

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
        """λ/λ_target of each limit state's fit over ``risk``'s dimensions (NaN where it has no objective); None without ``risk``.
        With ``apart``, of λ with the runs beyond the model counted apart as collapses (as run where none is). Where the runs
        do not pin the fit (:meth:`pinned`) this ratio is not theirs: :meth:`bound_ratios` is."""
        return None if self.risk is None else objective_ratio(self.risk, apart)

    def pinned(self, apart: bool = False) -> xr.DataArray | None:
        """Whether the runs pin each limit state's λ (``stochpound.risk.limit_state_pinned``: a lognormal the stripes identify),
        over ``risk``'s dimensions; None without ``risk``."""
        return None if self.risk is None else limit_state_pinned(self.risk, apart)

    def rate_bounds(self, apart: bool = False) -> tuple[xr.DataArray, xr.DataArray] | None:
        """λ⁻ and λ⁺ (1/yr), the bounds the stripes' fractions alone give each limit state's λ
        (``stochpound.risk.limit_state_bounds``; with ``apart`` a collapse counted as reaching it); None without them."""
        return None if self.risk is None else limit_state_bounds(self.risk, apart)

    def bound_ratios(self, apart: bool = False) -> tuple[xr.DataArray, xr.DataArray] | None:
        """λ⁻/λ_target and λ⁺/λ_target of :meth:`rate_bounds` (NaN without an objective); None without bounds."""
        bounds = self.rate_bounds(apart)
        if bounds is None:
            return None
        target = xr.apply_ufunc(rate_from_probability, self.risk["target"].fillna(0.5), 50.0).where(self.risk["target"].notnull())
        return bounds[0] / target, bounds[1] / target

    def judged(self, apart: bool = False) -> xr.DataArray | None:
        """λ/λ_target as each objective is judged (``stochpound.risk.judged_ratio``): the fit's where the runs pin it, else the
        lower bound's; None without ``risk``."""
        return None if self.risk is None else judged_ratio(self.risk, apart)

    def undecided(self, apart: bool = False) -> xr.DataArray | None:
        """Per limit state and configuration, whether the runs leave open if it misses its objective (``stochpound.risk.undecided``:
        a fit they do not pin, its bounds either side of the objective); None without ``risk``."""
        return None if self.risk is None else undecided(self.risk, apart)

    def wall_counts(self) -> tuple[int, int]:
        """The configurations with a moat wall at the studied building's base and the configurations ((0, 0) without walls)."""
        return (0, 0) if self.walled is None else (int(self.walled.sum()), int(self.walled.size))

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
        """Per configuration, the largest judged λ/λ_target (:meth:`judged`) and the limit state that has it (None without
        ``risk``); ``apart`` as in :meth:`ratio`."""
        ratio = self.judged(apart)
        if ratio is None:
            return None
        index = ratio.fillna(-1.0).argmax("limit_state")
        return ratio.isel(limit_state=index), ratio["limit_state"][index].drop_vars("limit_state", errors="ignore")

    def fits(self, apart: bool = False) -> xr.DataArray | None:
        """Each limit state's fit in words over ``risk``'s dimensions (``stochpound.risk.limit_state_fits``; with ``apart``, the
        credible runs' fit behind λ with the runs beyond the model counted apart); None without ``risk``."""
        return None if self.risk is None or "status" not in self.risk else limit_state_fits(self.risk, apart)

    def governing_unpinned(self, apart: bool = False) -> tuple[str, ...]:
        """The governing limit states (:meth:`governing`) whose fit, in some configuration they govern, the runs do not pin
        (:meth:`pinned`): they govern on the lower bound of λ the stripes give, not on a rate; () where none does."""
        governing, pinned = self.governing(apart), self.pinned(apart)
        if governing is None or pinned is None:
            return ()
        found: list[str] = []
        for index in np.ndindex(governing.shape):
            state = str(governing.values[index])
            if state == POUNDING or state in found:
                continue
            labels = {dim: governing[dim].values[i] for dim, i in zip(governing.dims, index)}
            if not bool(pinned.sel(labels).sel(limit_state=state).item()):
                found.append(state)
        return tuple(found)

    def undecided_counts(self, apart: bool = False) -> dict[str, int]:
        """Each limit state the runs leave open (:meth:`undecided`) with the number of configurations where they do, in order."""
        open_ = self.undecided(apart)
        if open_ is None:
            return {}
        counts = open_.sum([d for d in open_.dims if d != "limit_state"]) if open_.ndim > 1 else open_.astype(int)
        return {str(state): int(n) for state, n in zip(counts["limit_state"].values, counts.values) if int(n)}

    def misses_objective(self, apart: bool = False) -> xr.DataArray | None:
        """Per limit state and configuration, whether it misses its objective as judged (:meth:`judged` > 1: a fit the runs do
        not pin only where its lower bound does; False without an objective)."""
        ratio = self.judged(apart)
        return None if ratio is None else ratio > 1.0


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
        limit_states, given = limit_states_of(table), True
        source = f'{EXPERIMENT_SOURCE}, whose source reads "{table.source}"' if table.source else EXPERIMENT_SOURCE
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
    walls = tuple(_inputs.moat_clearances(store, _inputs.studied_building(store)))
    return StoreDamage(demands, done.sum("record"), (beyond & done).sum("record"), design_stripes, risk, held, source or "", free, elastic,
                       walls, _inputs.walled_configurations(store) if walls else None)
