"""Hazard-compatible calibration of the site-motion model, and its check against the NGA-West2 models.

The check (:func:`calibration_table`): simulate n motions of each scenario,
take ln Sa (PGA, and 5 %-damped PSA) of each, and compare their mean (the ln
of the median) and standard deviation with the NGA-West2 average of the
conditional spectrum (``_conditional._average_model``: mean of the four models'
ln medians, σ the rms of their σ); the correlation of ε at pairs of periods
(ε: ln Sa standardised within its scenario, pooled over the scenarios) with
Baker & Jayaram (2008).

The calibration (:func:`fit_calibration`) adds to the published equations, in
the standard normal space, ν_i += d_i · x(scenario) for the Arias intensity
(x: 1, M − 7, ln(R/25), ln(Vs30/750), reverse, normal, (M − 7)², (M − 7) ln(R/25)), the filter frequency
f_mid (1, M − 7, ln(R/25), ln(Vs30/750)) and the damping ζ_f (1); scales
the residuals of the Arias intensity and of f_mid; and makes the corner f_c lognormal about
c0 + c1 (M − 7). Those coefficients minimise, over a grid of scenarios and
the periods, the squared misfit of the simulated mean and σ of ln Sa to the
models' and of the ε correlations at the checked pairs to Baker & Jayaram's,
plus a ridge penalty on the adjustments (staying near the
published trends). The simulated statistics of a candidate come from one
pool of motions per scenario with common random numbers: the pool's other
parameters are drawn once from a proposal wider than the published model,
and a candidate reweights them (importance sampling: the ratio of the
candidate's density of ν_2…ν_6 and ln f_c to the proposal's); the Arias
intensity only scales a motion (Sa ∝ √I_a), so each pool motion's I_a under
the candidate follows exactly from its conditional residual, with no
re-simulation.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from stochpound.motions._arias import DEFAULT_G
from stochpound.motions._conditional import MODEL_DAMPING, _average_model, _node_correlation
from stochpound.motions._scenario import Scenario
from stochpound.motions._seeding import realization_rng
from stochpound.motions._site_model import (
    FEATURES, PARAMETERS, ZETA_MAX, SiteModel, load_site_model, mean_normals, motion_parameters, motions_from_parameters,
)  # fmt: skip
from stochpound.motions._spectrum import _spectrum_kernel

#: Periods of the check (s); None is PGA.
CHECK_PERIODS: tuple[float | None, ...] = (None, 0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0)
#: The pairs of periods (s) whose ε correlation is checked against Baker & Jayaram (2008).
CORRELATION_PAIRS = ((0.1, 1.0), (0.5, 2.0), (1.0, 2.0), (1.0, 3.0), (2.0, 4.0))
#: Scenarios of the calibration and of its check: magnitude, rupture distance (km), Vs30 (m/s), mechanism.
SCENARIOS: tuple[tuple[float, float, float, str], ...] = (
    (5.5, 5.0, 760.0, "strike_slip"), (5.5, 20.0, 300.0, "normal"), (6.0, 10.0, 1100.0, "reverse"),
    (6.0, 50.0, 400.0, "strike_slip"), (6.5, 20.0, 400.0, "strike_slip"), (6.5, 10.0, 200.0, "reverse"),
    (6.5, 100.0, 760.0, "normal"), (7.0, 10.0, 760.0, "strike_slip"), (7.0, 40.0, 250.0, "reverse"),
    (7.5, 40.0, 300.0, "strike_slip"), (7.5, 5.0, 560.0, "reverse"), (7.5, 100.0, 1100.0, "normal"),
    (8.0, 20.0, 400.0, "strike_slip"), (8.0, 70.0, 200.0, "reverse"),
)  # fmt: skip
#: Features of each adjusted equation (a prefix of the calibration's FEATURES).
ADJUSTED = {"arias_intensity": len(FEATURES), "f_mid": 4, "zeta_f": 1}
#: Weight of the ε correlations' misfit beside the ln Sa moments'.
CORRELATION_WEIGHT = 1.0
#: Parameters whose residual's standard deviation the calibration scales.
SCALED = ("arias_intensity", "f_mid")
#: Ridge weight of the adjustments (per coefficient, in the misfit's units of ln Sa²).
RIDGE = 0.02
#: The proposal's widening of the published residuals, and its corner's ln-distribution (ln Hz).
PROPOSAL_WIDTH, PROPOSAL_CORNER = 1.4, (math.log(0.15), 0.8)
#: Motions simulated at a time where only their spectra are kept (memory: 8 n_time bytes a motion).
SPECTRA_BATCH = 256


def ln_spectra(acceleration: np.ndarray, dt: float, periods: Sequence[float | None] = CHECK_PERIODS) -> np.ndarray:
    """ln Sa in g [n, len(periods)] of every motion (rows of ``acceleration``, m/s²): PGA for None, else 5 %-damped PSA."""
    psa = [p for p in periods if p is not None]
    omega = 2.0 * np.pi / np.array(psa)
    out = np.empty((acceleration.shape[0], len(periods)))
    sd, sa = np.empty_like(omega), np.empty_like(omega)
    columns = [i for i, p in enumerate(periods) if p is not None]
    for m, a in enumerate(np.ascontiguousarray(acceleration)):
        _spectrum_kernel(a, float(dt), omega, MODEL_DAMPING, sd, sa)
        out[m, columns] = omega**2 * sd
        for i, p in enumerate(periods):
            if p is None:
                out[m, i] = np.max(np.abs(a))
    return np.log(out / DEFAULT_G)


def target(scenario: tuple[float, float, float, str], periods: Sequence[float | None] = CHECK_PERIODS) -> tuple[np.ndarray, np.ndarray]:
    """The NGA-West2 average's mean of ln Sa (g) and σ at ``periods`` for a scenario."""
    return _average_model(list(periods), Scenario(*scenario))


