"""Lognormal fragility functions F(x) = Φ(ln(x/θ)/β): fitted to stripes by maximum likelihood or to IDA capacities.

*Stripes* (intensity level x_j, n_j runs of which k_j exceeded the limit
state, e.g. pounded) are fitted by maximising the binomial log-likelihood
(Baker 2015)

    Σ_j k_j ln Φ(ln(x_j/θ)/β) + (n_j − k_j) ln(1 − Φ(ln(x_j/θ)/β)),

a probit regression of the counts on ln x, solved by Fisher scoring with
step halving (vectorised: many fits at once, e.g. every gap and every
bootstrap resample). *IDA capacities* c_i (the intensity at which motion i
first exceeds the limit state) give θ = exp(mean ln c), β = std(ln c)
(maximum likelihood, ddof = 0); capacities that were never reached
(``inf``, the motion was scaled up to ``censored_at`` without exceeding)
are right-censored observations of the same lognormal likelihood.

When the data cannot identify a lognormal, the fit is *degenerate* and says
so in its ``status`` (``STATUS``), with a step (β = 0) at θ:

* ``never``: no run exceeded (θ = inf, F ≡ 0);
* ``always``: every run exceeded (θ = 0, F ≡ 1);
* ``separated``: no run exceeded at a level above one that did not
  (complete or quasi-complete separation: the likelihood grows without
  bound as β → 0); θ is the geometric midpoint between the highest level
  with a non-exceeding run and the lowest level with an exceeding one;
* ``decreasing``: the fitted slope is not positive, or so near 0 that the
  median lies beyond floating-point range (a flat fit; θ, β NaN);
* ``empty``: no runs (θ, β NaN).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

STATUS = ("fit", "never", "always", "separated", "decreasing", "empty")
"""Meaning of the integer ``status`` of a fit (its index in this tuple)."""
FIT, NEVER, ALWAYS, SEPARATED, DECREASING, EMPTY = range(len(STATUS))

_ITERATIONS = 100
_TOLERANCE = 1e-10
_LOG_LARGEST = float(np.log(np.finfo(float).max))


@dataclass(frozen=True)
class Fragility:
    """A lognormal fragility function F(x) = Φ(ln(x/θ)/β), or a batch of them (array θ, β).

    Attributes
    ----------
    theta : float or numpy.ndarray
        Median θ (intensity units): F(θ) = 0.5. ``inf`` for ``never``, 0 for ``always``.
    beta : float or numpy.ndarray
        Log-standard deviation β (> 0; 0 for a degenerate step).
    status : int or numpy.ndarray
        Index into ``STATUS``.
    method : str
        ``"stripes"`` or ``"ida"``.
    """

    theta: float | np.ndarray
    beta: float | np.ndarray
    status: int | np.ndarray = FIT
    method: str = field(default="stripes")

    def __call__(self, x: ArrayLike) -> np.ndarray:
        """P(exceedance | IM = x): Φ(ln(x/θ)/β), a step at θ when β = 0 (F(θ) = 1)."""
        return lognormal_cdf(x, self.theta, self.beta)

    @property
    def status_name(self) -> str | np.ndarray:
        """The status as text (``STATUS``)."""
        names = np.asarray(STATUS, dtype=object)[np.asarray(self.status)]
        return str(names) if np.ndim(names) == 0 else names


def lognormal_cdf(x: ArrayLike, theta: ArrayLike, beta: ArrayLike) -> np.ndarray:
    """Φ(ln(x/θ)/β), broadcast; with β = 0 the step 1[x ≥ θ]; NaN where θ or β is NaN."""
    from scipy import special

    x, theta, beta = np.broadcast_arrays(*(np.asarray(value, dtype=float) for value in (x, theta, beta)))
    with np.errstate(divide="ignore", invalid="ignore"):
        z = (np.log(x) - np.log(theta)) / beta
        step = np.where(x >= theta, 1.0, 0.0)
        result = np.where(beta > 0.0, special.ndtr(z), step)
    return np.where(np.isnan(theta) | np.isnan(beta), np.nan, result)


def fit_fragility(levels: ArrayLike | None = None, pounded: ArrayLike | None = None, runs: ArrayLike | None = None, *,
                  capacities: ArrayLike | None = None, censored_at: ArrayLike | None = None) -> Fragility:
    """Fit a lognormal fragility to stripes (binomial MLE) or to IDA capacities (log-moments).

    Parameters
    ----------
    levels : array_like, optional
        Stripes: the intensity of each stripe (IM units, > 0).
    pounded : array_like, optional
        Stripes: the number of runs at each level that exceeded the limit state (pounded), 0 ≤ k ≤ n.
    runs : array_like, optional
        Stripes: the number of runs at each level (≥ 0; stripes with 0 runs are ignored).
    capacities : array_like, optional
        IDA: each motion's capacity, the intensity at which it first exceeded
        (> 0; ``inf`` where it never did up to ``censored_at``).
    censored_at : array_like, optional
        IDA: the largest intensity each motion was scaled to (broadcast
        against ``capacities``); needed when some capacity is ``inf``.

    Returns
    -------
    Fragility
        θ, β and the fit's status (``STATUS``). Leading axes of the
        inputs (before the stripes' or motions' last axis) give a batch of fits.

    Examples
    --------
    >>> frag = fit_fragility([0.2, 0.4, 0.6, 0.8], [1, 8, 14, 19], [20, 20, 20, 20])
    >>> round(float(frag.theta), 3), round(float(frag.beta), 3)
    (0.442, 0.445)
    """
    if capacities is not None:
        if levels is not None or pounded is not None or runs is not None:
            raise ValueError("capacities: give either stripes (levels, pounded, runs) or IDA capacities, not both")
        theta, beta, status = ida_mle(capacities, censored_at)
        return Fragility(_scalar(theta), _scalar(beta), _scalar(status), "ida")
    if levels is None or pounded is None or runs is None:
        raise ValueError("levels, pounded, runs: all three are needed for stripes (or give capacities= for IDA)")
    theta, beta, status = stripe_mle(levels, pounded, runs)
    return Fragility(_scalar(theta), _scalar(beta), _scalar(status), "stripes")


def stripe_mle(levels: ArrayLike, exceeded: ArrayLike, runs: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Maximum-likelihood θ, β of the binomial counts of stripes, for a batch of fits (last axis: stripes).

    Parameters
    ----------
    levels : array_like
        Intensity of each stripe (> 0), broadcast against the counts.
    exceeded, runs : array_like
        k_j and n_j (0 ≤ k_j ≤ n_j; may be bootstrap weights' sums, not integers).

    Returns
    -------
    theta, beta, status : numpy.ndarray
        Over the leading axes; degenerate data as described in the module.
    """
    x, k, n = np.broadcast_arrays(*(np.asarray(value, dtype=float) for value in (levels, exceeded, runs)))
    if x.ndim == 0 or x.shape[-1] == 0:
        raise ValueError("levels: need at least one stripe")
    if not np.all(np.isfinite(x) & (x > 0.0)):
        raise ValueError("levels: every stripe's intensity must be finite and > 0")
    if not np.all((n >= 0.0) & (k >= 0.0) & (k <= n)):
        raise ValueError("pounded: counts must satisfy 0 <= pounded <= runs at every stripe")
    u = np.log(x)
    status, step = _stripe_status(u, k, n)
    a, b = _probit_fisher_scoring(u, k, n, status == FIT)
    log_theta = np.divide(-a, b, out=np.full(np.shape(b), np.nan), where=b > 0.0)
    # θ = exp(−a/b) only for a rising slope whose median is a float: a flat fit (b → 0) has no median to speak of
    rising = (b > 0.0) & (np.abs(log_theta) < _LOG_LARGEST)
    theta = np.exp(log_theta, out=np.full(np.shape(b), np.nan), where=rising)
    beta = np.divide(1.0, b, out=np.full(np.shape(b), np.nan), where=rising)
    status = np.where((status == FIT) & ~rising, DECREASING, status)
    return _degenerate(theta, beta, status, step)


