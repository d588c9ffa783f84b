"""Subset simulation (Au & Beck 2001): small exceedance probabilities of a response, model §13.

The response Y = g(u) is a function of n independent standard normals u (a
synthetic motion's randomness, :func:`~stochpound.motions.normal_motion`).
P(Y > b) is written as a product of conditional probabilities of nested
events {Y ≥ b_i}: level 0 is crude Monte Carlo with N samples; each
intermediate threshold b_{i+1} is the p0·N-th largest response of level i,
so that p0·N samples reach it (a few more when a chain's repeated state
ties with it); they seed as many Markov chains of 1/p0 states each, which
sample level i + 1 from the conditional distribution given Y ≥ b_{i+1}.
The levels stop when at least p0·N samples of a level exceed the largest
threshold asked for (or after ``max_levels``). For any threshold b with
b_i ≤ b < b_{i+1} (the last level's b_{i+1} = ∞),

    P(Y > b) ≈ p_0 ⋯ p_{i−1} · P_i(b),

p_j the fraction of level j that reached b_{j+1} (p0, or a little more
with ties) and P_i(b) the fraction of level i's samples above b,

so one run gives the whole exceedance curve down to the target.

The chains move by the component-wise modified Metropolis algorithm of
Au & Beck (2001): each component's candidate ξ_k is uniform on
u_k ± 1 and replaces u_k with probability min(1, φ(ξ_k)/φ(u_k)); the
candidate state is accepted if its response reaches the level's threshold,
else the chain repeats its state. All chains advance together: the
response is evaluated on the candidates of every chain at once.

The coefficient of variation is Au & Beck's, δ² = Σ_j δ_j², with
δ_0² = (1 − p)/(p N) for level 0 and δ_j² = (1 − p)/(p N_j)(1 + γ_j) for a
level of chains (N_j its samples), γ_j = 2 Σ_{k=1}^{N_s−1} (1 − k/N_s) ρ_j(k) from the
correlation ρ_j of the indicator along the chains (N_s states a chain),
computed for the probability actually estimated at that level: p_j and the
indicator of Y ≥ b_{j+1} for the intermediate levels, P_i(b) and the
indicator of Y > b for the last one. The levels' estimates are taken as
uncorrelated, as Au & Beck (2001) do.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Callable, Mapping, Sequence

import numpy as np
import xarray as xr

from stochpound.model.scene import Scene
from stochpound.motions import normal_motion
from stochpound.motions.ground import SampledMotion
from stochpound.solvers.simulate import simulate

#: The responses of a run that :func:`subset_simulation` samples (its ``response``), with their units.
RESPONSES = {"closure": "m", "peak_storey_drift": "m", "base_displacement": "m", "impact_force": "N"}
METHOD = "subset simulation (Au & Beck 2001), component-wise modified Metropolis with a uniform proposal of half-width 1"


@dataclass(frozen=True)
class _Level:
    """One level: its conditioning threshold (−∞ for level 0) and its responses as (chains, states a chain)."""

    threshold: float
    responses: np.ndarray
    acceptance: float


def subset_simulation(
    scene: Scene | Callable[[np.ndarray], np.ndarray],
    motion: Mapping[str, Any] | None = None,
    response: str = "closure",
    *,
    thresholds: Sequence[float],
    building: str | None = None,
    floor: int | None = None,
    contact: int = 0,
    samples_per_level: int = 1000,
    p0: float = 0.1,
    seed: int = 0,
    max_levels: int = 20,
    dimension: int | None = None,
) -> xr.Dataset:
    """Probabilities that a run's response exceeds thresholds, by subset simulation (model §13).

    Parameters
    ----------
    scene : Scene or callable
        The scene whose runs give the response (its own motion is replaced by
        ``motion``'s), or any function g(u) mapping (m, n) standard normals to
        (m,) responses (then give ``dimension``; ``motion`` and ``response``
        are not used).
    motion : mapping
        A synthetic ensemble's fields, as an experiment's ``[synthetic.<name>]``
        table writes them (:func:`~stochpound.motions.normal_motion`); use
        ``method = "filter"`` for a filtered process, which is exactly Gaussian.
    response : {"closure", "peak_storey_drift", "base_displacement", "impact_force"}
        The run's largest closure of contact ``contact`` (m,
        ``peak_contact_closure``), largest absolute drift of storey ``floor`` of
        ``building`` (m, ``peak_storey_drift``), largest absolute sliding
        displacement of ``building``'s base at the samples (m), or largest
        force of an impact at contact ``contact`` (N, 0 without impact).
    thresholds : sequence of float
        Thresholds b, in the response's units; the levels go on until the
        largest is reached.
    building : str, optional
        The building of ``peak_storey_drift`` and ``base_displacement``.
    floor : int, optional
        The storey (1 = lowest) of ``peak_storey_drift``.
    contact : int
        The contact index of ``closure`` and ``impact_force``.
    samples_per_level : int
        N, the samples of each level (runs of level 0); p0·N must be an
        integer that divides N. A level whose threshold ties with a chain's
        repeated state takes the tied samples as seeds too, and so has a few
        more samples.
    p0 : float
        The conditional probability of each intermediate level, in (0, 0.5].
    seed : int
        Seed (>= 0) of the sampler: the same seed gives the same estimate.
    max_levels : int
        Most levels (level 0 included) before stopping short of the largest threshold.
    dimension : int, optional
        n, when ``scene`` is a function of the normals.

    Returns
    -------
    xarray.Dataset
        Over ``threshold``: ``probability`` (of the response exceeding it) and
        ``cov`` (its estimated coefficient of variation, NaN where the
        probability is 0); attrs: ``runs`` (solver runs, or evaluations of g),
        ``level_thresholds``, ``gamma`` and ``acceptance`` per level,
        ``target_reached`` (1 if the last level reached the largest
        threshold), ``p0``, ``samples_per_level``, ``seed`` and ``method``.

    Raises
    ------
    ValueError
        Naming the argument that is out of range, or the response when it ties
        at a level's threshold (it does not vary in more than 1 − p0 of the
        level's samples: sample a response that keeps varying, e.g. the
        closure rather than the impact force).
    """
    chains, values, rng = _settings(thresholds, samples_per_level, p0, seed, max_levels)
    function, n, units = _response_function(scene, motion, response, building, floor, contact, dimension)
    levels, runs = _levels(function, n, values.max(), samples_per_level, chains, rng, max_levels)
    gamma = [0.0] + [_gamma(level.responses >= nxt.threshold) for level, nxt in zip(levels[1:-1], levels[2:])]
    probability, cov = _curve(levels, gamma, values)
    attrs = {
        "runs": runs,
        "levels": len(levels),
        "level_thresholds": np.array([level.threshold for level in levels[1:]], dtype=float),
        "gamma": np.array(gamma[: len(levels) - 1], dtype=float),
        "acceptance": np.array([level.acceptance for level in levels[1:]], dtype=float),
        "target_reached": int(np.count_nonzero(levels[-1].responses > values.max()) >= chains),
        "p0": float(p0),
        "samples_per_level": int(samples_per_level),
        "seed": int(seed),
        "method": METHOD,
        "response": response if not callable(scene) else "g(u)",
    }
    coords = {"threshold": xr.Variable(("threshold",), values, {"units": units})}
    return xr.Dataset(
        {
            "probability": xr.Variable(("threshold",), probability, {"units": "1", "long_name": "probability of the response exceeding the threshold"}),
            "cov": xr.Variable(("threshold",), cov, {"units": "1", "long_name": "estimated coefficient of variation of the probability"}),
        },
        coords=coords,
        attrs=attrs,
    )


def _settings(thresholds: Any, samples: Any, p0: Any, seed: Any, max_levels: Any) -> tuple[int, np.ndarray, np.random.Generator]:
    """The number of chains, the thresholds and the sampler's generator, each argument checked."""
    if not isinstance(p0, (int, float)) or isinstance(p0, bool) or not 0.0 < p0 <= 0.5:
        raise ValueError(f"p0: must be a number in (0, 0.5], got {p0!r}")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise ValueError(f"samples_per_level: must be an integer >= 2, got {samples!r}")
    chains = round(p0 * samples)
    if chains < 1 or not math.isclose(chains, p0 * samples) or samples % chains:
        raise ValueError(f"samples_per_level: p0 × samples_per_level must be an integer that divides it (p0 = {p0:g}), got {samples}")
    if isinstance(max_levels, bool) or not isinstance(max_levels, (int, np.integer)) or max_levels < 1:
        raise ValueError(f"max_levels: must be an integer >= 1, got {max_levels!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed: must be an integer >= 0, got {seed!r}")
    values = np.atleast_1d(np.asarray(thresholds, dtype=float))
    if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values)):
        raise ValueError(f"thresholds: must be one or more finite numbers, got {thresholds!r}")
    return chains, values, np.random.default_rng(seed)


