"""Limit states beyond first contact: the damage a run does, as fragilities and mean annual frequencies, and what the gap costs.

A limit state is a per-case demand of a store reaching a capacity: a storey
drift ratio, a residual drift ratio or a ductility (the yielding storeys'
summaries, ``stochpound.store.STOREY_SUMMARIES``), a floor acceleration, an
impact force, or a sliding base's peak base displacement (a bearing's displacement
capacity or a moat clearance: no stop is modelled unless the scene has a wall there). Each
goes through the pounding chain's steps: per run, whether the demand reaches
the capacity (:func:`~stochpound.risk.limit_state_events`); per
configuration of the grid, a lognormal fragility of the stripes
(:func:`~stochpound.risk.stripe_fragility`); and its mean annual frequency
at the site (:func:`~stochpound.risk.mean_annual_frequency`).

Unlike pounding, these limit states are not a property of the contact-free
run: a run at a finite gap pounds, and the pounding changes its drifts,
accelerations and base displacement. So they are evaluated on the runs at
each of the grid's gaps, and set against the same limit state of the
contact-free twins (``inf`` on every contact axis, the same motions): the
difference of the two rates is what the gap costs in damage risk.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from stochpound.hazard import HazardCurve, probability_from_rate, rate_from_probability
from stochpound.risk import _inputs
from stochpound.risk._inputs import LimitStates
from stochpound.risk._fragility_ensemble import limit_state_events, stripe_fragility
from stochpound.risk._maf import mean_annual_frequency
from stochpound.risk._chain import CONFIDENCE, YEARS, fit_name
from stochpound.risk._collapse import MODEL_DRIFT_LIMIT, beyond_model, collapse_fit, rate_collapses_apart
from stochpound.risk._fragility import FIT, NEVER
from stochpound.risk._stripe_coverage import at_lowest_stripe, identified, stripes_only_maf, stripes_upper_maf, unidentified


OBJECTIVE_YEARS = 50.0
"""The exposure time of a limit state's target (yr)."""
POUNDING = "pounding at g*"
"""What governs where every structural limit state is within its objective (λ/λ_target ≤ 1, pounding at g*'s ratio)."""
WITHIN = "none beyond its objective"
"""What governs at a finite gap of the grid (no g* there) where every limit state is within its objective."""
TREATMENTS = {False: "as run", True: "collapses apart"}
"""The two treatments of the runs beyond the model, by ``apart``: as computed, or counted apart as collapses (FEMA P-58)."""


@dataclasses.dataclass(frozen=True)
class _Kind:
    variable: str  # the store's per-case summary
    units: str  # the capacity's units
    label: str
    per_building: bool
    note: str  # what the store needs to hold the variable


#: The kinds of limit state: the ``[limit_states]`` keys, the store summary each reads, and the capacity's units.
KINDS = {kind: _Kind(_inputs.limit_state_variable(kind), *rest) for kind, rest in {
    "drift_ratio": ("1", "peak storey drift ratio", True, "yielding storeys or storey_height, and [output] demands = true"),
    "residual_drift_ratio": ("1", "residual storey drift ratio", True, "yield_force and storey_height"),
    "ductility": ("1", "peak storey ductility", True, "yield_force"),
    "floor_acceleration": ("g", "peak floor acceleration", True, "[output] demands = true"),
    "impact_force": ("N", "peak impact force", False, "runs at a finite gap"),
    "isolator_displacement": ("m", "peak base displacement", True, "a sliding base"),
}.items()}


def limit_state_problem(kind: str, capacity: object, building: str | None = None) -> str | None:
    """What is wrong with a limit state of ``kind`` at ``capacity`` for ``building``, in words for an error naming the field; None if nothing.

    The one rule of a limit state's fields, for :class:`LimitState` and an experiment file's ``[limit_states]`` table:
    ``kind`` one of ``stochpound.risk.LIMIT_STATE_KINDS``, ``capacity`` a finite number > 0 (in the kind's units), and no
    ``building`` for a kind that is not a building's (an impact force is a contact's).
    """
    if kind not in KINDS:
        return f"not a limit state; one of {', '.join(KINDS)}"
    if isinstance(capacity, bool) or not (isinstance(capacity, (int, float)) and math.isfinite(capacity) and capacity > 0):
        return f"a capacity must be a number > 0 ({KINDS[kind].units}), got {capacity!r}"
    if building is not None and not KINDS[kind].per_building:
        return f"has no building (an impact force is a contact's), got {building!r}"
    return None


