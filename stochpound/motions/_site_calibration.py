"""Hazard-compatible calibration of the site-motion model, and its check against the NGA-West2 models.

The check (:func:`calibration_table`): simulate n motions of each scenario,
take ln Sa (PGA, and 5 %-damped PSA) of each, and compare their mean (the ln
of the median) and standard deviation with the NGA-West2 average of the
conditional spectrum (``_conditional._average_model``: mean of the four models'
ln medians, σ the rms of their σ); the correlation of ε at pairs of periods
(ε: ln Sa standardised within its scenario, pooled over the scenarios) with
Baker & Jayaram (2008).

The calibration (:func:`fit_calibration`) keeps the published equations
(their residuals narrowed to :data:`RESIDUAL_SCALE` of their published
spread, f_c = 0.2 Hz) and adds a spectral-shape layer: each motion passes
through a minimum-phase filter whose ln gain at the periods T_j of
``SHAPE_PERIODS`` (0.05–5 s; linear in ln T between them, held beyond) is
μ_j − r_j + d_j (L z)_j, with μ_j, σ_j the NGA-West2 average of the scenario
(its geometry included), r_j and v_j the mean and variance of ln Sa the base
gives there (regressions on the scenario's features), d_j = √max(σ_j² − v_j, 0),
L the lower factor of the gains' correlation and z the motion's 12 shape
normals. Fit: for every scenario of :data:`FIT_SCENARIOS`, n motions with
common random numbers; at each of :data:`ITERATIONS` fixed-point iterations
their ln Sa moves every scenario's gain by the miss of the median
(μ_j − simulated mean; the first node's, 0.05 s, by the mean of its own
miss and PGA's, so that PGA, which the short-period band makes together,
is a target too) and its spread by the miss of the variance
(d_j² += σ_j² − simulated variance), and the correlation becomes the
covariance the layer must add (Baker–Jayaram's times σ σ, minus the
simulated one without the layer's), summed over the scenarios and divided
by the summed d_i d_j, made positive definite. Then r_j = μ_j − gain_j and
v_j = σ_j² − d_j² are regressed (ridge :data:`RIDGE`) on the features, so
that any scenario in the range has its layer, and :data:`REGRESSED_ITERATIONS`
more iterations simulate every scenario through the regressions' layer and
move each scenario's gain and d² by that layer's misses before the
regressions are fitted again: what the regressions leave at the corners of
the range (d_j ≥ σ_j at 3 s for M 8 in ``nga_west2_calibration_3``, whose fit
stopped at the scenarios' own layers) is corrected where the features can
follow it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

from stochpound.motions._arias import DEFAULT_G
from stochpound.motions._conditional import MODEL_DAMPING, _average_model, _node_correlation
from stochpound.motions._scenario import Scenario
from stochpound.motions._seeding import realization_rng
from stochpound.motions._site_model import (
    PARAMETER_NORMALS, PARAMETERS, SHAPE_PERIODS, SiteModel, layer_gains, load_site_model, motion_parameters, motions_from_parameters,
    shape_features,
)  # fmt: skip
from stochpound.motions._spectrum import _spectrum_kernel

#: Periods of the check (s); None is PGA.
CHECK_PERIODS: tuple[float | None, ...] = (None, 0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0)
#: The pairs of periods (s) whose ε correlation is checked against Baker & Jayaram (2008): the issue's five, then two
#: short-period pairs (PGA's σ is right only if the short periods vary together as the models' do).
CORRELATION_PAIRS = ((0.1, 1.0), (0.5, 2.0), (1.0, 2.0), (1.0, 3.0), (2.0, 4.0), (0.1, 0.3), (0.2, 0.5))
#: Scenarios of the calibration and of its check: magnitude, rupture distance (km), Vs30 (m/s), mechanism.
SCENARIOS: tuple[tuple[float, float, float, str], ...] = (
    (5.5, 5.0, 760.0, "strike_slip"), (5.5, 20.0, 300.0, "normal"), (6.0, 10.0, 1100.0, "reverse"),
    (6.0, 50.0, 400.0, "strike_slip"), (6.5, 20.0, 400.0, "strike_slip"), (6.5, 10.0, 200.0, "reverse"),
    (6.5, 100.0, 760.0, "normal"), (7.0, 10.0, 760.0, "strike_slip"), (7.0, 40.0, 250.0, "reverse"),
    (7.5, 40.0, 300.0, "strike_slip"), (7.5, 5.0, 560.0, "reverse"), (7.5, 100.0, 1100.0, "normal"),
    (8.0, 20.0, 400.0, "strike_slip"), (8.0, 70.0, 200.0, "reverse"),
)  # fmt: skip
#: Scenarios of the fit: the check's 14 and 20 more spread over the range (a Latin hypercube of M, ln R, ln Vs30, seed 43,
#: rounded; none is a held-out scenario of ``python -m benchmarks site_motions check --held-out``).
FIT_SCENARIOS: tuple[tuple[float, float, float, str], ...] = SCENARIOS + (
    (7.7, 59.0, 760.0, "strike_slip"), (7.15, 21.0, 420.0, "reverse"), (6.4, 8.0, 220.0, "normal"), (6.6, 14.0, 300.0, "strike_slip"),
    (5.85, 54.0, 800.0, "reverse"), (6.8, 10.0, 350.0, "normal"), (7.05, 44.0, 370.0, "strike_slip"), (8.0, 29.0, 680.0, "reverse"),
    (6.3, 39.0, 1100.0, "normal"), (7.85, 19.0, 250.0, "strike_slip"), (7.35, 90.0, 570.0, "reverse"), (7.5, 6.0, 910.0, "normal"),
    (6.65, 30.0, 280.0, "strike_slip"), (5.7, 13.0, 210.0, "reverse"), (6.9, 24.0, 660.0, "normal"), (6.15, 12.0, 510.0, "strike_slip"),
    (6.05, 73.0, 950.0, "reverse"), (7.45, 6.0, 460.0, "normal"), (5.5, 7.0, 520.0, "strike_slip"), (5.95, 75.0, 310.0, "reverse"),
)  # fmt: skip
#: The base model's residuals, as fractions of the published ones (by parameter): the Arias intensity scales every period
#: alike, and at its published spread that common factor alone exceeds the NGA-West2 covariance of distant periods; the
#: filter's frequency, its drift and its damping move the spectrum's shape as the NGA-West2 correlation does not (a shift
#: of the predominant period raises the short periods and lowers the long ones, and leaves neighbouring short periods
#: nearly independent). Narrowed, they leave most of the σ of ln Sa to the shape layer, whose correlation the fit sets;
#: the durations (D5–95, t_mid) keep their published spread (docs/site-motions.md).
RESIDUAL_SCALE: dict[str, float] = {"arias_intensity": 0.5, "d5_95": 1.0, "t_mid": 1.0, "f_mid": 0.4, "f_slope": 0.4, "zeta_f": 0.4}
#: Fixed-point iterations of the fit on every scenario's own layer (each simulates every scenario's motions once).
ITERATIONS = 6
#: Fixed-point iterations after them on the regressions' layer (each simulates every scenario's motions once).
REGRESSED_ITERATIONS = 2
#: The name a calibration fitted by :func:`fit_calibration` carries (stores name the calibration their motions came from).
CALIBRATION_NAME = "nga_west2_calibration_5"
#: Periods the fit simulates (s; None: PGA, which moves the first node's gain with PSA(0.05 s)'s: :func:`fit_calibration`).
FIT_PERIODS: tuple[float | None, ...] = (None, *SHAPE_PERIODS)
#: Ridge weight of the shape layer's regressions (per coefficient, the intercept free).
RIDGE = 1e-3
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
    parameters = motion_parameters(model, Scenario(*scenario), np.array([rng.standard_normal(model.normals) for rng in rngs]))
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


def base_model() -> SiteModel:
    """The base of the calibration: the published equations, their residuals narrowed by :data:`RESIDUAL_SCALE`."""
    published = load_site_model("rezaeian_2010")
    narrowed = published.cholesky * np.array([RESIDUAL_SCALE[p] for p in PARAMETERS])[:, None]  # D L: the factor of D S D
    return SiteModel("base", published.coefficients, narrowed, published.marginals, published.adjustments, published.corner, "")


def _shape_draw(base: SiteModel, scenario: tuple, gains: np.ndarray, spreads: np.ndarray, cholesky: np.ndarray, n: int, seed: int,
                dt: float) -> np.ndarray:
    """ln Sa [n, CHECK_PERIODS] of n motions of the base model through shape gains ``gains`` + ``spreads`` (L z) (realizations of ``seed``)."""
    n_time = int(round(scenario_duration(scenario) / dt)) + 1
    rngs = [realization_rng(seed, i) for i in range(n)]
    first = np.array([rng.standard_normal(PARAMETER_NORMALS + len(SHAPE_PERIODS)) for rng in rngs])
    parameters = motion_parameters(base, Scenario(*scenario), first[:, :PARAMETER_NORMALS])
    parameters["spectral_shape"] = gains + spreads * (first[:, PARAMETER_NORMALS:] @ cholesky.T)
    return _spectra_in_batches(parameters, lambda rows: np.array([rng.standard_normal(n_time) for rng in rngs[rows]]), dt)


def nearest_correlation(matrix: np.ndarray) -> np.ndarray:
    """A correlation matrix near a symmetric ``matrix``: its eigenvalues raised to at least 0.01, rescaled to a unit diagonal."""
    values, vectors = np.linalg.eigh(0.5 * (matrix + matrix.T))
    fixed = vectors @ np.diag(np.maximum(values, 0.01)) @ vectors.T
    scale = np.sqrt(np.diag(fixed))
    return fixed / np.outer(scale, scale)


def _ridge(features: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Coefficients [values' columns, features] of the ridge regression (weight :data:`RIDGE`, the intercept free) of ``values`` on ``features``."""
    penalty = RIDGE * np.eye(features.shape[1])
    penalty[0, 0] = 0.0
    return np.linalg.solve(features.T @ features + penalty, features.T @ values).T