def _draw(model: SiteModel, scenario: tuple, n: int, seed: int, dt: float, duration: float) -> np.ndarray:
    """ln Sa [n, periods] of n motions of the model for a scenario (realizations 0..n−1 of ``seed``)."""
    n_time = int(round(duration / dt)) + 1
    rngs = [realization_rng(seed, i) for i in range(n)]
    parameters = motion_parameters(model, Scenario(*scenario), np.array([rng.standard_normal(7) for rng in rngs]))
    return _spectra_in_batches(parameters, lambda rows: np.array([rng.standard_normal(n_time) for rng in rngs[rows]]), dt)


def _spectra_in_batches(parameters: dict[str, np.ndarray], noise_rows: Callable[[slice], np.ndarray], dt: float) -> np.ndarray:
    """ln Sa [n, periods] of the motions of ``parameters``, SPECTRA_BATCH at a time (``noise_rows(rows)``: their noise, called in order)."""
    n = parameters["t_mid"].size
    spectra = []
    for start in range(0, n, SPECTRA_BATCH):
        rows = slice(start, min(start + SPECTRA_BATCH, n))
        chosen = {name: values[rows] for name, values in parameters.items()}
        spectra.append(ln_spectra(motions_from_parameters(chosen, noise_rows(rows), dt), dt))
    return np.concatenate(spectra)


def scenario_duration(scenario: tuple) -> float:
    """The window (s) of a scenario's check: long enough for its long-duration draws (grows with M and R)."""
    magnitude, distance = scenario[0], scenario[1]
    return float(min(120.0, 40.0 + 20.0 * max(magnitude - 6.5, 0.0) + 0.25 * distance))


@dataclass(frozen=True)
class CheckTable:
    """The check's numbers: per scenario and period the ln ratio of medians and σ difference; the ε correlations."""

    periods: tuple
    scenarios: tuple
    ln_median_ratio: np.ndarray  # [scenario, period]
    sigma_difference: np.ndarray  # [scenario, period]
    correlation: dict[tuple[float, float], tuple[float, float]]  # pair of periods (s) -> (simulated, Baker-Jayaram)
    n: int