def ida_mle(capacities: ArrayLike, censored_at: ArrayLike | None = None, weights: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lognormal θ, β of IDA capacities (last axis: motions), right-censored where ``inf``, for a batch of fits.

    Without censoring, θ = exp(mean ln c) and β = std(ln c) (ddof = 0, the
    maximum-likelihood estimates). With censored capacities (``inf``: not
    reached up to ``censored_at``) the censored-normal likelihood of ln c is
    maximised by Newton's method in Olsen's (1978) parameters, where it is
    concave. ``weights`` (e.g. bootstrap multiplicities) weight each motion;
    NaN capacities are left out.

    Returns
    -------
    theta, beta, status : numpy.ndarray
        Over the leading axes; ``never`` when every capacity is censored,
        ``separated`` (β = 0) when the uncensored capacities are all equal and
        nothing is censored.
    """
    c = np.asarray(capacities, dtype=float)
    if c.ndim == 0 or c.shape[-1] == 0:
        raise ValueError("capacities: need at least one motion")
    if np.any(c <= 0.0):
        raise ValueError("capacities: must be > 0 (intensity at first exceedance; inf where never reached)")
    w = np.ones_like(c) if weights is None else np.broadcast_to(np.asarray(weights, dtype=float), np.broadcast_shapes(c.shape, np.shape(weights)))
    c = np.broadcast_to(c, w.shape)
    w = np.where(np.isnan(c), 0.0, w)
    censored = np.isinf(c) & (w > 0.0)
    if np.any(censored):
        if censored_at is None:
            raise ValueError("censored_at: some capacities are inf (never reached); give the largest intensity each motion was scaled to")
        bound = np.broadcast_to(np.asarray(censored_at, dtype=float), c.shape)
        if not np.all(np.isfinite(bound[censored]) & (bound[censored] > 0.0)):
            raise ValueError("censored_at: must be finite and > 0 where a capacity is inf")
    else:
        bound = np.ones_like(c)
    lead = c.shape[:-1]
    c, w, censored, bound = (value.reshape(-1, c.shape[-1]) for value in (c, w, censored, bound))
    y = np.where(censored | (w == 0.0), 0.0, np.log(np.where(np.isfinite(c), c, 1.0)))
    observed = np.where(censored, 0.0, w)
    total = observed.sum(-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = (observed * y).sum(-1) / total
        std = np.sqrt((observed * (y - mean[..., None]) ** 2).sum(-1) / total)
    status = np.full(mean.shape, FIT)
    status = np.where(total == 0.0, np.where((w * censored).sum(-1) > 0.0, NEVER, EMPTY), status)
    has_censored = (w * censored).sum(-1) > 0.0
    status = np.where((status == FIT) & ~has_censored & ~(std > 0.0), SEPARATED, status)
    mu, sigma = mean.copy(), std.copy()
    solve = (status == FIT) & has_censored
    if np.any(solve):
        mu[solve], sigma[solve] = _censored_newton(y[solve], observed[solve], np.where(censored, w, 0.0)[solve], np.log(bound)[solve],
                                                   mean[solve], std[solve])
    step = np.exp(np.where(status == SEPARATED, mean, np.nan))
    return tuple(value.reshape(lead) for value in _degenerate(np.exp(mu), sigma, status, step))


# ---------------------------------------------------------------- kernels


def _stripe_status(u: np.ndarray, k: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Status of each fit from its counts, and the step location (intensity) of the separated ones."""
    used = n > 0.0
    some = used & (k > 0.0)
    not_all = used & (k < n)
    highest_not_all = np.max(np.where(not_all, u, -np.inf), axis=-1)
    lowest_some = np.min(np.where(some, u, np.inf), axis=-1)
    status = np.full(u.shape[:-1], FIT)
    status = np.where(lowest_some >= highest_not_all, SEPARATED, status)
    status = np.where(~some.any(-1), NEVER, status)
    status = np.where(~not_all.any(-1), ALWAYS, status)
    status = np.where(~used.any(-1), EMPTY, status)
    with np.errstate(invalid="ignore"):
        step = np.exp(0.5 * (highest_not_all + lowest_some))
    return status, step


def _degenerate(theta: np.ndarray, beta: np.ndarray, status: np.ndarray, step: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """θ, β of the degenerate statuses (a step, β = 0): inf, 0 or ``step``; NaN for decreasing and empty."""
    theta = np.select([status == NEVER, status == ALWAYS, status == SEPARATED, status >= DECREASING], [np.inf, 0.0, step, np.nan], theta)
    beta = np.select([(status == NEVER) | (status == ALWAYS) | (status == SEPARATED), status >= DECREASING], [0.0, np.nan], beta)
    return theta, beta, status


def _probit_loglik(u: np.ndarray, k: np.ndarray, n: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Σ k ln Φ(a + b u) + (n − k) ln Φ(−(a + b u)) along the last axis."""
    from scipy import special

    eta = a[..., None] + b[..., None] * u
    return (k * special.log_ndtr(eta) + (n - k) * special.log_ndtr(-eta)).sum(-1)


def _probit_fisher_scoring(u: np.ndarray, k: np.ndarray, n: np.ndarray, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Maximum-likelihood (a, b) of P = Φ(a + b u) for binomial counts, by Fisher scoring with step halving.

    Each iteration works on the fits still moving only (flattened), so a
    few slow fits (nearly separated data) do not hold up the others.
    """
    shape = u.shape[:-1]
    u, k, n = (value.reshape(-1, value.shape[-1]) for value in (u, k, n))
    a, b = (value.ravel() for value in _probit_start(u, k, n))
    running = np.flatnonzero(active.ravel())
    a, b = np.where(active.ravel(), a, 0.0), np.where(active.ravel(), b, 1.0)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for _ in range(_ITERATIONS):
            if running.size == 0:
                break
            da, db, moved = _scoring_step(u[running], k[running], n[running], a[running], b[running])
            a[running] += da
            b[running] += db
            running = running[moved & (b[running] > 0.0)]  # a fit whose slope turns non-positive is decreasing
    return a.reshape(shape), b.reshape(shape)


def _scoring_step(u: np.ndarray, k: np.ndarray, n: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One Fisher-scoring step (halved until the likelihood does not fall) and whether each fit still moves."""
    from scipy import special

    eta = a[:, None] + b[:, None] * u
    log_phi = -0.5 * eta**2 - 0.5 * np.log(2.0 * np.pi)
    lower, upper = special.log_ndtr(eta), special.log_ndtr(-eta)
    score = k * np.exp(log_phi - lower) - (n - k) * np.exp(log_phi - upper)
    weight = n * np.exp(2.0 * log_phi - lower - upper)
    g0, g1 = score.sum(-1), (score * u).sum(-1)
    i00, i01, i11 = weight.sum(-1), (weight * u).sum(-1), (weight * u**2).sum(-1)
    det = i00 * i11 - i01**2
    da = np.nan_to_num((i11 * g0 - i01 * g1) / det)
    db = np.nan_to_num((i00 * g1 - i01 * g0) / det)
    loglik = (k * lower + (n - k) * upper).sum(-1)
    step = np.ones_like(a)
    pending = np.arange(a.size)
    for _ in range(40):
        trial = _probit_loglik(u[pending], k[pending], n[pending], a[pending] + step[pending] * da[pending], b[pending] + step[pending] * db[pending])
        worse = ~(trial >= loglik[pending] - 1e-12 * np.abs(loglik[pending]))
        pending = pending[worse]
        if pending.size == 0:
            break
        step[pending] *= 0.5
    da, db = step * da, step * db
    moved = np.abs(da) + np.abs(db) * (1.0 + np.abs(u).max(-1)) > _TOLERANCE
    return da, db, moved


def _probit_start(u: np.ndarray, k: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Starting (a, b): weighted least squares of the probits of the smoothed proportions on u."""
    from scipy import special

    with np.errstate(invalid="ignore", divide="ignore"):
        z = special.ndtri((k + 0.5) / (n + 1.0))
        w = n
        total = w.sum(-1)
        um = (w * u).sum(-1) / total
        zm = (w * z).sum(-1) / total
        suu = (w * (u - um[..., None]) ** 2).sum(-1)
        b = (w * (u - um[..., None]) * (z - zm[..., None])).sum(-1) / suu
        fallback = ~(np.isfinite(b) & (b > 0.0))
        b = np.where(fallback, 2.0, b)
        a = zm - b * um
    return np.nan_to_num(a), b


def _censored_newton(y: np.ndarray, observed: np.ndarray, censored: np.ndarray, bound: np.ndarray,
                     mean: np.ndarray, std: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """μ, σ of normal ln-capacities y (weights ``observed``) right-censored at ``bound`` (weights ``censored``).

    Newton's method on the concave log-likelihood in (δ, γ) = (1/σ, μ/σ), with step halving.
    """
    from scipy import special

    sigma0 = np.where(std > 0.0, std, 0.5)
    delta, gamma = 1.0 / sigma0, mean / sigma0

    def loglik(d: np.ndarray, g: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            value = (observed * (np.log(d)[..., None] - 0.5 * (d[..., None] * y - g[..., None]) ** 2)).sum(-1)
            value += (censored * special.log_ndtr(g[..., None] - d[..., None] * bound)).sum(-1)
        return np.where(d > 0.0, value, -np.inf)

    current = loglik(delta, gamma)
    for _ in range(_ITERATIONS):
        r = delta[..., None] * y - gamma[..., None]
        z = gamma[..., None] - delta[..., None] * bound
        mills = np.exp(-0.5 * z**2 - 0.5 * np.log(2.0 * np.pi) - special.log_ndtr(z))
        g_d = (observed * (1.0 / delta[..., None] - r * y)).sum(-1) - (censored * mills * bound).sum(-1)
        g_g = (observed * r).sum(-1) + (censored * mills).sum(-1)
        curvature = censored * mills * (z + mills)
        h_dd = -(observed * (1.0 / delta[..., None] ** 2 + y**2)).sum(-1) - (curvature * bound**2).sum(-1)
        h_dg = (observed * y).sum(-1) + (curvature * bound).sum(-1)
        h_gg = -observed.sum(-1) - curvature.sum(-1)
        det = h_dd * h_gg - h_dg**2
        step_d = -(h_gg * g_d - h_dg * g_g) / det
        step_g = -(h_dd * g_g - h_dg * g_d) / det
        scale = np.ones_like(delta)
        for _ in range(40):
            trial = loglik(delta + scale * step_d, gamma + scale * step_g)
            better = trial >= current - 1e-12 * np.abs(current)
            if better.all():
                break
            scale = np.where(better, scale, 0.5 * scale)
        delta, gamma = delta + scale * step_d, gamma + scale * step_g
        current = loglik(delta, gamma)
        if np.all(np.abs(scale * step_d) / delta + np.abs(scale * step_g) < _TOLERANCE):
            break
    return gamma / delta, 1.0 / delta


def _scalar(value: np.ndarray) -> float | np.ndarray:
    return value.item() if np.ndim(value) == 0 else value
