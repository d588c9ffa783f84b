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

The chains move by one of two proposals (``proposal``):

``"mma"``
    The component-wise modified Metropolis algorithm of Au & Beck (2001):
    each component's candidate ξ_k is uniform on u_k ± 1 and replaces u_k
    with probability min(1, φ(ξ_k)/φ(u_k)).
``"acs"``
    Adaptive conditional sampling (Papaioannou, Betz, Zwirglmaier & Straub
    2015): the whole candidate v_k ~ N(ρ_k u_k, σ_k²), ρ_k = √(1 − σ_k²),
    which leaves the standard normal invariant, with σ_k = min(1, λ) (the
    paper's σ̂_k = 1: a spread from the seeds' standard deviations makes the
    chains depend on their own seeds, which biased a first passage low). The
    level's chains run in adaptation groups of about a tenth of p0·N
    (:data:`ADAPTATION_SHARE`), in a fixed random order of the seeds; after
    group i, ln λ grows by (â_i − 0.44)/√i, â_i the group's acceptance rate,
    and the next level starts from the last λ (level 1 from 0.6). λ is
    fixed along each chain, so each chain is a Markov chain that leaves the
    conditional distribution invariant.

With either, the candidate state is accepted if its response reaches the
level's threshold, else the chain repeats its state. All chains of a group
(of the level, for ``"mma"``) advance together: the response is evaluated
on the candidates of every chain at once.

The coefficient of variation (``cov``) is read from the levels' genealogy
(``genealogy_cov``): every sample of the last level used descends from
one sample of level 0, and δ² = Σ_i s_i² − 1/N, s_i the share of the
samples above the threshold that descend from level-0 sample i (Chan & Lai
2013; Lee & Whiteley 2018; Du & Guyader 2021 for adaptive levels). It is
Au & Beck's δ exactly down to level 1 and adds the correlation between
levels that Au & Beck's leaves out. Au & Beck's (2001) δ² = Σ_j δ_j²
(``cov_au_beck``, :func:`au_beck_cov`), with δ_0² = (1 − p)/(p N) for
level 0 and δ_j² = (1 − p)/(p N_j)(1 + γ_j) for a level of chains (N_j its
samples), γ_j = 2 Σ_{k=1}^{N_s−1} (1 − k/N_s) ρ_j(k) from the correlation
ρ_j of the indicator along the chains (N_s states a chain), computed for
the probability actually estimated at that level, takes the levels'
estimates as uncorrelated; it is 20–30 % too small at 10⁻⁵–10⁻⁶ on Au &
Beck's oscillator (docs/rare-events.md).
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass, replace
from typing import Any, Callable, Mapping, Sequence

import numpy as np
import xarray as xr

from stochpound.model.scene import Scene
from stochpound.motions import normal_motion
from stochpound.motions.ground import SampledMotion
from stochpound.solvers.simulate import simulate

#: The responses of a run that :func:`subset_simulation` samples (its ``response``), with their units.
RESPONSES = {"closure": "m", "peak_storey_drift": "m", "base_displacement": "m", "impact_force": "N", "max_closure": "m"}
PROPOSALS = {
    "mma": "subset simulation (Au & Beck 2001), component-wise modified Metropolis with a uniform proposal of half-width 1",
    "acs": "subset simulation (Au & Beck 2001), adaptive conditional sampling (Papaioannou et al. 2015): conditional normal proposals, "
           "their spread adapted to an acceptance rate of 0.44",
}
"""The chains' proposals (``proposal``) and the method each names."""
UNCERTIFIED = {
    "acs": "proposal: adaptive conditional sampling is not certified on a run's peaks over time (closures, drifts, base displacements, "
           "impact forces): on Au & Beck's oscillator and a linear pair its estimates were unbiased but its reported CoV 0.73–0.86 of the "
           "empirical one at 3e-5 to 6e-7, 0.73 at the pair's deepest row (docs/rare-events.md); use proposal \"mma\" for certified intervals",
}
"""The proposals not certified on a scene's responses, with the warning :func:`warn_uncertified` gives."""
ADAPTATION_SHARE = 0.1
"""aCS: the chains of an adaptation group, as a share of p0·N (Papaioannou et al.'s p_a)."""
TARGET_ACCEPTANCE = 0.44
"""aCS: the acceptance rate the spread adapts to."""
INITIAL_SCALE = 0.6
"""aCS: λ of level 1's first group."""