@dataclasses.dataclass(frozen=True)
class LimitState:
    """One limit state: a run's ``kind`` of demand reaching ``capacity``.

    Attributes
    ----------
    kind : str
        One of ``stochpound.risk.LIMIT_STATE_KINDS``: ``drift_ratio``, ``residual_drift_ratio``,
        ``ductility`` (1), ``floor_acceleration`` (g), ``impact_force`` (N),
        ``isolator_displacement`` (m, the peak base displacement of a sliding
        base: a capacity such as a bearing's displacement capacity or a moat
        wall's clearance; the runs model a stop there only where the scene
        has a wall at that clearance).
    capacity : float
        The capacity, > 0, in the kind's units.
    building : str, optional
        The building whose demand counts; default any building (the
        largest over the buildings). Impact forces have no building.
    target : float, optional
        The performance objective: the probability in 50 years the limit
        state may be exceeded with, in (0, 1) (e.g. immediate occupancy 0.5,
        life safety 0.10, collapse prevention 0.02); None: no objective (its
        λ is given, not judged).
    """

    kind: str
    capacity: float
    building: str | None = None
    target: float | None = None

    def __post_init__(self) -> None:
        problem = limit_state_problem(self.kind, self.capacity, self.building)
        if problem is None and self.target is not None and not (isinstance(self.target, float | int) and 0.0 < self.target < 1.0):
            problem = f"a target must be a probability in 50 years in (0, 1), got {self.target!r}"
        if problem is not None:
            raise _inputs.RiskInputError(f"limit_states.{self.kind}: {problem}")

    @property
    def target_rate(self) -> float:
        """λ_target (1/yr): the rate of the objective's probability in 50 years, −ln(1 − p)/50; NaN without an objective."""
        return math.nan if self.target is None else float(rate_from_probability(self.target, OBJECTIVE_YEARS))

    def for_building(self, building: str) -> LimitState:
        """The same limit state for one building (a state of any building splits into one per building)."""
        return dataclasses.replace(self, building=building)

    @property
    def label(self) -> str:
        """The limit state in words, e.g. ``peak storey drift ratio of B1 ≥ 0.015``."""
        kind = KINDS[self.kind]
        units = "" if kind.units == "1" else f" {kind.units}"
        return f"{kind.label}{f' of {self.building}' if self.building else ''} ≥ {self.capacity:g}{units}"


def limit_states_of(table: LimitStates) -> tuple[LimitState, ...]:
    """The limit states of an experiment's ``[limit_states]`` table (:class:`~stochpound.store.LimitStates`), in its order, each
    with the target the table gives it, else the FEMA 356 objective of its drift limit (``default_target``)."""
    return tuple(LimitState(state.kind, capacity, state.building, _target_at(state.targets, index) or default_target(state.kind, capacity))
                 for state in table.states for index, capacity in enumerate(state.capacities))


def _target_at(targets: tuple[float, ...] | None, index: int) -> float | None:
    """The ``index``-th target of a ``[limit_states]`` entry's targets (one per capacity), None without them."""
    return None if targets is None else targets[index]


def default_target(kind: str, capacity: float) -> float | None:
    """The performance objective of a limit state at one of FEMA 356's steel moment frame capacities (``DEFAULT_TARGETS``), else None."""
    return next((target for (k, c), target in DEFAULT_TARGETS.items() if k == kind and math.isclose(c, capacity)), None)


DEFAULT_TARGETS = {("drift_ratio", 0.007): 0.50, ("drift_ratio", 0.025): 0.10, ("residual_drift_ratio", 0.01): 0.10, ("drift_ratio", 0.05): 0.02}
"""The objectives given FEMA 356's steel moment frame drifts (Table C1-3) where no target is stated: immediate occupancy
(0.7 % transient) at 50 % in 50 yr, life safety (2.5 % transient, 1 % permanent) at 10 % in 50 yr, collapse prevention (5 %) at
2 % in 50 yr: the hazard levels FEMA 356 pairs them with in its objectives (its Basic Safety Objective: life safety at 10 %/50 yr,
collapse prevention at 2 %/50 yr; immediate occupancy at 50 %/50 yr among its enhanced ones), read as the rates the limit state
may be exceeded at (a risk-based reading of a hazard-level objective)."""


