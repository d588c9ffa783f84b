"""The rate at which a demand exceeds thresholds, from a lognormal demand per stripe (the demand model of a multiple-stripe analysis).

A second estimator of the curve :func:`~stochpound.risk.risk_curve` gives
from the fragility fits of :func:`~stochpound.risk.stripe_fragility`. Those
fit, at every threshold d, a lognormal fragility to the counts of runs whose
demand D reaches d: at a threshold few runs reach, the answer rests on those
few. Here every run's value enters. At stripe j (level x_j of the
conditioning measure) the runs' ln D is taken as normal, with the mean m_j
and the sample standard deviation s_j (n − 1) of ln D over the runs with
D > 0, a fraction p_j of the stripe's runs (a run with D ≤ 0, e.g. a contact
that never closes, reaches no positive threshold):

    P(D ≥ d | x_j) = p_j Φ((m_j − ln d) / s_j).

Between stripes m, s and p are linear in ln x; below the lowest stripe and
above the highest, m continues along its end segment's slope (a power law of
x, as a demand often is), s and p are held. The rate is integrated with the
site's hazard λ(x) over its range [lo, hi] as
:func:`~stochpound.risk.mean_annual_frequency` does,

    λ_D(d) = P(D ≥ d | lo) λ(lo) + ∫_lo^hi λ(x) dP(D ≥ d | x),

the rate above the table's end counted at its end (trapezoids on
:data:`GRID_POINTS` points in ln x; a power law without ends is integrated
from :data:`BEYOND` e-folds below the lowest stripe to as many above the
highest). It is how Lin, Haselton & Baker (2013) compute drift hazard from
stripes; the price of its small sampling spread is the lognormal assumption
at each stripe, which the counts-based fits do not make. That price is
real where the measure is far from the periods that govern the demand:
within a stripe ln D is then a mixture over the shaking the measure does
not fix, right-skewed, and a stripe's normal misses its upper tail, which
is where a rare threshold's rate comes from. The sliding base's closure on
PGA or PSA at the superstructure's period is such a case: g* there comes
out low by ×1.3–1.8 (docs/intensity.md, "The short-period measures part by
their stripes' lognormal").
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import xarray as xr

from stochpound.hazard import HazardCurve

GRID_POINTS = 2000
"""Points in ln x of the integration over the hazard's range."""
BEYOND = 8.0
"""For a hazard without ends (a power law or an extrapolated table): e-folds of x integrated below the lowest stripe and above the highest."""


def stripe_demand_rate(demand: xr.DataArray, thresholds: Sequence[float] | np.ndarray, hz: HazardCurve, dim: str = "gap",
                       intensity_dim: str = "intensity", record_dim: str = "record") -> xr.DataArray:
    """λ(D ≥ d) (1/yr) at every threshold d, from a lognormal demand per stripe (module docstring).

    Parameters
    ----------
    demand : xarray.DataArray
        One value per run (e.g. the contact-free ``peak_contact_closure``, m),
        dims ``intensity_dim`` (coordinate: the stripes' levels in the
        hazard's units, > 0, at least 2) and ``record_dim``; NaN where a
        motion did not run at a stripe (a selection). Other dimensions
        (configurations) get their own curve.
    thresholds : sequence of float
        The thresholds d (> 0, in the units of ``demand``), e.g. gaps.
    hz : HazardCurve
        The site's hazard in the stripes' measure and units.
    dim : str
        The name of the thresholds' dimension.

    Returns
    -------
    xarray.DataArray
        Over ``dim`` and the other dimensions of ``demand`` (1/yr).

    Raises
    ------
    ValueError
        Naming the argument: thresholds not > 0, stripe levels missing or
        not > 0, a stripe with fewer than two runs with D > 0.
    """
    d = np.asarray(thresholds, dtype=float)
    if d.ndim != 1 or d.size == 0 or not np.all(np.isfinite(d) & (d > 0.0)):
        raise ValueError(f"thresholds: must be a non-empty 1-D sequence of numbers > 0, got {thresholds!r}")
    for name in (intensity_dim, record_dim):
        if name not in demand.dims:
            raise ValueError(f"demand: has no {name!r} dimension (its dimensions: {', '.join(map(str, demand.dims))})")
    levels = np.asarray(demand[intensity_dim].values, dtype=float) if intensity_dim in demand.coords else np.array([np.nan])
    if levels.size < 2 or not np.all(np.isfinite(levels) & (levels > 0.0)):
        raise ValueError(f"demand: the {intensity_dim!r} coordinate must hold at least two stripe levels (> 0)")
    order = np.argsort(levels)
    data = demand.isel({intensity_dim: order})
    rate = xr.apply_ufunc(_rate_kernel, data, kwargs={"levels": levels[order], "thresholds": d, "hz": hz},
                          input_core_dims=[[intensity_dim, record_dim]], output_core_dims=[[dim]])
    return rate.assign_coords({dim: d}).transpose(dim, ...).assign_attrs(units="1/yr", long_name="annual rate of the demand reaching the threshold")