@dataclass(frozen=True)
class SubsetLevel:
    """One level of a subset run: its conditioning threshold (−∞ for level 0), its responses and its chains' acceptance rate.

    Attributes
    ----------
    threshold : float
        b_j, in the response's units (−∞ for level 0, whose samples are independent).
    responses : np.ndarray
        (chains, states a chain) responses: (N, 1) for level 0.
    acceptance : float
        Fraction of the chains' candidates accepted (1 for level 0).
    seeds : np.ndarray or None
        (chains,) the previous level's sample that seeded each chain, an index into its responses read chain by chain
        (None for level 0): the levels' genealogy, which the CoV reads (:func:`exceedance`).
    """

    threshold: float
    responses: np.ndarray
    acceptance: float
    seeds: np.ndarray | None = None


@dataclass(frozen=True)
class ChainRun:
    """What :meth:`SubsetSampler.advance` returns: every state of some chains of a level.

    Attributes
    ----------
    states : np.ndarray
        (chains, states a chain, n) normals.
    responses : np.ndarray
        (chains, states a chain) responses.
    accepted : int
        Candidates accepted.
    """

    states: np.ndarray
    responses: np.ndarray
    accepted: int


@dataclass(frozen=True)
class SubsetSampler:
    """The steps of subset simulation, each chain on a generator of its own (seed, level, chain): any split of a level's
    chains into batches, run anywhere and in any order, gives the same samples.

    Parameters
    ----------
    function : callable
        g(u): (m, n) standard normals to (m,) responses (each row's response depends on that row alone).
    dimension : int
        n.
    samples_per_level : int
        N.
    p0 : float
        The conditional probability of each intermediate level.
    seed : int
        The sampler's seed (>= 0).
    proposal : {"mma", "acs"}
        The chains' proposal (:data:`PROPOSALS`).
    """

    function: Callable[[np.ndarray], np.ndarray]
    dimension: int
    samples_per_level: int
    p0: float
    seed: int
    proposal: str = "mma"

    @property
    def chains(self) -> int:
        """p0·N, the chains of a level (a few more when the level's threshold ties)."""
        return round(self.p0 * self.samples_per_level)

    @property
    def length(self) -> int:
        """States a chain (1/p0), its seed included."""
        return self.samples_per_level // self.chains

    def start(self, samples: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
        """Level 0's samples ``samples`` (indices in 0 .. N − 1), each drawn by its own generator: (m, n) normals and (m,) responses."""
        u = np.array([_generator(self.seed, 0, sample).standard_normal(self.dimension) for sample in samples]).reshape(len(samples), self.dimension)
        return u, _evaluate(self.function, u)

    def advance(self, level: int, u: np.ndarray, y: np.ndarray, threshold: float, chains: Sequence[int], spread: np.ndarray | None = None) -> ChainRun:
        """The states of chains ``chains`` (indices in the level) of level ``level`` >= 1, started at ``u`` (all in {Y ≥ threshold}).

        All chains advance together: g is called on every chain's candidate
        at once. ``spread``: aCS's σ (n,) of these chains' group (:meth:`spread`).

        Raises
        ------
        ValueError
            aCS without ``spread``.
        """
        if self.proposal == "acs" and spread is None:
            raise ValueError("spread: adaptive conditional sampling needs its group's spread (SubsetSampler.spread)")
        generators = [_generator(self.seed, level, chain) for chain in chains]
        move_one = _modified_metropolis if self.proposal == "mma" else functools.partial(_conditional_normal, spread)
        states, responses, accepted = [u], [y], 0
        for _ in range(self.length - 1):
            candidate = np.array([move_one(row, rng) for row, rng in zip(u, generators)]).reshape(u.shape)
            response = _evaluate(self.function, candidate)
            move = response >= threshold
            u = np.where(move[:, None], candidate, u)
            y = np.where(move, response, y)
            accepted += int(np.count_nonzero(move))
            states.append(u)
            responses.append(y)
        return ChainRun(np.stack(states, axis=1), np.stack(responses, axis=1), accepted)

    def seeds(self, responses: np.ndarray, level: int) -> tuple[float, np.ndarray]:
        """The next level's threshold and its chains' seeds: indices into ``responses`` (chains, states) read chain by chain.

        The threshold is the (p0·N)-th largest response; the seeds are the
        responses at or above it (a chain's repeated state tied with it
        included), the largest first; with aCS then in a random order drawn
        by the level's own generator (seed, level, N: N is no chain's
        number), so that each adaptation group holds seeds from the whole level.

        Raises
        ------
        ValueError
            Naming the response, when too many tie at the threshold (``level``: the level whose threshold it is).
        """
        y = responses.reshape(-1)
        order = np.argsort(-y, kind="stable")
        threshold = float(y[order[self.chains - 1]])
        seeds = order[y[order] >= threshold]
        if len(seeds) == len(y) or len(seeds) > 2 * self.chains:
            raise ValueError(
                f"response: ties at level {level}'s threshold ({threshold:g} is the response of {len(seeds) - self.chains + 1} of its {len(y)} samples); "
                "subset simulation needs a response that keeps varying (e.g. the closure rather than the impact force) "
                "and chains that move (a level of a chain stuck on one state ties too)"
            )
        if self.proposal == "acs":
            seeds = _generator(self.seed, level, self.samples_per_level).permutation(seeds)
        return threshold, seeds

    def groups(self, chains: int) -> list[range]:
        """A level's ``chains`` in the groups that run in turn: aCS's adaptation groups of about
        :data:`ADAPTATION_SHARE` × p0·N chains (the last takes the rest), or one group."""
        size = max(1, round(ADAPTATION_SHARE * self.chains)) if self.proposal == "acs" else max(1, chains)
        starts = list(range(0, chains, size))
        if len(starts) > 1 and chains - starts[-1] < size:
            starts.pop()
        return [range(first, end) for first, end in zip(starts, [*starts[1:], chains])]

    def spread(self, scale: float) -> np.ndarray:
        """aCS's σ_k = min(1, λ), the same for every component k (Papaioannou et al.'s σ̂_k = 1).

        Not λ σ̂_k with σ̂_k the standard deviation of the level's seeds'
        k-th component (the paper's other choice): such a spread depends on
        the chain's own seed and its siblings, so the chains no longer leave
        the conditional distribution invariant; on Au & Beck's oscillator
        (1501 normals) it biased the estimates low by a factor of about 0.4
        at 5e-7, even with the thresholds fixed beforehand (docs/rare-events.md).
        """
        return np.full(self.dimension, min(1.0, scale))

    @staticmethod
    def adapt(scale: float, acceptance: float, group: int) -> float:
        """λ after adaptation group ``group`` (0, 1, ...) of acceptance rate ``acceptance``: ln λ + (â − 0.44)/√(group + 1)."""
        return scale * math.exp((acceptance - TARGET_ACCEPTANCE) / math.sqrt(group + 1))

    def run_level(self, level: int, u: np.ndarray, y: np.ndarray, threshold: float, scale: float) -> tuple[ChainRun, float]:
        """All chains of level ``level`` >= 1 in this process, group after group, and λ after the last group (aCS)."""
        runs = []
        for group, chains in enumerate(self.groups(len(u))):
            part = slice(chains.start, chains.stop)
            spread = self.spread(scale) if self.proposal == "acs" else None
            run = self.advance(level, u[part], y[part], threshold, chains, spread)
            if spread is not None:
                scale = self.adapt(scale, run.accepted / (len(chains) * (self.length - 1)), group)
            runs.append(run)
        return ChainRun(np.concatenate([r.states for r in runs]), np.concatenate([r.responses for r in runs]), sum(r.accepted for r in runs)), scale

    def done(self, levels: Sequence[SubsetLevel], threshold: float | None, target_probability: float | None) -> bool:
        """Whether the levels reach the largest threshold (p0·N samples of the last level above it) or the target
        probability (the last level's probability times p0 at or below it)."""
        if threshold is not None:
            return np.count_nonzero(levels[-1].responses > threshold) >= self.chains
        return level_probability(levels) * self.p0 <= target_probability * (1.0 + 1e-9)


def warn_uncertified(proposal: str) -> None:
    """Warn (``UserWarning``) when ``proposal`` is not certified on a scene's responses (:data:`UNCERTIFIED`)."""
    if proposal in UNCERTIFIED:
        warnings.warn(UNCERTIFIED[proposal], stacklevel=3)


def level_probability(levels: Sequence[SubsetLevel]) -> float:
    """P(Y ≥ b_i) of the last level: the product of the steps p_j = P(Y ≥ b_{j+1} | Y ≥ b_j) estimated so far."""
    return math.prod(_steps(levels))


def subset_simulation(
    scene: Scene | Callable[[np.ndarray], np.ndarray],
    motion: Mapping[str, Any] | None = None,
    response: str = "closure",
    *,
    thresholds: Sequence[float] | None = None,
    target_probability: float | None = None,
    building: str | None = None,
    floor: int | None = None,
    contact: int = 0,
    samples_per_level: int = 1000,
    p0: float = 0.1,
    seed: int = 0,
    max_levels: int = 20,
    dimension: int | None = None,
    proposal: str = "mma",
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
    response : {"closure", "peak_storey_drift", "base_displacement", "impact_force", "max_closure"}
        The run's largest closure of contact ``contact`` (m,
        ``peak_contact_closure``), largest absolute drift of storey ``floor`` of
        ``building`` (m, ``peak_storey_drift``), largest absolute sliding
        displacement of ``building``'s base at the samples (m), largest
        force of an impact at contact ``contact`` (N, 0 without impact), or
        the largest closure of any contact (m: with one gap at every contact,
        a contact-free pair pounds at that gap exactly when it exceeds it).
    thresholds : sequence of float, optional
        Thresholds b, in the response's units; the levels go on until the
        largest is reached (without ``target_probability``). Without them, the
        curve's thresholds span its levels, from level 0's median response to the target.
    target_probability : float, optional
        The probability in (0, 1) the levels go down to instead: they stop
        when the last level's probability times p0 is at most this.
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
    proposal : {"mma", "acs"}
        The chains' proposal: Au & Beck's component-wise modified Metropolis
        (``"mma"``), or adaptive conditional sampling (``"acs"``, Papaioannou
        et al. 2015), whose spread adapts to an acceptance rate of 0.44;
        on a scene, ``"acs"`` warns that it is not certified there
        (docs/rare-events.md, "Which proposal, which p0").

    Returns
    -------
    xarray.Dataset
        Over ``threshold``: ``probability`` (of the response exceeding it),
        ``cov`` (its estimated coefficient of variation from the levels'
        genealogy, ``genealogy_cov``, NaN where the probability is 0) and
        ``cov_au_beck`` (Au & Beck's, which leaves out the correlation
        between levels and is too small far down); attrs: ``runs`` (solver runs, or evaluations of g),
        ``level_thresholds``, ``gamma`` and ``acceptance`` per level,
        ``target_reached`` (1 if the last level reached the largest
        threshold or the target probability), ``target_probability`` (if given), ``p0``, ``samples_per_level``, ``seed``,
        ``proposal`` and ``method``; with aCS, ``scale`` (λ at the end of each level after level 0).

    Raises
    ------
    ValueError
        Naming the argument that is out of range, or the response when it ties
        at a level's threshold (it does not vary in more than 1 − p0 of the
        level's samples: sample a response that keeps varying, e.g. the
        closure rather than the impact force).
    """
    values = _settings(thresholds, samples_per_level, p0, seed, max_levels, target_probability)
    if proposal not in PROPOSALS:
        raise ValueError(f"proposal: must be one of {', '.join(PROPOSALS)}, got {proposal!r}")
    function, n, units = _response_function(scene, motion, response, building, floor, contact, dimension)
    if isinstance(scene, Scene):
        warn_uncertified(proposal)
    sampler = SubsetSampler(function, n, int(samples_per_level), float(p0), int(seed), proposal)
    levels, runs, scales = _levels(sampler, float(values.max()) if target_probability is None else None, target_probability, max_levels)
    if values is None:
        values = curve_thresholds(levels, target_probability)
    probability, cov = exceedance(levels, values)
    attrs = {
        "runs": runs,
        **level_attributes(levels, sampler.chains),
        "target_reached": int(sampler.done(levels, None if target_probability is not None else float(values.max()), target_probability)),
        "p0": float(p0),
        "samples_per_level": int(samples_per_level),
        "seed": int(seed),
        "proposal": proposal,
        "method": PROPOSALS[proposal],
        "response": response if not callable(scene) else "g(u)",
    }
    if proposal == "acs":
        attrs["scale"] = np.array(scales, dtype=float)
    if target_probability is not None:
        attrs["target_probability"] = float(target_probability)
    curve = curve_dataset(values, probability, cov, units, attrs)
    curve["cov_au_beck"] = xr.Variable(("threshold",), au_beck_cov(levels, values),
                                       {"units": "1", "long_name": "Au & Beck's coefficient of variation (the levels taken as uncorrelated)"})
    return curve


def curve_dataset(thresholds: np.ndarray, probability: np.ndarray, cov: np.ndarray, units: str, attrs: Mapping[str, Any]) -> xr.Dataset:
    """An exceedance curve as :func:`subset_simulation` returns it: ``probability`` and ``cov`` over ``threshold`` (``units``)."""
    coords = {"threshold": xr.Variable(("threshold",), np.asarray(thresholds, dtype=float), {"units": units})}
    return xr.Dataset(
        {
            "probability": xr.Variable(("threshold",), probability, {"units": "1", "long_name": "probability of the response exceeding the threshold"}),
            "cov": xr.Variable(("threshold",), cov, {"units": "1", "long_name": "estimated coefficient of variation of the probability"}),
        },
        coords=coords,
        attrs=dict(attrs),
    )


def level_attributes(levels: Sequence[SubsetLevel], chains: int) -> dict[str, Any]:
    """``levels``, ``level_thresholds``, ``gamma`` and ``acceptance`` per level after level 0 (``chains``: p0·N)."""
    return {
        "levels": len(levels),
        "level_thresholds": np.array([level.threshold for level in levels[1:]], dtype=float),
        "gamma": np.array(_step_gammas(levels)[: len(levels) - 1], dtype=float),
        "acceptance": np.array([level.acceptance for level in levels[1:]], dtype=float),
    }


def _settings(thresholds: Any, samples: Any, p0: Any, seed: Any, max_levels: Any, target: Any) -> np.ndarray | None:
    """The thresholds (None: the curve's own, down to the target probability), each argument checked."""
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
    if target is not None and (isinstance(target, bool) or not isinstance(target, (int, float)) or not 0.0 < target < 1.0):
        raise ValueError(f"target_probability: must be a number in (0, 1), got {target!r}")
    if thresholds is None and target is not None:
        return None
    values = np.atleast_1d(np.asarray(thresholds, dtype=float))
    if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values)):
        raise ValueError(f"thresholds: must be one or more finite numbers (or give target_probability), got {thresholds!r}")
    return values