def limit_states_from_table(table: Mapping[str, Any]) -> tuple[LimitState, ...]:
    """The limit states of a ``[limit_states]`` table (docs/risk.md, "Limit states beyond first contact").

    Each key is a kind of ``stochpound.risk.LIMIT_STATE_KINDS``; its value a capacity or a list of
    capacities (any building), or a table of building names to a capacity or
    a list of them. ``targets`` (optional) gives a kind's objectives, probabilities in
    50 years: one for all its capacities or a list, one per capacity; else ``default_target`` (the FEMA 356 objectives of a drift limit).

    Raises
    ------
    ValueError
        (``RiskInputError``) An unknown kind, a capacity that is not a number > 0, or an empty table.
    """
    if not isinstance(table, Mapping) or not table:
        raise _inputs.RiskInputError(f"limit_states: must be a table of {', '.join(KINDS)} to capacities, got {table!r}")
    states = []
    targets = table["targets"] if "targets" in table else {}
    for kind, value in table.items():
        if kind == "targets":
            continue
        per_building = value.items() if isinstance(value, Mapping) else [(None, value)]
        given = targets[kind] if kind in targets else None
        for building, capacities in per_building:
            listed = capacities if isinstance(capacities, (list, tuple)) else [capacities]
            for index, capacity in enumerate(listed):
                target = given[index] if isinstance(given, (list, tuple)) and index < len(given) else given
                states.append(LimitState(kind, capacity, building, target if target is not None else default_target(kind, capacity)))
    return tuple(states)