def stripe_demand_moments(values: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The lognormal demand of each stripe (module docstring): m_j, s_j and p_j.

    Parameters
    ----------
    values : numpy.ndarray
        Demands (..., run), the last axis a stripe's runs (e.g. closures, m);
        NaN where a motion did not run.

    Returns
    -------
    mean, std, fraction : numpy.ndarray
        Over the leading axes: the mean and sample standard deviation (n − 1)
        of ln D over the runs with D > 0, and their fraction of the runs.

    Raises
    ------
    ValueError
        A stripe with fewer than two runs with D > 0.
    """
    values = np.asarray(values, dtype=float)
    ran = np.isfinite(values)
    positive = ran & (values > 0.0)
    count = positive.sum(-1)
    if np.any(count < 2):
        raise ValueError("demand: every stripe needs at least two runs with a demand > 0 for its lognormal")
    with np.errstate(divide="ignore", invalid="ignore"):
        logs = np.where(positive, np.log(np.where(positive, values, 1.0)), np.nan)
    mean = np.nanmean(logs, axis=-1)
    std = np.nanstd(logs, axis=-1, ddof=1)
    return mean, std, count / ran.sum(-1)


def _rate_kernel(values: np.ndarray, levels: np.ndarray, thresholds: np.ndarray, hz: HazardCurve) -> np.ndarray:
    """λ_D at every threshold from runs (..., stripe, run)."""
    from scipy import special

    mean, std, fraction = stripe_demand_moments(values)
    log_levels = np.log(levels)
    lo, hi = hz.support
    start = np.log(lo) if lo > 0.0 else log_levels[0] - BEYOND
    stop = np.log(hi) if np.isfinite(hi) else log_levels[-1] + BEYOND
    grid = np.linspace(start, stop, GRID_POINTS)
    m = _extended(grid, log_levels, mean)
    s = _held(grid, log_levels, std)
    p = _held(grid, log_levels, fraction)
    exceed = p[..., None, :] * special.ndtr((m[..., None, :] - np.log(thresholds)[:, None]) / s[..., None, :])  # (..., threshold, grid)
    rate = np.exp(hz.log_rate(grid))
    return exceed[..., 0] * rate[0] + np.sum(0.5 * (rate[1:] + rate[:-1]) * np.diff(exceed, axis=-1), axis=-1)


def _held(grid: np.ndarray, at: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``values`` (..., stripe) linear in ln x between the stripes, held beyond them, on ``grid``."""
    flat = values.reshape(-1, at.size)
    return np.stack([np.interp(grid, at, row) for row in flat]).reshape(*values.shape[:-1], grid.size)


def _extended(grid: np.ndarray, at: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``values`` (..., stripe) linear in ln x between the stripes and along the end segments' slopes beyond them, on ``grid``."""
    inside = _held(grid, at, values)
    low_slope = (values[..., 1] - values[..., 0]) / (at[1] - at[0])
    high_slope = (values[..., -1] - values[..., -2]) / (at[-1] - at[-2])
    below = values[..., :1] + low_slope[..., None] * (grid - at[0])
    above = values[..., -1:] + high_slope[..., None] * (grid - at[-1])
    return np.where(grid < at[0], below, np.where(grid > at[-1], above, inside))
