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
* the limit states' mean annual frequencies (:func:`~stochpound.risk.limit_state_risk`)
  and, per configuration and target, the one that governs: the most frequent
  of pounding at the risk-targeted separation g* (the target's rate) and the
  structural limit states.

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
from stochpound.risk._limit_states import KINDS, LimitState, limit_state_risk, limit_states_of
from stochpound.risk._maf import TARGETS
from stochpound.risk._chain import YEARS

MODEL_DRIFT_LIMIT = 0.05
"""Peak storey drift ratio beyond which a run is flagged: the model has no strength loss or collapse (the collapse-prevention drift of ``DEFAULT_SOURCE``)."""
QUANTILES = (0.5, 0.84)
"""The fractiles over each stripe's motions of ``StoreDamage.demands``."""
DEFAULT_LIMIT_STATES = (
    LimitState("drift_ratio", 0.007),
    LimitState("drift_ratio", 0.025),
    LimitState("residual_drift_ratio", 0.01),
    LimitState("drift_ratio", 0.05),
)
"""The default limit states: peak storey drift ratios 0.7 %, 2.5 %, 5 % and a residual storey drift ratio of 1 % (``DEFAULT_SOURCE``)."""
DEFAULT_SOURCE = ("FEMA 356 (2000), Table C1-3, steel moment frames: immediate occupancy at 0.7 % transient storey drift, life safety at "
                  "2.5 % transient or 1 % permanent, collapse prevention at 5 % transient or permanent")
"""Where ``DEFAULT_LIMIT_STATES`` come from."""
EXPERIMENT_SOURCE = "the experiment's [limit_states] table"
"""The source of limit states an experiment's ``[limit_states]`` gives without a ``source``."""
POUNDING = "pounding at g*"
"""What ``StoreDamage.governing`` names where no structural limit state is more frequent than pounding at g*."""
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

    def governing_counts(self, probability: float) -> tuple[dict[str, int], int] | None:
        """At the g* of ``probability`` in 50 yr: the configurations each structural limit state governs (:meth:`governing`), in
        the order first met, and the number of configurations; None without ``risk``."""
        governing = self.governing(probability)
        if governing is None:
            return None
        names = [str(v) for v in governing.values.ravel()]
        structural = {str(state) for state in self.risk["limit_state"].values}
        return {n: names.count(n) for n in names if n in structural}, len(names)

    def governing(self, probability: float) -> xr.DataArray | None:
        """Per configuration, what is reached most often at the risk-targeted separation g* of ``probability`` in 50 yr.

        Pounding at g* has the target's rate; the governing limit state is
        the most frequent of the structural ones where its mean annual
        frequency exceeds that rate (it is then reached before pounding at
        g*), else ``POUNDING``. None without ``risk``.
        """
        before = self.before_pounding(probability)
        if before is None:
            return None
        maf = self.risk["maf"].fillna(-1.0)
        worst = maf["limit_state"][maf.argmax("limit_state")].drop_vars("limit_state", errors="ignore")
        return worst.where(before.any("limit_state"), POUNDING)

    def before_pounding(self, probability: float) -> xr.DataArray | None:
        """Per limit state and configuration, whether its λ exceeds the rate of ``probability`` in 50 yr: it is reached more often than pounding at g* (None without ``risk``)."""
        if self.risk is None:
            return None
        return self.risk["maf"] > float(rate_from_probability(probability, YEARS))


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
    risk = None
    if held:
        risk = limit_state_risk(store, held, hz)
        risk = _inputs.contact_free_part(risk) if free else risk
    return StoreDamage(demands, done.sum("record"), (beyond & done).sum("record"), design_stripes, risk, held, source or "", free, elastic)