def limit_state_risk(store: xr.Dataset, limit_states: Sequence[LimitState], hz: HazardCurve | None = None, confidence: float = CONFIDENCE,
                     bootstrap: int = 0, seed: int = 0) -> xr.Dataset:
    """Fragility and mean annual frequency of each limit state at every configuration of a store's grid, and what the gap costs.

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store with intensity stripes (a yielding scene runs
        stripes), holding the variable of every limit state (``stochpound.risk.LIMIT_STATE_KINDS``).
    limit_states : sequence of LimitState
        The limit states (:func:`limit_states_from_table` reads a table of them).
    hz : HazardCurve, optional
        The site's hazard; default the one the store carries.
    confidence, bootstrap, seed
        As in :func:`~stochpound.risk.stripe_fragility` (default: no bootstrap).

    Returns
    -------
    xarray.Dataset
        Over ``limit_state`` (coordinate: each one's label; ``kind``,
        ``capacity``, ``building`` and ``target``, its objective's probability in 50 yr or NaN, beside it) and the store's other grid
        dimensions (its gap axes, variants): the fragility (``theta``, IM
        units; ``beta``; ``status``; per stripe ``exceeded``, ``runs``,
        ``probability``), ``maf`` (1/yr), and ``maf_lower``, ``maf_upper``, the bounds the
        stripes' fractions alone give λ (:func:`~stochpound.risk.stripes_only_maf`,
        :func:`~stochpound.risk.stripes_upper_maf`: what the runs say where their fit does not pin λ,
        :func:`limit_state_pinned`). With contact-free cases:
        ``maf_contact_free`` (the contact-free twins' rate, the same motions
        and other labels) and ``gap_cost`` = ``maf`` − ``maf_contact_free``
        (1/yr; 0 for the twins themselves, negative where pounding lowers the
        demand). Where some run's peak storey drift ratio passes
        ``MODEL_DRIFT_LIMIT`` (beyond the model): ``maf_collapses_apart``,
        λ with those runs counted apart as collapses and combined by total
        probability (:func:`~stochpound.risk.rate_collapses_apart`; a
        collapse reaches every limit state), ``lower_collapses_apart`` and
        ``upper_collapses_apart``, the same bounds with a collapse counted as reaching it, the credible
        runs' fit (``status_collapses_apart``, ``theta_collapses_apart``, ``beta_collapses_apart``),
        and ``beyond_model``, those runs per stripe and configuration.

    Raises
    ------
    ValueError
        (``RiskInputError``) No limit states, a store without stripes or
        hazard, or without a limit state's variable or building.
    """
    if not limit_states:
        raise _inputs.RiskInputError("limit_states: give at least one limit state")
    hz, demands, measure = _inputs.limit_state_inputs(store, [(KINDS[s.kind].variable, s.building, KINDS[s.kind].note, KINDS[s.kind].units == "g")
                                                              for s in limit_states], hz)
    collapsed = _collapsed_cases(store)
    collapse = None if collapsed is None else collapse_fit(collapsed, hz)  # P(C | IM) once: every limit state's runs are the same runs
    fits, apart = [], []
    for state, demand in zip(limit_states, demands):
        events = limit_state_events(demand, [state.capacity], dim="limit_state").assign_coords(limit_state=[state.label])
        fit = stripe_fragility(events, confidence=confidence, bootstrap=bootstrap, seed=seed)
        fits.append(fit.assign_coords(kind=("limit_state", [state.kind]), capacity=("limit_state", [float(state.capacity)]),
                                      building=("limit_state", [state.building or ""]),
                                      target=("limit_state", [math.nan if state.target is None else float(state.target)])))
        if collapsed is not None:
            rate, _, credible = (part.assign_coords(limit_state=[state.label]) for part in
                                 rate_collapses_apart(demand, collapsed, [state.capacity], "limit_state", hz, collapse))
            either = _either_counts(events, collapsed)
            apart.append(xr.Dataset({"maf_collapses_apart": rate, "lower_collapses_apart": stripes_only_maf(either, hz),
                                     "upper_collapses_apart": stripes_upper_maf(either, hz),
                                     **{f"{name}_collapses_apart": credible[name] for name in ("status", "theta", "beta")}}))
    result = xr.concat(fits, "limit_state", coords="different", compat="equals", join="outer")
    result["maf"] = mean_annual_frequency(result, hz)
    result["maf_lower"] = stripes_only_maf(result, hz).assign_attrs(long_name=_LOWER)
    result["maf_upper"] = stripes_upper_maf(result, hz).assign_attrs(long_name=_UPPER)
    if apart:
        both = xr.concat(apart, "limit_state", join="outer")
        result["maf_collapses_apart"] = both["maf_collapses_apart"].assign_attrs(
            units="1/yr", long_name=f"mean annual frequency, the runs beyond a {100 * MODEL_DRIFT_LIMIT:g} % storey drift counted apart as collapses")
        for name, words in (("lower", _LOWER), ("upper", _UPPER)):
            result[f"{name}_collapses_apart"] = both[f"{name}_collapses_apart"].assign_attrs(
                units="1/yr", long_name=f"{words}, a collapse counted as reaching the limit state")
        for name in ("status", "theta", "beta"):  # the credible runs' fit, whose kind says what λ collapses apart rests on
            result[f"{name}_collapses_apart"] = both[f"{name}_collapses_apart"].assign_attrs(
                long_name=f"{name} of the credible runs' fit (the runs beyond the model left out)")
        result["beyond_model"] = collapsed.sum("record").assign_attrs(units="1", long_name="runs beyond the model (collapses) per stripe")
        result["collapse_identified"] = identified(collapse).reset_coords(drop=True).assign_attrs(
            long_name="whether P(C | IM) is a lognormal the stripes identify")
    twins = _inputs.contact_free_twins(result["maf"])
    if twins is not None:
        result["maf_contact_free"] = twins.assign_attrs(units="1/yr", long_name="mean annual frequency of the contact-free twins")
        result["gap_cost"] = (result["maf"] - twins).assign_attrs(units="1/yr", long_name="what the gap costs: maf minus that of the contact-free twins")
    return result.assign_attrs(intensity=measure)


_LOWER = "λ⁻: the stripes' fractions alone, nothing below the lowest stripe (stochpound.risk.stripes_only_maf)"
_UPPER = "λ⁺: the stripes' fractions as upper bounds, 1 beyond the top stripe (stochpound.risk.stripes_upper_maf)"


def _either_counts(events: xr.DataArray, collapsed: xr.DataArray) -> xr.Dataset:
    """Per stripe, the runs that reach a limit state or collapse (``exceeded``) and the runs (``runs``): its events with every
    collapse counted as reaching it."""
    events, collapsed = xr.align(events, collapsed.drop_vars([c for c in collapsed.coords if c not in collapsed.dims]), join="inner")
    either = xr.where(collapsed == 1.0, 1.0, events).where(events.notnull())
    return xr.Dataset({"exceeded": either.sum("record"), "runs": either.notnull().sum("record")})


