"""The answer without an intensity measure: a response's rate of exceedance at a site of ruptures, from motions of each (model §11).

A site given by its ruptures (:class:`~stochpound.analysis.RuptureSite`,
annual rates ν_r) has a demand hazard that needs no intensity measure:

    λ(D > x) = Σ_r ν_r P(D > x | r),

P(D > x | r) the fraction of the runs of rupture r's simulated motions
(:func:`~stochpound.motions.site_motions` of its magnitude, R_rup, the
site's Vs30, its mechanism and geometry) whose response D exceeds x. It is a
stratified Monte Carlo estimate, each rupture a stratum of n_r motions:

    λ̂(x) = Σ_r (ν_r / n_r) #{i : D_ri > x},

unbiased for every x at once from the same runs. D is a contact-free run's
largest closure (by the gap identity, pounding at gap g ⇔ closure > g, so
λ(closure > g) is the pounding rate of every gap g), a sliding base's
largest displacement or a storey's largest drift. The level exceeded at a
target rate (for the closure, the risk-targeted separation g*) is the
smallest x with λ̂(x) ≤ λ_target: walking down the runs' responses
(all ruptures together) and summing their weights ν_r/n_r, the response
at which the sum first exceeds λ_target.

*Importance over ruptures* (``extra``): a first stage of ``motions`` runs
per rupture, then ``extra`` more in :data:`ROUNDS` rounds, each shared out
by Neyman allocation on all the runs before it, n_r ∝ ν_r √(p_r (1 − p_r)),
at the level x* of the rarest target estimated from those runs; p_r is the
larger of rupture r's fraction of runs at or beyond x* and
Φc((ln x* − m_r)/s_r), m_r and s_r the mean and standard deviation of ln D
over its runs (a lognormal fit, used to allocate only: it resolves the
small p_r of frequent distant ruptures that a few runs' counts cannot). The
ruptures that carry the rate at the target get the runs. The estimate pools
all rounds and stays the count above (the allocation, not the estimate,
depends on the earlier runs).

*Interval*: the stratified bootstrap over motions within each rupture
(each rupture's runs resampled with replacement, ``bootstrap`` times, the
estimator recomputed), percentile intervals of λ̂(x) and of the level at
each target. It is the simulation's sampling interval alone: the ruptures
and their rates are the site's model, taken as given.

*Reproducible*: motion i of rupture r depends on (``seed``, r, i) alone
(rupture r's motions use the seed in ``motion_seed`` and a window fixed per
rupture, ``motion_duration``), so the result is the same whatever the
workers and however the runs are batched.
"""

from __future__ import annotations

import math
import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace
from typing import Any, Callable, Sequence

import numpy as np
import xarray as xr

from stochpound._errors import SiteError
from stochpound.analysis._subset_simulation import RESPONSES, _reader
from stochpound.hazard import RuptureSite, rate_from_probability
from stochpound.model.scene import Scene
from stochpound.motions import SITE_MOTION_LIMITS, Scenario, site_model_provenance, site_motions
from stochpound.motions.ground import SampledMotion
from stochpound.solvers.simulate import simulate
from stochpound.stats import kernels

MEASURE_FREE_RESPONSES = ("closure", "base_displacement", "peak_storey_drift")
"""The responses :func:`measure_free_risk` estimates the rate of (units in :data:`~stochpound.analysis.RESPONSES`)."""
OUTSIDE = ("refuse", "clamp")
"""What :func:`measure_free_risk` does with a rupture outside the site-motion model's range (its ``outside``)."""
CHUNK = 20
"""Motions generated and run at a time (one task of a worker)."""
THRESHOLDS = 200
"""Thresholds of the default grid, log-spaced from the smallest positive response to the largest."""
METHOD = ("stratified Monte Carlo over the site's ruptures: lambda(D > x) = sum_r nu_r (1/n_r) #{D_ri > x}, "
          "n_r runs of simulated motions of rupture r (site_motions of its scenario: magnitude, R_rup, the site's Vs30, its mechanism and geometry)")