def calibration_table(model_name: str = "hazard_compatible", scenarios: Sequence[tuple] = SCENARIOS, n: int = 2000, seed: int = 2026,
                      dt: float = 0.01) -> CheckTable:
    """Simulate ``n`` motions of every scenario with the model and compare with the NGA-West2 models (module docstring)."""
    model = load_site_model(model_name)
    ratios, differences, epsilons = [], [], []
    for scenario in scenarios:
        ln_sa = _draw(model, scenario, n, seed, dt, scenario_duration(scenario))
        mean, sigma = target(scenario)
        ratios.append(ln_sa.mean(axis=0) - mean)
        differences.append(ln_sa.std(axis=0, ddof=1) - sigma)
        epsilons.append((ln_sa - ln_sa.mean(axis=0)) / ln_sa.std(axis=0, ddof=1))
    pooled = np.concatenate(epsilons)
    correlation = {}
    for pair in CORRELATION_PAIRS:
        i, j = (CHECK_PERIODS.index(p) for p in pair)
        bj = _node_correlation(list(pair))[0, 1]
        correlation[pair] = (float(np.corrcoef(pooled[:, i], pooled[:, j])[0, 1]), float(bj))
    return CheckTable(CHECK_PERIODS, tuple(scenarios), np.array(ratios), np.array(differences), correlation, n)


@dataclass
class _Pool:
    """One scenario's pool: ν_2…ν_6 and ln f_c drawn from the proposal, their log proposal density,
    each motion's conditional Arias residual, and ln Sa at I_a = 1 m/s."""

    scenario: tuple
    nu: np.ndarray
    ln_corner: np.ndarray
    log_proposal: np.ndarray
    z_arias: np.ndarray
    ln_sa_unit: np.ndarray
    mean: np.ndarray
    sigma: np.ndarray


def _pool(scenario: tuple, n: int, seed: int, dt: float) -> _Pool:
    from scipy import stats
    published = load_site_model("rezaeian_2010")
    centre = mean_normals(published, Scenario(*scenario))[1:]
    factor = PROPOSAL_WIDTH * published.cholesky[1:, 1:]
    rng = np.random.default_rng([seed, int(scenario[0] * 10), int(scenario[1]), int(scenario[2])])
    z = rng.standard_normal((n, 5))
    nu = centre + z @ factor.T
    ln_corner = PROPOSAL_CORNER[0] + PROPOSAL_CORNER[1] * rng.standard_normal(n)
    covariance = factor @ factor.T
    log_proposal = stats.multivariate_normal(centre, covariance).logpdf(nu) + stats.norm(*PROPOSAL_CORNER).logpdf(ln_corner)
    p = np.clip(stats.norm.cdf(nu), 1e-12, 1.0 - 1e-12)
    parameters = {"arias_intensity": np.ones(n)}
    for i, name in enumerate(PARAMETERS[1:]):
        parameters[name] = published.marginals[i + 1].ppf(p[:, i])
    parameters["zeta_f"] = np.minimum(parameters["zeta_f"], ZETA_MAX)
    parameters["f_corner"] = np.exp(ln_corner)
    n_time = int(round(scenario_duration(scenario) / dt)) + 1
    ln_sa_unit = _spectra_in_batches(parameters, lambda rows: rng.standard_normal((rows.stop - rows.start, n_time)), dt)
    mean, sigma = target(scenario)
    return _Pool(scenario, nu, ln_corner, log_proposal, rng.standard_normal(n), ln_sa_unit, mean, sigma)