def _generator(seed: int, level: int, chain: int) -> np.random.Generator:
    """The generator of one chain of a level (of one sample of level 0)."""
    return np.random.default_rng([seed, level, chain])


def _levels(sampler: SubsetSampler, threshold: float | None, target: float | None, max_levels: int) -> tuple[list[SubsetLevel], int, list[float]]:
    """The levels down to ``threshold`` (or the ``target`` probability), in this process, the evaluations of g they took
    and λ at the end of each level after level 0."""
    u, y = sampler.start(range(sampler.samples_per_level))
    states, scales = u[:, None, :], [INITIAL_SCALE]
    levels, runs = [SubsetLevel(-math.inf, y[:, None], 1.0)], sampler.samples_per_level
    while not sampler.done(levels, threshold, target) and len(levels) < max_levels:
        bound, seeds = sampler.seeds(levels[-1].responses, len(levels))
        flat = states.reshape(-1, sampler.dimension)
        run, scale = sampler.run_level(len(levels), flat[seeds], levels[-1].responses.reshape(-1)[seeds], bound, scales[-1])
        runs += len(seeds) * (sampler.length - 1)
        levels.append(SubsetLevel(bound, run.responses, run.accepted / (len(seeds) * (sampler.length - 1)) if sampler.length > 1 else 1.0, seeds))
        states = run.states
        scales.append(scale)
    return levels, runs, scales[1:]