INTERVAL = "stratified bootstrap over the motions within each rupture (rates nu_r taken as given), percentile interval"
ALLOCATION = ("Neyman allocation of the extra runs in rounds, n_r proportional to nu_r sqrt(p_r (1 - p_r)) at the level of the rarest "
              "target from the runs before, p_r the larger of the rupture's fraction beyond it and its lognormal fit's")
ROUNDS = 3
"""Rounds the extra runs come in, each allocated on all the runs before it."""
SPREAD_FLOOR = 0.05
"""Smallest standard deviation of ln D taken in the allocation's lognormal fit (runs that barely differ)."""


@dataclass(frozen=True)
class MeasureFreeDemand:
    """One response read from every run of :func:`measure_free_demands` (units in :data:`~stochpound.analysis.RESPONSES`).

    Attributes
    ----------
    response : {"closure", "base_displacement", "peak_storey_drift"}
        The run's largest closure (m), a sliding base's largest absolute
        displacement (m) or a storey's largest absolute drift (m).
    building : str, optional
        The building of ``base_displacement`` and ``peak_storey_drift``.
    floor : int, optional
        The storey of ``peak_storey_drift`` (1 = lowest); None: the largest over the building's storeys.
    contact : int, optional
        The contact of ``closure``; None: the largest over the contacts (the gap identity's, for one gap of all).
    """

    response: str = "closure"
    building: str | None = None
    floor: int | None = None
    contact: int | None = None

    def describe(self) -> str:
        """The demand in words, e.g. ``"storey drift of B1 (largest over its storeys)"``."""
        if self.response == "closure":
            return "closure (largest over the contacts)" if self.contact is None else f"closure of contact {self.contact}"
        if self.response == "base_displacement":
            return f"base displacement of {self.building}"
        return f"storey drift of {self.building} ({'largest over its storeys' if self.floor is None else f'storey {self.floor}'})"


@dataclass(frozen=True)
class _Rupture:
    """How one rupture's motions are drawn: the scenario run, its seed, window and whether it was clamped to the model's range."""

    scenario: Scenario
    seed: int
    duration: float
    clamped: str


@dataclass(frozen=True)
class _Task:
    """One batch of runs: a rupture's motions ``realizations`` of the scene, the demands read from each."""

    scene: Scene
    demands: tuple[MeasureFreeDemand, ...]
    rupture: _Rupture
    realizations: tuple[int, ...]
    n: int
    dt: float
    model: str