def _collapsed_cases(store: xr.Dataset) -> xr.DataArray | None:
    """:func:`~stochpound.risk.beyond_model` of every case of a store (its gap axes kept), None without storey drift ratios or
    where no run is beyond the model (the collapses-apart rate is then the rate itself)."""
    if "peak_drift_ratio" not in store:
        return None
    collapsed = beyond_model(_inputs.case_demand(store, "peak_drift_ratio", None, ""))
    return collapsed if bool((collapsed == 1.0).any()) else None


def objective_ratio(risk: xr.Dataset, apart: bool = False) -> xr.DataArray:
    """λ/λ_target of each limit state of :func:`limit_state_risk` (NaN without an objective), λ_target = −ln(1 − p)/50 yr for its
    ``target`` p; with ``apart``, of λ with the runs beyond the model counted apart as collapses (λ as run where no run is).
    λ is the fit's, whether the runs pin it or not (:func:`judged_ratio` is what an objective is judged on)."""
    return _per_target(risk["maf_collapses_apart"] if apart and "maf_collapses_apart" in risk else risk["maf"], risk)


def _per_target(rate: xr.DataArray, risk: xr.Dataset) -> xr.DataArray:
    """``rate``/λ_target of each limit state of ``risk`` (NaN without an objective)."""
    target = risk["target"]
    return rate / xr.apply_ufunc(rate_from_probability, target.fillna(0.5), OBJECTIVE_YEARS).where(target.notnull())


def limit_state_pinned(risk: xr.Dataset, apart: bool = False) -> xr.DataArray:
    """Whether the runs pin each limit state's λ of :func:`limit_state_risk`: its fit (with ``apart``, the credible runs' fit
    behind λ with the runs beyond the model counted apart) is a lognormal the stripes identify
    (:func:`~stochpound.risk.unidentified` says nothing). A step (``never``, ``always``, ``separated``: the runs place no
    median or spread), a flat fit (``decreasing``) or a lognormal not identified is not: its λ rests on where the step or the
    extrapolation is put, and only the bounds of :func:`limit_state_bounds` are the runs'. With ``apart``, a limit state no
    credible run reaches has λ = λ_C, pinned where P(C | IM) is a lognormal the stripes identify. True throughout where
    ``risk`` holds no fit kinds (nothing to judge them by)."""
    fit = _fit_of(risk, apart)
    if "status" not in fit:
        return xr.ones_like(risk["maf"], dtype=bool)
    known = "intensity" in fit.coords
    pinned = identified(fit) if known else fit["status"] == FIT
    if apart and "collapse_identified" in risk:  # no credible run reaches it: λ is λ_C, pinned where P(C | IM) is
        pinned = pinned | ((fit["status"] == NEVER) & risk["collapse_identified"])
    return pinned


def limit_state_bounds(risk: xr.Dataset, apart: bool = False) -> tuple[xr.DataArray, xr.DataArray] | None:
    """λ⁻ and λ⁺ (1/yr) of each limit state of :func:`limit_state_risk`: the bounds the stripes' fractions alone give λ
    (:func:`~stochpound.risk.stripes_only_maf`, :func:`~stochpound.risk.stripes_upper_maf`), with ``apart`` a collapse counted as
    reaching it; None where ``risk`` holds none."""
    names = ("lower_collapses_apart", "upper_collapses_apart") if apart and "maf_collapses_apart" in risk else ("maf_lower", "maf_upper")
    return (risk[names[0]], risk[names[1]]) if all(name in risk for name in names) else None


def judged_ratio(risk: xr.Dataset, apart: bool = False) -> xr.DataArray:
    """λ/λ_target as an objective is judged on: the fit's ratio (``objective_ratio``) where the runs pin λ
    (:func:`limit_state_pinned`), else the lower bound's, λ⁻/λ_target (:func:`limit_state_bounds`): a limit state whose fit the
    runs do not pin misses its objective only where the runs alone say so (NaN without an objective)."""
    ratio = objective_ratio(risk, apart)
    bounds = limit_state_bounds(risk, apart)
    return ratio if bounds is None else ratio.where(limit_state_pinned(risk, apart), _per_target(bounds[0], risk))