def _unpack(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Adjustments [6, FEATURES], the residual scales of SCALED and the corner (c0, c1, σ) from the fitted vector."""
    adjustments = np.zeros((len(PARAMETERS), len(FEATURES)))
    at = 0
    for name, count in ADJUSTED.items():
        adjustments[PARAMETERS.index(name), :count] = x[at:at + count]
        at += count
    scales = np.exp(x[at:at + len(SCALED)])
    at += len(SCALED)
    return adjustments, scales, np.array([x[at], x[at + 1], np.exp(x[at + 2])])


def _pool_statistics(pool: _Pool, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Weighted mean and σ of ln Sa of a pool under the candidate ``x``, the correlations at CORRELATION_PAIRS, the effective sample size."""
    from scipy import stats

    published = load_site_model("rezaeian_2010")
    adjustments, scales, corner = _unpack(x)
    model = SiteModel("candidate", published.coefficients, published.cholesky, published.marginals, adjustments, corner, "")
    mu = mean_normals(model, Scenario(*pool.scenario))
    factor = np.ones(len(PARAMETERS))
    factor[[PARAMETERS.index(name) for name in SCALED]] = scales
    covariance = published.cholesky @ published.cholesky.T * np.outer(factor, factor)
    rest = covariance[1:, 1:]
    log_target = stats.multivariate_normal(mu[1:], rest).logpdf(pool.nu)
    log_target += stats.norm(corner[0] + corner[1] * (pool.scenario[0] - 7.0), corner[2]).logpdf(pool.ln_corner)
    weights = np.exp(log_target - pool.log_proposal - np.max(log_target - pool.log_proposal))
    weights /= weights.sum()
    gain = np.linalg.solve(rest, covariance[1:, 0])
    conditional_mean = mu[0] + (pool.nu - mu[1:]) @ gain
    conditional_sd = math.sqrt(covariance[0, 0] - covariance[1:, 0] @ gain)
    nu_arias = conditional_mean + conditional_sd * pool.z_arias
    marginal = published.marginals[0]
    ln_arias = marginal.mu + marginal.sigma * nu_arias + math.log(DEFAULT_G)  # ln I_a in m/s
    ln_sa = pool.ln_sa_unit + 0.5 * ln_arias[:, None]
    mean = weights @ ln_sa
    deviation = ln_sa - mean
    sigma = np.sqrt(weights @ deviation**2)
    pairs = [(CHECK_PERIODS.index(a), CHECK_PERIODS.index(b)) for a, b in CORRELATION_PAIRS]
    correlation = np.array([weights @ (deviation[:, i] * deviation[:, j]) / (sigma[i] * sigma[j]) for i, j in pairs])
    return mean, sigma, correlation, float(1.0 / np.sum(weights**2))


def _residuals(x: np.ndarray, pools: Sequence[_Pool]) -> np.ndarray:
    bj = np.array([_node_correlation(list(pair))[0, 1] for pair in CORRELATION_PAIRS])
    parts = []
    for pool in pools:
        mean, sigma, correlation, _ = _pool_statistics(pool, x)
        parts.extend([mean - pool.mean, sigma - pool.sigma, CORRELATION_WEIGHT * (correlation - bj)])
    parts.append(math.sqrt(RIDGE) * x[: sum(ADJUSTED.values())])
    return np.concatenate(parts)


def start_vector() -> np.ndarray:
    """The published model in the fitted vector's terms: no adjustment, scales 1, f_c = 0.2 Hz with a small spread."""
    count = sum(ADJUSTED.values())
    return np.concatenate([np.zeros(count), np.zeros(len(SCALED)), [math.log(0.2), 0.0, math.log(0.3)]])


def calibration_pools(n: int = 1000, seed: int = 7, dt: float = 0.01, scenarios: Sequence[tuple] = SCENARIOS) -> list[_Pool]:
    """The pools of ``n`` motions per scenario the calibration reweights (module docstring)."""
    return [_pool(scenario, n, seed, dt) for scenario in scenarios]


def fit_pools(pools: Sequence[_Pool]) -> dict:
    """Fit the calibration (module docstring) on ``pools``; the coefficients and diagnostics."""
    from scipy import optimize

    result = optimize.least_squares(_residuals, start_vector(), args=(pools,), method="trf", x_scale=1.0, diff_step=1e-4)
    adjustments, scales, corner = _unpack(result.x)
    sizes = [_pool_statistics(pool, result.x)[3] for pool in pools]
    return {"adjustments": {name: adjustments[PARAMETERS.index(name), :count].tolist() for name, count in ADJUSTED.items()},
            "residual_scale": dict(zip(SCALED, scales.tolist())), "corner": {"ln_hz": corner[:2].tolist(), "sigma_ln": float(corner[2])},
            "cost": float(result.cost), "effective_sizes": sizes, "n": pools[0].nu.shape[0], "scenarios": [list(p.scenario) for p in pools]}


def fit_calibration(n: int = 1000, seed: int = 7, dt: float = 0.01, scenarios: Sequence[tuple] = SCENARIOS) -> dict:
    """Fit the calibration on fresh pools (:func:`calibration_pools`, :func:`fit_pools`)."""
    return {**fit_pools(calibration_pools(n, seed, dt, scenarios)), "seed": seed}