def measure_free_risk(
    scene: Scene,
    site: RuptureSite,
    response: str = "closure",
    *,
    motions: int = 100,
    extra: int = 0,
    seed: int = 0,
    building: str | None = None,
    floor: int | None = None,
    contact: int | None = None,
    thresholds: Sequence[float] | None = None,
    targets: Sequence[float] | None = None,
    years: float = 50.0,
    confidence: float = 0.95,
    bootstrap: int = 1000,
    outside: str = "refuse",
    dt: float = 0.01,
    model: str = "hazard_compatible",
    workers: int = 1,
) -> xr.Dataset:
    """The rate of exceedance of a run's response at a site of ruptures, with no intensity measure (module docstring; model §11).

    Parameters
    ----------
    scene : Scene
        The scene run under every motion (its own motion is replaced). For
        ``"closure"`` every contact must have gap ``inf`` (contact-free).
    site : RuptureSite
        The site's ruptures and their annual rates.
    response : {"closure", "base_displacement", "peak_storey_drift"}
        The run's largest closure (m; over all contacts, or of ``contact``),
        largest absolute sliding displacement of ``building``'s base (m), or
        largest absolute drift of storey ``floor`` of ``building`` (m).
    motions : int
        Runs of each rupture in the first stage (>= 2).
    extra : int
        Further runs (>= 0) shared out over the ruptures by Neyman allocation
        at the level of the rarest target, in rounds (module docstring).
    seed : int
        Seed (>= 0) of the motions: the same seed gives the same runs and result.
    building, floor, contact
        The building (of ``base_displacement`` and ``peak_storey_drift``),
        storey (1 = lowest; None: the largest over the building's storeys)
        and contact index (of ``closure``; None: the largest over the
        contacts, the gap identity's for one gap of all).
    thresholds : sequence of float, optional
        Levels x of the response (m) at which λ(D > x) is given; default
        200 log-spaced from the smallest positive response to the largest.
    targets : sequence of float, optional
        Probabilities of exceedance in ``years``, each in (0, 1) (default
        ``stochpound.risk.TARGETS``, 10 % and 2 %); their rates
        −ln(1 − p)/years (:func:`~stochpound.analysis.rate_from_probability`).
    years : float
        The targets' exposure time, yr.
    confidence : float
        Level of the intervals, in (0, 1).
    bootstrap : int
        Bootstrap resamples (>= 100).
    outside : {"refuse", "clamp"}
        A rupture outside the site-motion model's calibrated range (M 5.5–8,
        R_rup 5–100 km, Vs30 200–1100 m/s): refused (a one-line error naming
        the rupture and field), or run at the range's nearest edge, flagged in
        ``clamped``, its part of the rate given apart (``clamped_rate``) and
        the level at each target also without it (``level_without_clamped``).
    dt : float
        The motions' time step, s (<= 0.02).
    model : {"hazard_compatible", "rezaeian_2010"}
        The site-motion model.
    workers : int
        Processes running the batches (>= 1); the result does not depend on it.

    Returns
    -------
    xarray.Dataset
        Over ``threshold`` (m): ``rate_of_exceedance`` λ̂(x) (1/yr) with
        ``rate_lower``/``rate_upper``, ``clamped_rate``; over ``rupture``:
        ``rate`` ν_r, ``motions`` n_r, the scenario run (``magnitude``,
        ``distance_km``, ``mechanism``), ``clamped`` ("" or what was
        clamped), ``motion_seed`` and ``motion_duration`` (s), and over
        (``rupture``, ``threshold``) ``exceedance_probability``
        P̂(D > x | r); ``response_value`` (``rupture``, ``motion``: every
        run's response, NaN past n_r); over ``target``: ``target_rate``,
        ``level`` (the response exceeded at the target rate; for the closure
        the separation g*, m), ``level_lower``/``level_upper``,
        ``level_without_clamped``; over (``target``, ``rupture``):
        ``share_at_level`` (each rupture's share of the rate at the level)
        and ``motions_beyond`` (its runs at or beyond it). Attributes:
        ``runs``, ``seconds``, ``method``, ``interval``, ``allocation``,
        the settings and the site.

    Raises
    ------
    ValueError
        One line naming the argument: a response, building, storey or contact
        the scene does not have, a contact not contact-free, a count, seed,
        target or level out of range.
    SiteError
        A rupture outside the site-motion model's range with ``outside="refuse"``,
        naming the rupture and the field.
    """
    demand = MeasureFreeDemand(response, building, floor, contact)
    return measure_free_demands(scene, site, [demand], motions=motions, extra=extra, seed=seed, thresholds=thresholds, targets=targets,
                                years=years, confidence=confidence, bootstrap=bootstrap, outside=outside, dt=dt, model=model, workers=workers)[0]