def _draw_all(base: SiteModel, scenarios: Sequence[tuple], gains: np.ndarray, spreads: np.ndarray, cholesky: np.ndarray, n: int,
              seed: int, dt: float, workers: int) -> list[np.ndarray]:
    """ln Sa [n, FIT_PERIODS] of every scenario's motions through its layer (scenario i: realizations of seed + 1000 i), on ``workers`` processes."""
    fit_columns = [CHECK_PERIODS.index(p) for p in FIT_PERIODS]
    jobs = [(base, s, gains[i], spreads[i], cholesky, n, seed + 1000 * i, dt) for i, s in enumerate(scenarios)]
    if workers <= 1:
        return [_shape_draw(*job)[:, fit_columns] for job in jobs]
    with ProcessPoolExecutor(workers) as pool:
        return [ln_sa[:, fit_columns] for ln_sa in pool.map(_shape_draw, *zip(*jobs))]


def _regressed_layer(x: np.ndarray, targets: list, gains: np.ndarray, variances: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The regressions of r = μ − gain and v = σ² − d² (:func:`_ridge`), and the mean gains and spreads they give at the scenarios."""
    mean, sigma = (np.array([t[k] for t in targets]) for k in (0, 1))
    r_coefficients, v_coefficients = _ridge(x, mean - gains), _ridge(x, sigma**2 - variances)
    return r_coefficients, v_coefficients, *layer_gains(mean, sigma, r_coefficients, v_coefficients, x)


def fit_calibration(n: int = 400, seed: int = 7, dt: float = 0.01, scenarios: Sequence[tuple] = FIT_SCENARIOS,
                    iterations: int = ITERATIONS, regressed_iterations: int = REGRESSED_ITERATIONS, workers: int = 1) -> dict:
    """Fit the spectral-shape layer (module docstring) on ``n`` motions of every scenario; its coefficients and diagnostics.

    The first ``iterations`` move every scenario's own layer; the ``regressed_iterations`` after them simulate every
    scenario through the regressions' layer and move the data the regressions are fitted to by that layer's misses, so
    that the misses left are the regressions' own, not only the scenarios'. ``workers`` processes share the scenarios
    (the numbers do not depend on how many).
    """
    base, k = base_model(), len(SHAPE_PERIODS)
    fit_targets = [target(s, FIT_PERIODS) for s in scenarios]  # PGA first, then the nodes
    targets = [(mean[1:], sigma[1:]) for mean, sigma in fit_targets]
    pga_targets = [float(mean[0]) for mean, _ in fit_targets]
    x = np.array([shape_features(Scenario(*s)) for s in scenarios])
    bj = _node_correlation(list(SHAPE_PERIODS))
    gains, variances = np.zeros((len(scenarios), k)), np.zeros((len(scenarios), k))  # the data: mean gain and d² of every scenario
    correlation, history = np.eye(k), []
    for iteration in range(iterations + regressed_iterations):
        used_gains, used_spreads = gains, np.sqrt(np.maximum(variances, 0.0))
        if iteration >= iterations:
            *_, used_gains, used_spreads = _regressed_layer(x, targets, gains, variances)
        draws = _draw_all(base, scenarios, used_gains, used_spreads, np.linalg.cholesky(correlation), n, seed, dt, workers)
        wanted, spread_products, misses = np.zeros((k, k)), np.zeros((k, k)), []
        for i, (pga, ln_sa) in enumerate((draw[:, 0], draw[:, 1:]) for draw in draws):
            mean, sigma = targets[i]
            covariance = np.cov(ln_sa.T)
            simulated = np.sqrt(np.diag(covariance))
            median_miss, pga_miss = mean - ln_sa.mean(axis=0), pga_targets[i] - pga.mean()
            misses.append((max(np.max(np.abs(median_miss)), abs(pga_miss)), np.max(np.abs(simulated - sigma))))
            gains[i] += median_miss
            gains[i, 0] += 0.5 * (pga_miss - median_miss[0])  # the first node: the mean of its own miss and PGA's
            variances[i] += sigma**2 - simulated**2
            if iteration < iterations:
                variances[i] = np.maximum(variances[i], 0.0)
            spread = np.sqrt(np.maximum(variances[i], 0.0))
            wanted += bj * np.outer(sigma, sigma) - covariance + np.outer(used_spreads[i], used_spreads[i]) * correlation
            spread_products += np.outer(spread, spread)
        correlation = nearest_correlation(np.where(spread_products > 1e-3, wanted / np.maximum(spread_products, 1e-3), np.eye(k)))
        history.append([float(np.max([m[0] for m in misses])), float(np.max([m[1] for m in misses]))])
    r_coefficients, v_coefficients, *_ = _regressed_layer(x, targets, gains, variances)
    return {"name": CALIBRATION_NAME, "periods": list(SHAPE_PERIODS), "mean": r_coefficients.tolist(), "variance": v_coefficients.tolist(),
            "correlation": correlation.tolist(), "residual_scale": dict(RESIDUAL_SCALE), "history": history, "n": n, "seed": seed,
            "iterations": iterations, "regressed_iterations": regressed_iterations, "scenarios": [list(s) for s in scenarios]}
