"""Importance sampling with the elementary events of a linear surrogate (ISEE; Au & Beck 2001), for a nonlinear response.

The response Y = g(u) is a function of n independent standard normals u. A
linear surrogate of the response's history, x_k = a_k · u at samples k (an
equivalent linear system under the same motion of u), gives elementary
events E_k = {‖a_k · u‖ > c} of probability P_k = 2 Φ(−c / ‖a_k‖), and
Au & Beck's ISEE density q(u) = φ(u) · N(u) / S, N(u) the number of events
u is in and S = Σ_k P_k, which puts its samples where the surrogate's peak
exceeds c. A defensive mixture (Hesterberg 1995) h = α φ + (1 − α) q keeps
every u possible, so

    P̂(Y > b) = (1/M) Σ_i 1{g(u_i) > b} / (α + (1 − α) N(u_i) / S)

is unbiased for any surrogate, and its coefficient of variation is the
sample's (M independent samples; the weights are at most 1/α). How small it
is depends on the surrogate: the failures of g that no elementary event
covers (N = 0) are sampled only by the share α drawn from φ, so a surrogate
that misses part of the failure domain leaves that part to chance (far down,
never drawn): check the coverage on failure samples drawn another way
(:func:`uncovered_share`, on a subset simulation's last level).
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np
import xarray as xr
from scipy.linalg import expm
from scipy.special import ndtr, ndtri

DEFENSIVE_SHARE = 0.1
"""α, the share of samples drawn from the standard normal itself."""


def oscillator_rows(motion: Callable[[np.ndarray], np.ndarray], dimension: int, dt: float, period: float, damping: float) -> np.ndarray:
    """The surrogate's rows a_k: the displacement of a linear oscillator under the motion of the normals, x_k = a_k · u.

    Parameters
    ----------
    motion : callable
        The ground acceleration (m, T) of normals (m, n), linear in them (a synthetic motion of
        :func:`~stochpound.motions.normal_motion`, m/s²).
    dimension : int
        n.
    dt : float
        The motion's step, s.
    period, damping : float
        The oscillator's period (s) and damping ratio (1): ẍ + 2ζωẋ + ω²x = −a_g, a_g linear between samples.

    Returns
    -------
    np.ndarray
        (T − 1, n) rows a_1 .. a_{T−1} (x_0 = 0 is never exceeded), m per unit normal.
    """
    accelerations = np.asarray(motion(np.eye(dimension)), dtype=float)  # (n, T): the motion of each unit normal
    omega = 2.0 * math.pi / period
    system = np.zeros((4, 4))
    system[:2, :2] = ((0.0, 1.0), (-omega**2, -2.0 * damping * omega))
    system[:2, 2], system[2, 3] = (0.0, -1.0), 1.0  # the ground's acceleration a_k + s t over the step, ṡ = 0
    step = expm(system * dt)
    phi, ramp = step[:2, :2], step[:2, 3] / dt
    hold = step[:2, 2] - ramp  # x_{k+1} = Φ x_k + hold a_k + ramp a_{k+1}
    state = np.zeros((2, dimension))
    rows = np.empty((accelerations.shape[1] - 1, dimension))
    for k in range(accelerations.shape[1] - 1):
        state = phi @ state + np.outer(hold, accelerations[:, k]) + np.outer(ramp, accelerations[:, k + 1])
        rows[k] = state[0]
    return rows


def surrogate_level(rows: np.ndarray, probability: float) -> float:
    """The surrogate's threshold c with S = Σ_k 2 Φ(−c / ‖a_k‖) = ``probability`` (m, by bisection)."""
    norms = np.linalg.norm(rows, axis=1)
    low, high = 0.0, 40.0 * float(norms.max())
    for _ in range(200):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if float(np.sum(2.0 * ndtr(-middle / norms))) > probability else (low, middle)
    return 0.5 * (low + high)