def undecided(risk: xr.Dataset, apart: bool = False) -> xr.DataArray:
    """Per limit state and configuration, whether the runs leave open if it misses its objective: its fit does not pin λ
    (:func:`limit_state_pinned`) and its bounds straddle λ_target (λ⁻/λ_target ≤ 1 < λ⁺/λ_target); False without bounds."""
    bounds = limit_state_bounds(risk, apart)
    if bounds is None:
        return xr.zeros_like(risk["maf"], dtype=bool)
    lower, upper = (_per_target(bound, risk) for bound in bounds)
    return ~limit_state_pinned(risk, apart) & (upper > 1.0) & ~(lower > 1.0)


def governing_limit_state(risk: xr.Dataset, apart: bool = False, within: str = POUNDING) -> xr.DataArray | None:
    """Per configuration of :func:`limit_state_risk`, the limit state with the largest λ/λ_target (:func:`judged_ratio`: a fit
    the runs do not pin by its lower bound) where it exceeds 1 (it misses its objective), else ``within``; None where no limit
    state has an objective (nothing is said to govern).

    ``apart`` judges λ with the runs beyond the model counted apart as collapses: the two treatments may name different limit
    states (:func:`governing_disagreement`). A limit state whose bounds straddle its objective (:func:`undecided`) does not
    govern: the runs do not say it misses it.
    """
    if not bool(risk["target"].notnull().any()):
        return None
    ratio = judged_ratio(risk, apart)
    worst = ratio["limit_state"][ratio.fillna(-1.0).argmax("limit_state")].drop_vars("limit_state", errors="ignore")
    return worst.where((ratio > 1.0).any("limit_state"), within)


def governing_disagreement(risk: xr.Dataset, within: str = POUNDING) -> xr.DataArray | None:
    """Per configuration, whether what governs as run differs from what governs with the collapses counted apart; None without
    objectives or where no run is beyond the model (one treatment only)."""
    if "maf_collapses_apart" not in risk:
        return None
    run, apart = governing_limit_state(risk, False, within), governing_limit_state(risk, True, within)
    return None if run is None else run != apart


def _fit_of(risk: xr.Dataset, apart: bool) -> xr.Dataset:
    """``risk`` with, for ``apart``, the credible runs' fit (``status``, ``theta``, ``beta``) in place of the fit as run (as run
    where no run is beyond the model)."""
    if apart and "status_collapses_apart" in risk:
        return risk.assign({name: risk[f"{name}_collapses_apart"] for name in ("status", "theta", "beta")})
    return risk


def limit_state_fits(risk: xr.Dataset, apart: bool = False) -> xr.DataArray:
    """Each limit state's fit in words over :func:`limit_state_risk`'s dimensions: ``lognormal``, ``step: never`` …;
    ``lognormal, not identified (why)`` where :func:`~stochpound.risk.unidentified` says so; ``step at the lowest stripe: a
    bound`` where its λ is one (:func:`~stochpound.risk.at_lowest_stripe`). With ``apart``, the credible runs' fit behind λ
    with the runs beyond the model counted apart (the fit as run where no run is beyond it)."""
    risk = _fit_of(risk, apart)
    name = xr.apply_ufunc(np.vectorize(lambda status: fit_name(int(status)).replace("runs that pounded", "runs that reached it"), otypes=[object]),
                          risk["status"])  # a limit state is reached, not pounded
    why = unidentified(risk)
    name = xr.apply_ufunc(np.vectorize(lambda n, w: f"{n}, not identified ({w})" if w else n, otypes=[object]), name, why)
    return name.where(~at_lowest_stripe(risk), "step at the lowest stripe: a bound")