def _levels(
    function: Callable[[np.ndarray], np.ndarray], n: int, target: float, samples: int, chains: int, rng: np.random.Generator, max_levels: int
) -> tuple[list[_Level], int]:
    """The levels down to ``target``, and the evaluations of ``function`` they took."""
    u = rng.standard_normal((samples, n))
    y = _evaluate(function, u)
    levels, runs = [_Level(-math.inf, y[:, None], 1.0)], samples
    length = samples // chains
    while np.count_nonzero(y > target) < chains and len(levels) < max_levels:
        order = np.argsort(-y, kind="stable")
        threshold = y[order[chains - 1]]
        seeds = order[y[order] >= threshold]  # the top p0·N, and any state tied with the last (a chain's repeated state)
        if len(seeds) == len(y) or len(seeds) > 2 * chains:
            raise ValueError(
                f"response: ties at level {len(levels)}'s threshold ({threshold:g} is the response of {len(seeds) - chains + 1} of its {len(y)} samples); "
                "subset simulation needs a response that keeps varying (e.g. the closure rather than the impact force)"
            )
        u, y, accepted = _chains(function, u[seeds], y[seeds], threshold, length, rng)
        runs += len(seeds) * (length - 1)
        levels.append(_Level(threshold, y.reshape(length, len(seeds)).T, accepted))
    return levels, runs