def measure_free_demands(
    scene: Scene,
    site: RuptureSite,
    demands: Sequence[MeasureFreeDemand],
    *,
    motions: int = 100,
    extra: int = 0,
    seed: int = 0,
    thresholds: Sequence[float] | None = None,
    targets: Sequence[float] | None = None,
    years: float = 50.0,
    confidence: float = 0.95,
    bootstrap: int = 1000,
    outside: str = "refuse",
    dt: float = 0.01,
    model: str = "hazard_compatible",
    workers: int = 1,
) -> tuple[xr.Dataset, ...]:
    """Several demands' rates of exceedance at a site of ruptures from the same runs (:func:`measure_free_risk` of each).

    Every run is read for every demand; the extra runs are allocated at the
    rarest target's level of the *first* demand (the others' estimates stay
    the same unbiased count over the runs, their intervals say how well
    those runs serve them). The arguments are :func:`measure_free_risk`'s.

    Returns
    -------
    tuple of xarray.Dataset
        One dataset per demand, as :func:`measure_free_risk` returns, in the order given
        (attribute ``allocated_on``: the demand the extra runs were allocated for).

    Raises
    ------
    ValueError, SiteError
        As :func:`measure_free_risk`; ``demands`` empty or not :class:`MeasureFreeDemand`.
    """
    started = time.perf_counter()
    if not demands or not all(isinstance(d, MeasureFreeDemand) for d in demands):
        raise ValueError(f"demands: must be one or more MeasureFreeDemand, got {demands!r}")
    demands = tuple(_check_demand(scene, demand) for demand in demands)
    _check_counts(motions, extra, seed, bootstrap, workers)
    kernels.check_confidence(confidence)
    target_rates = _target_rates(targets, years)
    if outside not in OUTSIDE:
        raise ValueError(f"outside: must be one of {', '.join(OUTSIDE)}, got {outside!r}")
    ruptures = [_rupture(site, index, outside, seed, motions + extra, dt, model) for index in range(len(site))]
    run = _Runner(scene, demands, ruptures, motions + extra, dt, model, workers)
    values = run([range(motions)] * len(site))
    for step in range(ROUNDS if extra else 0):
        counts = neyman_allocation([v[:, 0] for v in values], np.asarray(site.rate), float(target_rates.min()),
                                   extra * (step + 1) // ROUNDS - extra * step // ROUNDS)
        more = run([range(len(v), len(v) + count) for v, count in zip(values, counts)])
        values = [np.concatenate(pair) for pair in zip(values, more)]
    clamped = np.array([bool(r.clamped) for r in ruptures])
    attrs = {
        "runs": int(sum(len(v) for v in values)), "seconds": time.perf_counter() - started, "seed": int(seed), "first_stage": int(motions),
        "extra": int(extra), "years": float(years), "confidence": float(confidence), "bootstrap": int(bootstrap), "outside": outside,
        "dt": float(dt), "model": model, "model_provenance": site_model_provenance(model), "method": METHOD, "interval": INTERVAL,
        "allocation": ALLOCATION if extra else "the same runs for every rupture", "allocated_on": demands[0].describe(), "site": site.describe(),
        "targets": np.asarray(_targets_or_default(targets), dtype=float)}
    results = []
    for k, demand in enumerate(demands):
        each = [v[:, k] for v in values]
        result = _estimate(each, np.asarray(site.rate), target_rates, thresholds, confidence, bootstrap, seed, clamped)
        results.append(_dataset(result, site, ruptures, each, demand, dict(attrs)))
    return tuple(results)


def _targets_or_default(targets: Sequence[float] | None) -> Sequence[float]:
    """The target probabilities: those given, or the risk chain's (``stochpound.risk.TARGETS``)."""
    if targets is not None:
        return targets
    from stochpound.risk import TARGETS  # the risk chain's targets, imported when used (the statistics do not import it)

    return TARGETS


def _target_rates(targets: Sequence[float] | None, years: float) -> np.ndarray:
    values = np.atleast_1d(np.asarray(_targets_or_default(targets), dtype=float))
    if values.ndim != 1 or not values.size or not np.all((values > 0.0) & (values < 1.0)):
        raise ValueError(f"targets: must be one or more probabilities in (0, 1), got {targets!r}")
    if isinstance(years, bool) or not isinstance(years, (int, float)) or not 0.0 < years < math.inf:
        raise ValueError(f"years: must be a number of years > 0, got {years!r}")
    return np.atleast_1d(rate_from_probability(values, years))


def _check_demand(scene: Any, demand: MeasureFreeDemand) -> MeasureFreeDemand:
    """The demand, checked against the scene (its response, building, storey or contact)."""
    if not isinstance(scene, Scene):
        raise ValueError(f"scene: must be a Scene, got {type(scene).__name__}")
    if demand.response not in MEASURE_FREE_RESPONSES:
        raise ValueError(f"response: must be one of {', '.join(MEASURE_FREE_RESPONSES)}, got {demand.response!r}")
    if demand.response == "closure":
        if not scene.contacts:
            raise ValueError("scene: has no contact (the closure needs one)")
        closing = [i for i, c in enumerate(scene.contacts) if math.isfinite(c.gap)]
        if closing:
            raise ValueError(f"scene: contact {closing[0]} has gap {scene.contacts[closing[0]].gap:g} m; the closure needs a contact-free scene (every gap inf), "
                             "whose closure gives every gap's pounding (the gap identity)")
    response_reader(scene, demand)
    return demand


def _check_counts(motions: Any, extra: Any, seed: Any, bootstrap: Any, workers: Any) -> None:
    for name, value, low in (("motions", motions, 2), ("extra", extra, 0), ("seed", seed, 0), ("bootstrap", bootstrap, 100), ("workers", workers, 1)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
            raise ValueError(f"{name}: must be an integer >= {low}, got {value!r}")


def _rupture(site: RuptureSite, index: int, outside: str, seed: int, most: int, dt: float, model: str) -> _Rupture:
    """Rupture ``index``'s motions: its scenario within the model's range (or refused), its seed and window."""
    row = site.row(index)
    asked = {"magnitude": row["magnitude"], "distance_km": row["distance_rup_km"], "vs30": site.vs30}
    run, clamped = dict(asked), []
    for field, value in asked.items():
        low, high = SITE_MOTION_LIMITS[field]
        if low <= value <= high:
            continue
        where = "site.vs30" if field == "vs30" else f"site rupture {index} ({site.names[index]}): {'magnitude' if field == 'magnitude' else 'distance_rup_km'}"
        if outside == "refuse":
            raise SiteError(f"{where}: {value:g} is outside the site-motion model's range {low:g}-{high:g} "
                            "(outside='clamp' runs it at the range's edge and gives its part of the rate apart)")
        run[field] = min(max(value, low), high)
        clamped.append(f"{field} {value:g} -> {run[field]:g}")
    # the rupture's own scenario, geometry included (the hazard-compatible model follows its NGA-West2 medians), unless clamped
    scenario = Scenario(**run, mechanism=row["mechanism"]) if clamped or model == "rezaeian_2010" else site.scenario(index)
    motion_seed = int(np.random.SeedSequence([seed, index]).generate_state(1)[0])
    first = site_motions(scenario=scenario, n=most, seed=motion_seed, dt=dt, model=model, realizations=[0])
    return _Rupture(scenario, motion_seed, float(first["time"].values[-1]), "; ".join(clamped))


class _Runner:
    """Runs batches of each rupture's motions (in ``workers`` processes), reading the response of each run."""

    def __init__(self, scene: Scene, demands: tuple[MeasureFreeDemand, ...], ruptures: list[_Rupture], n: int, dt: float, model: str,
                 workers: int) -> None:
        self.scene, self.demands, self.ruptures, self.n, self.dt, self.model, self.workers = scene, demands, ruptures, n, dt, model, workers

    def __call__(self, wanted: Sequence[range]) -> list[np.ndarray]:
        """The demands (realization, demand) of the realizations ``wanted[r]`` of each rupture r, in their order."""
        tasks = [(r, _Task(self.scene, self.demands, self.ruptures[r], tuple(chunk), self.n, self.dt, self.model))
                 for r, indices in enumerate(wanted) for chunk in _chunks(list(indices))]
        if self.workers > 1 and len(tasks) > 1:
            with ProcessPoolExecutor(self.workers, mp_context=multiprocessing.get_context("spawn")) as pool:
                results = list(pool.map(run_task, [task for _, task in tasks]))
        else:
            results = [run_task(task) for _, task in tasks]
        out = [[] for _ in wanted]
        for (r, _), values in zip(tasks, results):
            out[r].append(values)
        return [np.concatenate(parts) if parts else np.empty((0, len(self.demands))) for parts in out]


def _chunks(indices: list[int]) -> list[list[int]]:
    return [indices[i:i + CHUNK] for i in range(0, len(indices), CHUNK)]


def run_task(task: _Task) -> np.ndarray:
    """The demands (realization, demand) of one batch: its motions generated and each run (a worker's job; module-level so that it pickles)."""
    generated = site_motions(scenario=task.rupture.scenario, n=task.n, seed=task.rupture.seed, dt=task.dt, duration=task.rupture.duration,
                             model=task.model, realizations=list(task.realizations))
    readers = [response_reader(task.scene, demand) for demand in task.demands]
    drift = any(demand.response == "peak_storey_drift" for demand in task.demands)
    label = f"site motion of M {task.rupture.scenario.magnitude:g} at {task.rupture.scenario.distance_km:g} km"
    runs = (simulate(replace(task.scene, motion=SampledMotion(task.dt, a, "linear", label)), demands=drift) for a in generated["acceleration"].values)
    return np.array([[read(run) for read in readers] for run in runs], dtype=float).reshape(-1, len(readers))


def response_reader(scene: Scene, demand: MeasureFreeDemand) -> Callable[[xr.Dataset], float]:
    """The demand read from a run: the closure of ``contact`` (None: the largest over the contacts), a storey drift (floor None:
    the largest over the building's storeys), or subset simulation's readers (which check the building, storey and contact)."""
    if demand.response == "closure" and demand.contact is None:
        return lambda run: float(np.max(run["peak_contact_closure"].values))
    if demand.response == "peak_storey_drift" and demand.floor is None:
        _reader(scene, demand.response, demand.building, 1, 0)
        return lambda run: float(np.max(run["peak_storey_drift"].sel(building=demand.building).values))
    return _reader(scene, demand.response, demand.building, demand.floor, 0 if demand.contact is None else demand.contact)


def neyman_allocation(values: Sequence[np.ndarray], rates: np.ndarray, target_rate: float, extra: int) -> np.ndarray:
    """Extra runs per rupture, ∝ ν_r √(p_r (1 − p_r)) at the first stage's level of ``target_rate`` (module docstring), summing to ``extra``."""
    level = rate_weighted_levels(values, rates, [target_rate])[0]
    p = np.array([max(_lognormal_exceedance(v, level), np.count_nonzero(v >= level) / v.size) for v in values])
    spread = rates * np.sqrt(p * (1.0 - p))
    if not spread.sum() > 0.0:
        spread = rates.astype(float)
    share = extra * spread / spread.sum()
    counts = np.floor(share).astype(int)
    counts[np.argsort(-(share - counts), kind="stable")[: extra - counts.sum()]] += 1  # largest remainders
    return counts


def _lognormal_exceedance(values: np.ndarray, level: float) -> float:
    """P(D > level) of the lognormal fitted to the positive responses (0 without any, or at a level <= 0: 1)."""
    from scipy.special import ndtr

    if level <= 0.0:
        return 1.0
    logs = np.log(values[values > 0.0])
    if logs.size < 2:
        return 0.0
    return float(ndtr((logs.mean() - math.log(level)) / max(float(logs.std(ddof=1)), SPREAD_FLOOR)))


def _weights(values: Sequence[np.ndarray], rates: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """All runs' responses sorted from the largest, the rupture of each and its weight ν_r/n_r."""
    responses = np.concatenate(values)
    rupture = np.concatenate([np.full(v.size, r) for r, v in enumerate(values)])
    weight = np.concatenate([np.full(v.size, rates[r] / v.size) for r, v in enumerate(values)])
    order = np.argsort(-responses, kind="stable")
    return responses[order], rupture[order], weight[order]


def _rates_at(sorted_responses: np.ndarray, cumulative: np.ndarray, thresholds: np.ndarray) -> np.ndarray:
    """λ̂(x) = the weights of the runs with D > x, from the cumulative weights along the sorted runs (last axis)."""
    above = np.searchsorted(-sorted_responses, -thresholds, side="left")  # runs with D > x
    padded = np.concatenate([np.zeros(cumulative.shape[:-1] + (1,)), cumulative], axis=-1)
    return padded[..., above]


def _level_from(sorted_responses: np.ndarray, cumulative: np.ndarray, target_rates: np.ndarray) -> np.ndarray:
    """The smallest x with λ̂(x) <= each target rate: the response at which the cumulative weight first exceeds it (0 if it never does)."""
    first = np.stack([np.argmax(cumulative > rate, axis=-1) for rate in target_rates], axis=-1)
    reached = np.stack([cumulative[..., -1] > rate for rate in target_rates], axis=-1)
    return np.where(reached, sorted_responses[first], 0.0)


def rate_weighted_levels(values: Sequence[np.ndarray], rates: np.ndarray | Sequence[float], target_rates: np.ndarray | Sequence[float]) -> np.ndarray:
    """The level a response exceeds at each target rate, from runs of each rupture weighted by its rate (the measure-free estimate).

    Each of rupture r's n_r runs carries ν_r/n_r; λ̂(x) is the summed weight of
    the runs with a response above x, and the level is the smallest x with
    λ̂(x) ≤ the target: the response at which the weights summed from the
    largest first exceed the target.

    Parameters
    ----------
    values : sequence of numpy.ndarray
        Each rupture's runs' responses (any units; 1-D, at least one run).
    rates : array_like
        ν_r, each rupture's annual rate (1/yr), one per entry of ``values``.
    target_rates : array_like
        The rates (1/yr) to read the level at.

    Returns
    -------
    numpy.ndarray
        One level per target rate, in the responses' units; 0 where all the
        runs' weight does not exceed the target.
    """
    responses, _, weight = _weights([np.asarray(v, dtype=float) for v in values], np.asarray(rates, dtype=float))
    return _level_from(responses, np.cumsum(weight), np.asarray(target_rates, dtype=float))


@dataclass(frozen=True)
class _Estimate:
    thresholds: np.ndarray
    rate: np.ndarray
    rate_interval: np.ndarray
    clamped_rate: np.ndarray
    probability: np.ndarray
    target_rates: np.ndarray
    level: np.ndarray
    level_interval: np.ndarray
    level_without_clamped: np.ndarray


def _estimate(values: list[np.ndarray], rates: np.ndarray, target_rates: np.ndarray, thresholds: Sequence[float] | None, confidence: float,
              bootstrap: int, seed: int, clamped: np.ndarray) -> _Estimate:
    """λ̂ at the thresholds and the levels at the targets, with their stratified-bootstrap intervals."""
    grid = _thresholds(thresholds, np.concatenate(values))
    responses, rupture, weight = _weights(values, rates)
    cumulative = np.cumsum(weight)
    rng = np.random.default_rng(np.random.SeedSequence([seed, len(values), 1]))
    counts = np.empty((bootstrap, responses.size))
    for r, v in enumerate(values):
        where = rupture == r
        counts[:, where] = rng.multinomial(v.size, np.full(v.size, 1.0 / v.size), size=bootstrap)
    resampled = np.cumsum(counts * weight, axis=-1)
    tails = [(1.0 - confidence) / 2.0 * 100.0, (1.0 + confidence) / 2.0 * 100.0]
    kept = np.cumsum(np.where(clamped[rupture], 0.0, weight))
    return _Estimate(
        thresholds=grid,
        rate=_rates_at(responses, cumulative, grid),
        rate_interval=np.percentile(_rates_at(responses, resampled, grid), tails, axis=0),
        clamped_rate=_rates_at(responses, np.cumsum(np.where(clamped[rupture], weight, 0.0)), grid),
        probability=np.array([[np.count_nonzero(v > x) / v.size for x in grid] for v in values]),
        target_rates=target_rates,
        level=_level_from(responses, cumulative, target_rates),
        level_interval=np.percentile(_level_from(responses, resampled, target_rates), tails, axis=0),
        level_without_clamped=_level_from(responses, kept, target_rates),
    )


def _thresholds(thresholds: Sequence[float] | None, responses: np.ndarray) -> np.ndarray:
    if thresholds is None:
        positive = responses[responses > 0.0]
        if not positive.size:
            raise ValueError("thresholds: no run has a positive response to span; give the thresholds")
        return np.unique(np.geomspace(positive.min(), positive.max(), THRESHOLDS))
    grid = np.atleast_1d(np.asarray(thresholds, dtype=float))
    if grid.ndim != 1 or not grid.size or not np.all(np.isfinite(grid)) or np.any(np.diff(grid) <= 0.0):
        raise ValueError(f"thresholds: must be one or more finite, strictly increasing levels (m), got {thresholds!r}")
    return grid


def _dataset(estimate: _Estimate, site: RuptureSite, ruptures: list[_Rupture], values: list[np.ndarray], demand: MeasureFreeDemand,
             attrs: dict[str, float | str | np.ndarray]) -> xr.Dataset:
    units = RESPONSES[demand.response]
    names = list(site.names)
    table = np.full((len(values), max(v.size for v in values)), np.nan)
    for r, v in enumerate(values):
        table[r, : v.size] = v
    beyond = np.array([[np.count_nonzero(v >= level) for v in values] for level in estimate.level])
    share = np.array([[site.rate[r] * np.count_nonzero(v >= level) / v.size for r, v in enumerate(values)] for level in estimate.level])
    share = share / np.where(share.sum(axis=1, keepdims=True) > 0.0, share.sum(axis=1, keepdims=True), 1.0)
    rate_attrs = {"units": "1/yr"}
    data = {
        "rate_of_exceedance": ("threshold", estimate.rate, {**rate_attrs, "long_name": f"annual rate of the {demand.response} exceeding the threshold"}),
        "rate_lower": ("threshold", estimate.rate_interval[0], rate_attrs),
        "rate_upper": ("threshold", estimate.rate_interval[1], rate_attrs),
        "clamped_rate": ("threshold", estimate.clamped_rate, {**rate_attrs, "long_name": "part of the rate from ruptures clamped to the model's range"}),
        "exceedance_probability": (("rupture", "threshold"), estimate.probability, {"units": "1", "long_name": "fraction of the rupture's runs beyond the threshold"}),
        "rate": ("rupture", np.asarray(site.rate, dtype=float), {**rate_attrs, "long_name": "annual rate of occurrence of the rupture"}),
        "motions": ("rupture", np.array([v.size for v in values]), {"units": "1", "long_name": "runs of the rupture's simulated motions"}),
        "magnitude": ("rupture", np.array([r.scenario.magnitude for r in ruptures], dtype=float), {"units": "1", "long_name": "magnitude of the motions run"}),
        "distance_km": ("rupture", np.array([r.scenario.distance_km for r in ruptures], dtype=float), {"units": "km", "long_name": "R_rup of the motions run"}),
        "mechanism": ("rupture", np.array([r.scenario.mechanism for r in ruptures], dtype=object)),
        "clamped": ("rupture", np.array([r.clamped for r in ruptures], dtype=object), {"long_name": "what was clamped to the site-motion model's range"}),
        "motion_seed": ("rupture", np.array([r.seed for r in ruptures], dtype=np.int64), {"long_name": "seed of the rupture's site_motions"}),
        "motion_duration": ("rupture", np.array([r.duration for r in ruptures]), {"units": "s", "long_name": "window of the rupture's site_motions"}),
        "response_value": (("rupture", "motion"), table, {"units": units, "long_name": f"each run's {demand.response} (NaN past the rupture's runs)"}),
        "target_rate": ("target", estimate.target_rates, rate_attrs),
        "level": ("target", estimate.level, {"units": units, "long_name": f"{demand.response} exceeded at the target rate (closure: the separation g*)"}),
        "level_lower": ("target", estimate.level_interval[0], {"units": units}),
        "level_upper": ("target", estimate.level_interval[1], {"units": units}),
        "level_without_clamped": ("target", estimate.level_without_clamped, {"units": units, "long_name": "level with the clamped ruptures left out"}),
        "share_at_level": (("target", "rupture"), share, {"units": "1", "long_name": "each rupture's share of the rate at the level"}),
        "motions_beyond": (("target", "rupture"), beyond, {"units": "1", "long_name": "the rupture's runs at or beyond the level"}),
    }
    coords = {"threshold": ("threshold", estimate.thresholds, {"units": units}), "rupture": names, "motion": np.arange(table.shape[1]),
              "target": ("target", attrs.pop("targets"), {"units": "1", "long_name": f"probability of exceedance in {attrs['years']:g} years"})}
    demand_attrs = {"response": demand.response, "units": units, "building": demand.building or "", "floor": demand.floor or 0,
                    "contact": "largest over the contacts" if demand.response == "closure" and demand.contact is None else
                    str(demand.contact if demand.contact is not None else ""), "demand": demand.describe()}
    return xr.Dataset(data, coords=coords, attrs={**attrs, **demand_attrs})