def objectives_frame(risk: xr.Dataset, within: str = WITHIN) -> pd.DataFrame | None:
    """What governs per configuration of :func:`limit_state_risk` at its finite gaps, each treatment of the runs beyond the
    model (``TREATMENTS``: as run, and collapses apart where some run is): the limit state with the largest λ/λ_target beyond 1
    (else ``within``) and that largest ratio (:func:`judged_ratio`: a fit the runs do not pin by its lower bound), and whether
    the treatments agree. None without any objective.

    Returns
    -------
    pandas.DataFrame or None
        Indexed by the grid labels other than ``limit_state`` (the contact-free rows left out where the grid has finite gaps).
    """
    finite = _inputs.at_finite_gaps(risk)
    data = finite if all(finite.sizes.values()) else risk
    columns = {}
    for apart in ([False, True] if "maf_collapses_apart" in data else [False]):
        governs = governing_limit_state(data, apart, within)
        if governs is None:
            return None
        columns[f"governs, {TREATMENTS[apart]}"] = governs.reset_coords(drop=True)
        columns[f"largest λ/λ_target, {TREATMENTS[apart]}"] = judged_ratio(data, apart).max("limit_state").reset_coords(drop=True)
    frame = xr.Dataset(columns).to_dataframe() if data["maf"].ndim > 1 else pd.DataFrame({k: [v.item()] for k, v in columns.items()})
    if "maf_collapses_apart" in data:
        frame["treatments agree"] = frame[f"governs, {TREATMENTS[False]}"] == frame[f"governs, {TREATMENTS[True]}"]
    return frame


def disagreement_text(frame: pd.DataFrame | None) -> str:
    """In words, whether the two treatments of :func:`objectives_frame` name the same governing limit state: where they
    disagree, each configuration and both answers; "" with one treatment only or without objectives."""
    if frame is None or "treatments agree" not in frame:
        return ""
    differ = frame[~frame["treatments agree"]]
    if differ.empty:
        return "The two treatments of the runs beyond the model name the same governing limit state in every configuration."
    rows = "; ".join(f"{_where(index, frame.index.names)}{row[f'governs, {TREATMENTS[False]}']} as run, "
                     f"{row[f'governs, {TREATMENTS[True]}']} with the collapses counted apart" for index, row in differ.iterrows())
    return (f"The two treatments disagree on what governs in {len(differ)} of {len(frame)} configurations ({rows}): the answer "
            "depends on whether the runs beyond the model are taken as computed or as collapses.")


def _where(index: object, names: Sequence[str | None]) -> str:
    """A configuration's labels in words from a frame's index, then ": " ("" for a frame of one unlabelled row)."""
    values = index if isinstance(index, tuple) else (index,)
    words = ", ".join(f"{name} {value:g}" if isinstance(value, float) else f"{name} {value}" for name, value in zip(names, values)
                      if name is not None)
    return f"{words}: " if words else ""


def gap_cost_frame(risk: xr.Dataset, years: float = YEARS) -> pd.DataFrame:
    """The "what the gap costs" table of :func:`limit_state_risk`: per limit state and finite gap, λ, λ of the twins, their difference, and P in ``years``
    (and λ with the runs beyond the model counted apart as collapses, where some run is), the fit's kind, and where the runs do
    not pin it (:func:`limit_state_pinned`) the bounds λ⁻ and λ⁺ they give λ (:func:`limit_state_bounds`): there λ is the fit's
    extrapolation, not the runs'.

    Returns
    -------
    pandas.DataFrame
        Indexed by the limit state and the other grid labels (the contact-free rows left out).
    """
    keep = [name for name in ("maf", "maf_contact_free", "gap_cost", "maf_collapses_apart") if name in risk]
    data = risk[keep].assign(fit=limit_state_fits(risk))
    bounds = limit_state_bounds(risk)
    if bounds is not None:  # where the runs do not pin the fit, the bounds they give λ (NaN where they pin it)
        pinned = limit_state_pinned(risk)
        data = data.assign(maf_lower=bounds[0].where(~pinned), maf_upper=bounds[1].where(~pinned))
    frame = _inputs.at_finite_gaps(data).reset_coords(drop=True).to_dataframe()
    frame[f"P in {years:g} yr"] = probability_from_rate(frame["maf"].to_numpy(), years)
    if "maf_contact_free" in frame:
        frame[f"P in {years:g} yr, contact-free"] = probability_from_rate(frame["maf_contact_free"].to_numpy(), years)
    return frame.rename(columns={"maf": "λ (1/yr)", "maf_contact_free": "λ contact-free (1/yr)", "gap_cost": "Δλ (1/yr)",
                                 "maf_collapses_apart": "λ collapses apart (1/yr)", "maf_lower": "λ⁻ if not pinned (1/yr)",
                                 "maf_upper": "λ⁺ if not pinned (1/yr)"})