def linear_importance_sampling(
    function: Callable[[np.ndarray], np.ndarray], rows: np.ndarray, level: float, *, thresholds: Sequence[float], samples: int, seed: int,
    defensive: float = DEFENSIVE_SHARE,
) -> xr.Dataset:
    """P(g(u) > b) at thresholds b by importance sampling with the surrogate's elementary events {‖a_k · u‖ > level}.

    Parameters
    ----------
    function : callable
        g(u): (m, n) standard normals to (m,) responses.
    rows : np.ndarray
        (K, n) the surrogate's rows a_k (:func:`oscillator_rows`), in the response's units per unit normal.
    level : float
        c, the surrogate's threshold (> 0; :func:`surrogate_level` sets it from S).
    thresholds : sequence of float
        Thresholds b, in the response's units.
    samples : int
        M, the samples (runs of g), >= 2.
    seed : int
        Seed (>= 0): the same seed gives the same estimate.
    defensive : float
        α in (0, 1), the share of samples drawn from the standard normal itself.

    Returns
    -------
    xarray.Dataset
        Over ``threshold``: ``probability`` and ``cov`` (the sample's coefficient of variation, NaN where no sample fails);
        attrs: ``runs`` (M), ``surrogate_level`` (c), ``surrogate_probability`` (S), ``defensive`` (α), ``seed``, ``method``.

    Raises
    ------
    ValueError
        Naming the argument that is out of range.
    """
    rows = np.asarray(rows, dtype=float)
    values = np.atleast_1d(np.asarray(thresholds, dtype=float))
    if rows.ndim != 2 or rows.shape[0] == 0 or not np.all(np.isfinite(rows)) or np.any(np.linalg.norm(rows, axis=1) == 0.0):
        raise ValueError(f"rows: must be a (K, n) array of finite, non-zero rows, got shape {rows.shape}")
    if not isinstance(level, (int, float)) or isinstance(level, bool) or not 0.0 < level < math.inf:
        raise ValueError(f"level: must be a number > 0, got {level!r}")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise ValueError(f"samples: must be an integer >= 2, got {samples!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed: must be an integer >= 0, got {seed!r}")
    if not isinstance(defensive, (int, float)) or isinstance(defensive, bool) or not 0.0 < defensive < 1.0:
        raise ValueError(f"defensive: must be a number in (0, 1), got {defensive!r}")
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise ValueError(f"thresholds: must be one or more finite numbers, got {thresholds!r}")
    u, weights = _draw(rows, float(level), int(samples), np.random.default_rng(seed), float(defensive))
    y = np.asarray(function(u), dtype=float).reshape(-1)
    if y.shape != (len(u),) or not np.all(np.isfinite(y)):
        raise ValueError(f"response: must give one finite number per sample ({len(u)}), got shape {y.shape}")
    terms = (y[:, None] > values[None, :]) * weights[:, None]
    probability = terms.mean(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        cov = np.where(probability > 0.0, terms.std(axis=0, ddof=1) / math.sqrt(len(u)) / probability, math.nan)
    norms = np.linalg.norm(rows, axis=1)
    attrs = {"runs": int(samples), "surrogate_level": float(level), "surrogate_probability": float(np.sum(2.0 * ndtr(-level / norms))),
             "defensive": float(defensive), "seed": int(seed),
             "method": "importance sampling with the elementary events of a linear surrogate (Au & Beck 2001), defensive mixture"}
    return xr.Dataset(
        {"probability": ("threshold", probability, {"units": "1", "long_name": "probability of the response exceeding the threshold"}),
         "cov": ("threshold", cov, {"units": "1", "long_name": "coefficient of variation of the probability (the sample's)"})},
        coords={"threshold": values}, attrs=attrs,
    )


def uncovered_share(rows: np.ndarray, level: float, u: np.ndarray) -> float:
    """The share of the states u (rows: e.g. failure samples of a subset simulation) in no elementary event {‖a_k · u‖ > level}."""
    return float(np.mean(np.count_nonzero(np.abs(np.atleast_2d(u) @ np.asarray(rows).T) > level, axis=1) == 0))


def _draw(rows: np.ndarray, level: float, samples: int, rng: np.random.Generator, defensive: float) -> tuple[np.ndarray, np.ndarray]:
    """M samples of the mixture α φ + (1 − α) q and their weights φ / h = 1 / (α + (1 − α) N(u) / S)."""
    norms = np.linalg.norm(rows, axis=1)
    elementary = 2.0 * ndtr(-level / norms)
    total = float(elementary.sum())
    z = rng.standard_normal((samples, rows.shape[1]))
    chosen = rng.choice(len(rows), samples, p=elementary / total)
    direction = rows[chosen] / norms[chosen, None]
    beyond = -ndtri(ndtr(-level / norms[chosen]) * rng.random(samples)) * np.where(rng.random(samples) < 0.5, -1.0, 1.0)
    event = z + (beyond - np.sum(direction * z, axis=1))[:, None] * direction  # u in {|a_k · u| > c}: the rest of z kept
    u = np.where((rng.random(samples) < defensive)[:, None], z, event)
    inside = np.count_nonzero(np.abs(u @ rows.T) > level, axis=1)
    return u, 1.0 / (defensive + (1.0 - defensive) * inside / total)