def _modified_metropolis(u: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Component-wise candidates: ξ uniform on u ± 1, each kept with probability min(1, φ(ξ)/φ(u))."""
    proposal = u + rng.uniform(-1.0, 1.0, u.shape)
    keep = rng.random(u.shape) < np.exp(0.5 * (u * u - proposal * proposal))
    return np.where(keep, proposal, u)


def _conditional_normal(spread: np.ndarray, u: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """aCS's candidate: v_k ~ N(ρ_k u_k, σ_k²), ρ_k = √(1 − σ_k²) (σ: ``spread``)."""
    return np.sqrt(1.0 - spread * spread) * u + spread * rng.standard_normal(u.shape)


def _evaluate(function: Callable[[np.ndarray], np.ndarray], u: np.ndarray) -> np.ndarray:
    y = np.asarray(function(u), dtype=float).reshape(-1)
    if y.shape != (len(u),) or not np.all(np.isfinite(y)):
        raise ValueError(f"response: must give one finite number per sample ({len(u)}), got shape {y.shape} with {np.count_nonzero(~np.isfinite(y))} not finite")
    return y


def exceedance(levels: Sequence[SubsetLevel], thresholds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """P(Y > b) and its coefficient of variation from the levels' genealogy (``genealogy_cov``) for every threshold b, from a run's levels."""
    return _probabilities(levels, np.asarray(thresholds, dtype=float)), genealogy_cov(levels, thresholds)


def genealogy_cov(levels: Sequence[SubsetLevel], thresholds: np.ndarray) -> np.ndarray:
    """The coefficient of variation of P̂(Y > b) from the levels' genealogy, the correlation between levels included.

    Every sample of the last level used for b (level m) descends from one
    sample i of level 0 (its ancestor, followed through each chain's seed),
    and P̂(Y > b) = Σ_i A_i, A_i the part of the estimate from the samples
    above b that descend from i (all samples of level m weigh the same:
    p_0 ⋯ p_{m−1} / N_m). Treating the N ancestors' families as exchangeable
    parts of the estimate, as the genealogy estimators of sequential Monte
    Carlo do (Chan & Lai 2013; Lee & Whiteley 2018; Du & Guyader 2021 for
    adaptive levels), δ² = Σ_i (A_i / P̂)² − 1/N = Σ_i s_i² − 1/N,
    s_i the share of the level-m samples above b that descend from i. At
    level 0 it is (1 − p)/(pN), at level 1 exactly Au & Beck's δ
    (:func:`au_beck_cov`) with γ from the chains; further down it adds the
    correlation between the levels that Au & Beck's δ leaves out (a level's
    chains start from the previous level's samples). NaN where P̂ = 0.

    Parameters
    ----------
    levels : sequence of SubsetLevel
        A run's levels, each after level 0 with its chains' ``seeds``.
    thresholds : np.ndarray
        Thresholds b, in the response's units.

    Returns
    -------
    np.ndarray
        δ at each threshold.

    Raises
    ------
    ValueError
        Naming ``seeds``, when a level after level 0 does not name its chains' seeds.
    """
    bounds = np.array([level.threshold for level in levels[1:]])
    ancestors = _ancestors(levels)
    cov = np.empty(len(thresholds))
    for index, b in enumerate(np.asarray(thresholds, dtype=float)):
        level = int(np.searchsorted(bounds, b, side="right"))
        above = ancestors[level][levels[level].responses > b]
        shares = np.bincount(above, minlength=levels[0].responses.size) / above.size if above.size else None
        cov[index] = math.sqrt(max(0.0, float(np.sum(shares * shares)) - 1.0 / levels[0].responses.size)) if shares is not None else math.nan
    return cov


def au_beck_cov(levels: Sequence[SubsetLevel], thresholds: np.ndarray) -> np.ndarray:
    """Au & Beck's (2001) coefficient of variation of P̂(Y > b), the levels taken as uncorrelated: δ² = Σ_j δ_j², δ_j² = (1 − p_j)/(p_j N_j)(1 + γ_j)."""
    bounds = np.array([level.threshold for level in levels[1:]])
    steps = _steps(levels)
    variances = [(1.0 - p) / (p * level.responses.size) * (1.0 + g) for p, level, g in zip(steps, levels, _step_gammas(levels))]
    cov = np.empty(len(thresholds))
    for index, b in enumerate(np.asarray(thresholds, dtype=float)):
        level = int(np.searchsorted(bounds, b, side="right"))  # the levels conditioned on thresholds <= b
        indicator = levels[level].responses > b
        p = float(indicator.mean())
        own = (1.0 - p) / (p * indicator.size) * (1.0 + (_gamma(indicator) if level else 0.0)) if p > 0.0 else math.nan
        cov[index] = math.sqrt(sum(variances[:level]) + own)
    return cov


def _ancestors(levels: Sequence[SubsetLevel]) -> list[np.ndarray]:
    """For each level, the level-0 sample (0 .. N − 1) each of its samples descends from, shaped as its responses.

    Raises
    ------
    ValueError
        When a level after level 0 does not name its chains' seeds.
    """
    ancestors = [np.arange(levels[0].responses.size).reshape(levels[0].responses.shape)]
    for index, level in enumerate(levels[1:], start=1):
        if level.seeds is None or len(level.seeds) != level.responses.shape[0]:
            raise ValueError(f"seeds: level {index} must name the previous level's sample that seeded each of its {level.responses.shape[0]} chains")
        ancestors.append(np.broadcast_to(ancestors[-1].reshape(-1)[np.asarray(level.seeds)][:, None], level.responses.shape))
    return ancestors


def curve_thresholds(levels: Sequence[SubsetLevel], target: float | None, points: int = 25) -> np.ndarray:
    """Thresholds that draw a run's exceedance curve: ``points`` a level, from level 0's median response to the
    response at the ``target`` probability (or the last level's (p0·N)-th largest), evenly between each level's bounds."""
    bounds = [float(np.median(levels[0].responses))] + [level.threshold for level in levels[1:]]
    last = np.sort(levels[-1].responses.reshape(-1))[::-1]
    reach = level_probability(levels)
    share = (target / reach) if target is not None else levels[1].responses.shape[0] / levels[0].responses.size if len(levels) > 1 else 0.5
    bounds.append(float(last[min(len(last) - 1, round(share * len(last)))]))  # P̂(Y > it) = reach · share
    pieces = [np.linspace(low, high, points, endpoint=False) for low, high in zip(bounds, bounds[1:]) if high > low]
    return np.unique(np.concatenate([*pieces, [bounds[-1]]]))


def exceedance_quantiles(levels: Sequence[SubsetLevel], probabilities: Sequence[float], z: float = 1.96) -> dict[str, np.ndarray]:
    """The response exceeded with each probability p, and an interval of it, from a run's levels.

    The value b_p is the smallest of the run's responses with P̂(Y > b_p) ≤ p
    (for a closure, the separation for probability p of pounding); its
    interval the values at p·exp(±z δ), δ the estimate's coefficient of
    variation at b_p (a lognormal estimate's 95 % interval for z = 1.96),
    read off the same curve. A probability below the run's reach (the last
    level's probability times p0) gives NaN.

    Parameters
    ----------
    levels : sequence of SubsetLevel
        A run's levels.
    probabilities : sequence of float
        The probabilities p.
    z : float
        The standard normal quantile of the interval.

    Returns
    -------
    dict of np.ndarray
        ``value``, ``low``, ``high`` (the response's units) and ``cov`` (δ) for each p.
    """
    candidates = np.unique(np.concatenate([level.responses.reshape(-1) for level in levels]))
    curve = _probabilities(levels, candidates)
    reach = level_probability(levels) * levels[-1].responses.shape[0] / levels[-1].responses.size * (1.0 - 1e-9)

    def at(p: float) -> float:
        below = np.flatnonzero(curve <= p)
        return float(candidates[below[0]]) if p >= reach and below.size else math.nan

    result: dict[str, list[float]] = {"value": [], "low": [], "high": [], "cov": []}
    for p in probabilities:
        value = at(p)
        delta = float(exceedance(levels, np.array([value]))[1][0]) if np.isfinite(value) else math.nan
        result["value"].append(value)
        result["cov"].append(delta)
        result["low"].append(at(p * math.exp(z * delta)) if np.isfinite(delta) else math.nan)
        result["high"].append(at(p * math.exp(-z * delta)) if np.isfinite(delta) else math.nan)
    return {key: np.array(values, dtype=float) for key, values in result.items()}


def _probabilities(levels: Sequence[SubsetLevel], thresholds: np.ndarray) -> np.ndarray:
    """P̂(Y > b) at thresholds b (without its CoV: many thresholds at once)."""
    bounds = np.array([level.threshold for level in levels[1:]])
    scale = np.cumprod([1.0, *_steps(levels)])
    which = np.searchsorted(bounds, thresholds, side="right")
    probability = np.empty(len(thresholds))
    for index, level in enumerate(levels):
        chosen = which == index
        ordered = np.sort(level.responses.reshape(-1))
        above = ordered.size - np.searchsorted(ordered, thresholds[chosen], side="right")
        probability[chosen] = scale[index] * above / ordered.size
    return probability


def _steps(levels: Sequence[SubsetLevel]) -> list[float]:
    """p_j = P(Y ≥ b_{j+1} | Y ≥ b_j), each level's fraction of samples that seeded the next."""
    return [nxt.responses.shape[0] / level.responses.size for level, nxt in zip(levels, levels[1:])]


def _step_gammas(levels: Sequence[SubsetLevel]) -> list[float]:
    """γ_j of each level's step to the next (γ_0 = 0: level 0's samples are independent)."""
    return [0.0] + [_gamma(level.responses >= nxt.threshold) for level, nxt in zip(levels[1:-1], levels[2:])]


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
    return scene_response(scene, motion, response, building, floor, contact)


def scene_response(
    scene: Scene, motion: Mapping[str, Any], response: str, building: str | None = None, floor: int | None = None, contact: int = 0
) -> tuple[Callable[[np.ndarray], np.ndarray], int, str]:
    """g(u), n and the response's units: a scene's runs under the synthetic motion of the normals u.

    Parameters are :func:`subset_simulation`'s; each row of u is one run, its
    response independent of the other rows.

    Raises
    ------
    ValueError
        Naming the response, building, floor, contact or motion field that is out of range.
    """
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
    if response == "max_closure":
        if not scene.contacts:
            raise ValueError("response: 'max_closure' needs a contact, and the scene has none")
        return lambda run: float(np.max(run["peak_contact_closure"].values))
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