def _chains(
    function: Callable[[np.ndarray], np.ndarray], u: np.ndarray, y: np.ndarray, threshold: float, length: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, float]:
    """``length`` states of each chain started at ``u`` (all in {Y ≥ threshold}), state by state; and the acceptance rate.

    Returns the states and responses ordered state-major (state 0 of every
    chain, then state 1, ...), and the fraction of candidates accepted.
    """
    states, responses, accepted = [u], [y], 0
    for _ in range(length - 1):
        candidate = _modified_metropolis(u, rng)
        response = _evaluate(function, candidate)
        move = response >= threshold
        u = np.where(move[:, None], candidate, u)
        y = np.where(move, response, y)
        accepted += int(np.count_nonzero(move))
        states.append(u)
        responses.append(y)
    rate = accepted / (len(y) * (length - 1)) if length > 1 else 1.0
    return np.concatenate(states), np.concatenate(responses), rate


def _modified_metropolis(u: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Component-wise candidates: ξ uniform on u ± 1, each kept with probability min(1, φ(ξ)/φ(u))."""
    proposal = u + rng.uniform(-1.0, 1.0, u.shape)
    keep = rng.random(u.shape) < np.exp(0.5 * (u * u - proposal * proposal))
    return np.where(keep, proposal, u)


def _evaluate(function: Callable[[np.ndarray], np.ndarray], u: np.ndarray) -> np.ndarray:
    y = np.asarray(function(u), dtype=float).reshape(-1)
    if y.shape != (len(u),) or not np.all(np.isfinite(y)):
        raise ValueError(f"response: must give one finite number per sample ({len(u)}), got shape {y.shape} with {np.count_nonzero(~np.isfinite(y))} not finite")
    return y


def _curve(levels: list[_Level], gamma: list[float], thresholds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """P(Y > b) and its coefficient of variation for every threshold b (``gamma``: γ_j of each level's step to the next, γ_0 = 0)."""
    bounds = np.array([level.threshold for level in levels[1:]])
    steps = [nxt.responses.shape[0] / level.responses.size for level, nxt in zip(levels, levels[1:])]  # p_j = P(Y ≥ b_{j+1} | Y ≥ b_j)
    variances = [(1.0 - p) / (p * level.responses.size) * (1.0 + g) for p, level, g in zip(steps, levels, gamma)]
    probability, cov = np.empty(thresholds.size), np.empty(thresholds.size)
    for index, b in enumerate(thresholds):
        level = int(np.searchsorted(bounds, b, side="right"))  # the levels conditioned on thresholds <= b
        indicator = levels[level].responses > b
        p = float(indicator.mean())
        probability[index] = math.prod(steps[:level]) * p
        own = (1.0 - p) / (p * indicator.size) * (1.0 + (_gamma(indicator) if level else 0.0)) if p > 0.0 else math.nan
        cov[index] = math.sqrt(sum(variances[:level]) + own)
    return probability, cov


def _gamma(indicator: np.ndarray) -> float:
    """Au & Beck's γ of an indicator sampled along chains (chains, states a chain): 2 Σ_k (1 − k/N_s) ρ(k)."""
    chains, length = indicator.shape
    p = float(indicator.mean())
    variance = p * (1.0 - p)
    if variance == 0.0 or length == 1:
        return 0.0
    values = indicator.astype(float)
    total = 0.0
    for lag in range(1, length):
        covariance = float(np.sum(values[:, :-lag] * values[:, lag:])) / (chains * (length - lag)) - p * p
        total += (1.0 - lag / length) * covariance / variance
    return 2.0 * total


def _response_function(
    scene: Any, motion: Any, response: str, building: str | None, floor: int | None, contact: int, dimension: int | None
) -> tuple[Callable[[np.ndarray], np.ndarray], int, str]:
    """g(u), n and the response's units: the function given, or the scene's runs under the motion of u."""
    if callable(scene) and not isinstance(scene, Scene):
        if isinstance(dimension, bool) or not isinstance(dimension, (int, np.integer)) or dimension < 1:
            raise ValueError(f"dimension: must be an integer >= 1 when scene is a function of the normals, got {dimension!r}")
        return scene, int(dimension), ""
    if not isinstance(scene, Scene):
        raise ValueError(f"scene: must be a Scene or a function of the normals, got {type(scene).__name__}")
    if response not in RESPONSES:
        raise ValueError(f"response: must be one of {', '.join(RESPONSES)}, got {response!r}")
    read = _reader(scene, response, building, floor, contact)
    normals = normal_motion(motion)

    def runs(u: np.ndarray) -> np.ndarray:
        return np.array([read(simulate(replace(scene, motion=SampledMotion(normals.dt, a, "linear", "subset simulation")), demands=response == "peak_storey_drift"))
                         for a in normals(u)])

    return runs, normals.dimension, RESPONSES[response]


def _reader(scene: Scene, response: str, building: str | None, floor: int | None, contact: int) -> Callable[[xr.Dataset], float]:
    """The response read from a run's result, its building, floor or contact checked against the scene."""
    names = [b.name for b in scene.buildings]
    if response in ("closure", "impact_force"):
        if isinstance(contact, bool) or not isinstance(contact, (int, np.integer)) or not 0 <= contact < len(scene.contacts):
            raise ValueError(f"contact: must be a contact index in [0, {len(scene.contacts) - 1}], got {contact!r}" if scene.contacts else "contact: the scene has no contact")
        if response == "closure":
            return lambda run: float(run["peak_contact_closure"].values[contact])
        return lambda run: float(np.max(run["impact_peak_force"].values[run["impact_contact"].values == contact], initial=0.0))
    if building not in names:
        raise ValueError(f"building: must be one of {', '.join(names)}, got {building!r}")
    chosen = scene.buildings[names.index(building)]
    if response == "base_displacement":
        if chosen.base is None:
            raise ValueError(f"building: {building!r} has a fixed base (base_displacement needs a sliding base)")
        return lambda run: float(np.max(np.abs(run["sliding_displacement"].sel(building=building).values)))
    if isinstance(floor, bool) or not isinstance(floor, (int, np.integer)) or not 1 <= floor <= chosen.n_floors:
        raise ValueError(f"floor: must be a storey of {building!r}, 1 .. {chosen.n_floors}, got {floor!r}")
    return lambda run: float(run["peak_storey_drift"].sel(building=building, floor=floor).values)
