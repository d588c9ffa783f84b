"""Fragility functions of an ensemble for every threshold at once (every gap), with bootstrap-over-motions intervals.

Since a run with gap g pounds iff its contact-free peak closure D reaches g,
the pounded/not-pounded outcome of every run at every gap comes from the
contact-free runs: ``limit_state_events(D, gaps)``. The same holds for any
limit state defined by a demand and a threshold (isolator displacement
against its capacity, moat-wall closure against the moat gap, drift,
floor acceleration), so one function fits them all.

Inputs are :class:`xarray.DataArray` objects with a motion dimension
(``record``) and, for stripes, an intensity dimension (``intensity``, whose
coordinate is the stripe's level in IM units); every other dimension
(``gap``, configuration axes such as ``mu``) is carried along and gets its
own fit. The results are computed (not lazy).

Bootstrap: the motions (records), not the runs, are resampled with
replacement, the same resample for every stripe, threshold and
configuration, and everything is refitted; the intervals are BCa
percentiles of the refits (:mod:`stochpound.stats._bootstrap`). The
resamples are drawn from ``numpy.random.default_rng(seed)``, so a seed
reproduces them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from stochpound.stats import bootstrap_method, bootstrap_weights, interval, jackknife_weights, kernels, record_clusters, resampling_obstacle
from stochpound.risk._fragility import DECREASING, STATUS, ida_mle, lognormal_cdf, stripe_mle

BOOTSTRAP = 1000
"""Default number of bootstrap resamples of the motions."""


def limit_state_events(demand: xr.DataArray, thresholds: Sequence[float] | np.ndarray, dim: str = "gap",
                       contact_dim: str | None = None) -> xr.DataArray:
    """Whether each run's demand reaches each threshold: 1 if demand ≥ threshold, 0 if not, NaN if missing.

    Parameters
    ----------
    demand : xarray.DataArray
        One value per run, e.g. the contact-free ``peak_contact_closure``
        (m; pounding at gap g iff D ≥ g), ``peak_sliding_displacement`` (m),
        a storey drift or floor acceleration.
    thresholds : sequence of float
        The thresholds, in the units of ``demand`` (1-D, not NaN).
    dim : str
        Name of the new dimension of the thresholds (``gap`` for pounding).
    contact_dim : str, optional
        Reduce this dimension by its maximum first (a run pounds when any contact does).

    Returns
    -------
    xarray.DataArray
        ``demand``'s dimensions (less ``contact_dim``) plus ``dim``, first.
    """
    values = np.asarray(thresholds, dtype=float)
    if values.ndim != 1 or values.size == 0 or np.isnan(values).any():
        raise ValueError(f"thresholds: must be a non-empty 1-D sequence of numbers, got {thresholds!r}")
    if contact_dim is not None and contact_dim in demand.dims:
        demand = demand.max(contact_dim, skipna=False)
    if dim in demand.coords and dim not in demand.dims:  # e.g. a store's contact-free selection (gap = inf)
        demand = demand.drop_vars(dim)
    level = xr.DataArray(values, dims=dim, coords={dim: values}, attrs={"units": demand.attrs.get("units", "")})
    events = (demand >= level).astype(float).where(demand.notnull())
    return events.transpose(dim, ...).assign_attrs(units="1", long_name=f"demand reaches the threshold ({dim})")


def stripe_fragility(events: xr.DataArray, intensity_dim: str = "intensity", record_dim: str = "record",
                     confidence: float = 0.95, bootstrap: int = BOOTSTRAP, seed: int = 0) -> xr.Dataset:
    """Lognormal fragility of stripes by binomial maximum likelihood, for every other dimension, with bootstrap intervals.

    Parameters
    ----------
    events : xarray.DataArray
        1/0/NaN per run (:func:`limit_state_events`), with ``intensity_dim``
        (coordinate: the stripe levels, IM units, > 0) and ``record_dim``.
    intensity_dim, record_dim : str
        The stripes' and the motions' dimensions.
    confidence : float
        Level of the two-sided intervals, in (0, 1).
    bootstrap : int
        Number of resamples of the motions (0: no intervals).
    seed : int
        Seed of the resamples.

    Returns
    -------
    xarray.Dataset
        Over the other dimensions: ``theta`` (IM units), ``beta``,
        ``status`` (``stochpound.risk._fragility.STATUS``),
        ``theta_lower``/``theta_upper`` and ``beta_lower``/``beta_upper``
        (BCa bootstrap intervals), ``theta_bootstrap`` and ``beta_bootstrap``
        (dimension ``bootstrap``) and ``theta_jackknife`` and
        ``beta_jackknife`` (dimension ``jackknife``, one per motion left
        out), for the risk chain; per stripe, the
        empirical points ``exceeded``, ``runs``, ``probability`` and their
        Clopper–Pearson ``probability_lower``/``probability_upper``. Where
        the motions cannot be resampled (one motion, or every motion from one
        earthquake) there are no bootstrap variables and the attribute
        ``no_interval`` says why.
    """
    kernels.check_confidence(confidence)
    _check_dims(events, "events", intensity_dim, record_dim)
    levels = np.asarray(events[intensity_dim].values, dtype=float) if intensity_dim in events.coords else None
    if levels is None or not np.all(np.isfinite(levels) & (levels > 0.0)):
        raise ValueError(f"events: the {intensity_dim!r} coordinate must hold the stripes' levels (> 0)")
    data = events.transpose(..., intensity_dim, record_dim)
    values = np.asarray(data.values, dtype=float)
    valid = ~np.isnan(values)
    exceeded, runs = np.where(valid, values, 0.0).sum(-1), valid.sum(-1).astype(float)
    theta, beta, status = stripe_mle(levels, exceeded, runs)
    lower, upper = kernels.clopper_pearson(exceeded, runs, confidence)
    other = data.dims[:-2]
    coords = {name: coord for name, coord in data.coords.items() if set(coord.dims) <= set(other)}
    result = _fit_dataset(theta, beta, status, other, coords, "stripes")
    with np.errstate(invalid="ignore", divide="ignore"):
        probability = exceeded / runs
    per_stripe = (*other, intensity_dim)
    result = result.assign(
        exceeded=(per_stripe, exceeded, {"units": "1", "long_name": "runs that reached the limit state"}),
        runs=(per_stripe, runs, {"units": "1", "long_name": "runs counted"}),
        probability=(per_stripe, probability, {"units": "1", "long_name": "empirical probability of exceedance"}),
        probability_lower=(per_stripe, lower, {"units": "1", "long_name": "lower Clopper-Pearson bound", "confidence": confidence}),
        probability_upper=(per_stripe, upper, {"units": "1", "long_name": "upper Clopper-Pearson bound", "confidence": confidence}),
    ).assign_coords({intensity_dim: data[intensity_dim]})
    if bootstrap:
        def refit(weights: np.ndarray) -> tuple[np.ndarray, ...]:
            k_w = np.einsum("...jr,br->...bj", np.where(valid, values, 0.0), weights)
            n_w = np.einsum("...jr,br->...bj", valid.astype(float), weights)
            theta_w, beta_w, status_w = stripe_mle(levels, k_w, n_w)
            with np.errstate(invalid="ignore", divide="ignore"):  # a decreasing resample's flat fit: its pooled fraction
                flat = np.where(status_w == DECREASING, k_w.sum(-1) / n_w.sum(-1), np.nan)
            return theta_w, beta_w, flat

        ran = valid.reshape(-1, *valid.shape[-2:]).any(0)  # per stripe, the motions that ran in some configuration
        result = _with_bootstrap(result, refit, record_clusters(data, record_dim), values.shape[-1], other, confidence, bootstrap, seed, ran)
    return result


def ida_fragility(capacities: xr.DataArray, record_dim: str = "record", censored_at: ArrayLike | xr.DataArray | None = None,
                  confidence: float = 0.95, bootstrap: int = BOOTSTRAP, seed: int = 0) -> xr.Dataset:
    """Lognormal fragility of IDA capacities (log-moments; censored MLE where ``inf``), for every other dimension.

    Parameters
    ----------
    capacities : xarray.DataArray
        Each motion's intensity at first exceedance (> 0, ``inf`` where it
        never exceeded up to ``censored_at``), dims ``record_dim`` and e.g.
        ``gap`` (:func:`homogeneous_capacities`).
    censored_at : float or xarray.DataArray, optional
        The largest intensity each motion was scaled to (broadcast against ``capacities``).
    confidence, bootstrap, seed
        As in :func:`stripe_fragility`.

    Returns
    -------
    xarray.Dataset
        ``theta``, ``beta``, ``status`` and their bootstrap intervals and
        samples (or ``no_interval``), as in :func:`stripe_fragility` (no per-stripe points).
    """
    kernels.check_confidence(confidence)
    _check_dims(capacities, "capacities", record_dim)
    data = capacities.transpose(..., record_dim)
    values = np.asarray(data.values, dtype=float)
    bound = None
    if censored_at is not None:
        given = censored_at.broadcast_like(data).transpose(*data.dims).values if isinstance(censored_at, xr.DataArray) else censored_at
        bound = np.broadcast_to(np.asarray(given, dtype=float), values.shape)
    theta, beta, status = ida_mle(values, bound)
    other = data.dims[:-1]
    coords = {name: coord for name, coord in data.coords.items() if set(coord.dims) <= set(other)}
    result = _fit_dataset(theta, beta, status, other, coords, "ida")
    if bootstrap:
        def refit(weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return ida_mle(values[..., None, :], None if bound is None else bound[..., None, :], weights)[:2]

        result = _with_bootstrap(result, refit, record_clusters(data, record_dim), values.shape[-1], other, confidence, bootstrap, seed)
    return result


def homogeneous_capacities(peak_closure: xr.DataArray, intensity: xr.DataArray, gaps: Sequence[float] | np.ndarray,
                           dim: str = "gap") -> xr.DataArray:
    """IDA pounding capacities of every motion at every gap from one contact-free run per motion (linear scenes only).

    A contact-free scene with fixed bases and linear contact elements is
    linear from rest, so scaling motion i by λ scales its peak closure D_i
    by λ: it first pounds at gap g when λ = g / D_i, i.e. at intensity
    IM_i · g / D_i. Sliding bases break this: use stripes.

    Parameters
    ----------
    peak_closure : xarray.DataArray
        D_i of each motion at scale 1 (m, contact-free; already reduced over contacts).
    intensity : xarray.DataArray
        IM_i of each motion at scale 1 (IM units).
    gaps : sequence of float
        Gaps g (m, > 0).
    dim : str
        Name of the new dimension of the gaps.

    Returns
    -------
    xarray.DataArray
        Capacities (IM units) over ``dim`` and the inputs' dimensions;
        ``inf`` where D_i ≤ 0 (the motion never closes the gap at any scale).
    """
    values = np.asarray(gaps, dtype=float)
    if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values) & (values > 0.0)):
        raise ValueError(f"gaps: must be a non-empty 1-D sequence of gaps > 0 (m), got {gaps!r}")
    gap = xr.DataArray(values, dims=dim, coords={dim: values}, attrs={"units": "m"})
    closure = peak_closure.drop_vars(dim) if dim in peak_closure.coords and dim not in peak_closure.dims else peak_closure
    capacity = (intensity * gap / closure).where(closure > 0.0, np.inf).where(closure.notnull())
    return capacity.transpose(dim, ...).assign_attrs(units=intensity.attrs.get("units", ""), long_name="intensity at first pounding (IDA capacity)")


def fragility_surface(fragility: xr.Dataset, im: Sequence[float] | np.ndarray | xr.DataArray, dim: str = "im") -> xr.DataArray:
    """F(x) of every fit of ``fragility`` (θ, β) at intensities ``im``: e.g. the surface P(gap, IM).

    Returns
    -------
    xarray.DataArray
        The fits' dimensions plus ``dim`` (the intensities, IM units).
    """
    x = im if isinstance(im, xr.DataArray) else xr.DataArray(np.asarray(im, dtype=float), dims=dim, coords={dim: np.asarray(im, dtype=float)})
    surface = xr.apply_ufunc(lognormal_cdf, x, fragility["theta"], fragility["beta"])
    return surface.assign_attrs(units="1", long_name="fitted probability of exceedance")


def fragility_band(fragility: xr.Dataset, im: Sequence[float] | np.ndarray, confidence: float = 0.95, dim: str = "im") -> xr.Dataset:
    """The fitted F(x) at intensities ``im`` with its bootstrap band, for every fit (e.g. curves at a few gaps).

    Parameters
    ----------
    fragility : xarray.Dataset
        From :func:`stripe_fragility` or :func:`ida_fragility` with a bootstrap.
    im : sequence of float
        Intensities (IM units, > 0).
    confidence : float
        Level of the band (BCa over the resamples of the motions), in (0, 1).
    dim : str
        Name of the intensities' dimension.

    Returns
    -------
    xarray.Dataset
        ``probability`` (the fit), ``lower`` and ``upper`` over the fits' dimensions and ``dim``.
    """
    kernels.check_confidence(confidence)
    if "theta_bootstrap" not in fragility:
        raise ValueError("fragility: has no bootstrap samples (fit it with bootstrap > 0)")
    x = xr.DataArray(np.asarray(im, dtype=float), dims=dim, coords={dim: np.asarray(im, dtype=float)})
    fit = fragility_surface(fragility, x, dim)
    sampled = xr.apply_ufunc(lognormal_cdf, x, fragility["theta_bootstrap"], fragility["beta_bootstrap"])
    left_out = xr.apply_ufunc(lognormal_cdf, x, fragility["theta_jackknife"], fragility["beta_jackknife"])
    lower, upper = xr.apply_ufunc(lambda b, e, j: interval(b, e, j, confidence), sampled, fit, left_out,
                                  input_core_dims=[["bootstrap"], [], ["jackknife"]], output_core_dims=[[], []])
    attrs = {"units": "1", "confidence": confidence}
    return xr.Dataset({"probability": fit, "lower": lower.assign_attrs(long_name="lower bound of the fitted probability", **attrs),
                       "upper": upper.assign_attrs(long_name="upper bound of the fitted probability", **attrs)})


# ---------------------------------------------------------------- helpers


def _check_dims(data: xr.DataArray, name: str, *dims: str) -> None:
    for dim in dims:
        if dim not in data.dims:
            raise ValueError(f"{name}: has no dimension {dim!r} (its dimensions: {', '.join(map(str, data.dims))})")


def _fit_dataset(theta: np.ndarray, beta: np.ndarray, status: np.ndarray, dims: tuple, coords: dict, method: str) -> xr.Dataset:
    return xr.Dataset(
        {
            "theta": (dims, theta, {"long_name": "median of the lognormal fragility (IM units)"}),
            "beta": (dims, beta, {"units": "1", "long_name": "log-standard deviation of the lognormal fragility"}),
            "status": (dims, status.astype(np.int8), {"long_name": "fit status", "flag_values": list(range(len(STATUS))), "flag_meanings": " ".join(STATUS)}),
        },
        coords=coords,
        attrs={"method": method},
    )


def _with_bootstrap(result: xr.Dataset, refit: Callable[[np.ndarray], tuple[np.ndarray, ...]], clusters: np.ndarray | None,
                    motions: int, dims: tuple, confidence: float, resamples: int, seed: int, ran: np.ndarray | None = None) -> xr.Dataset:
    """``result`` with θ, β refitted to bootstrap and jackknife resamples of the motions (by cluster), and their BCa intervals
    (``ran``: which motions ran, per stripe, for the method's words; :func:`~stochpound.analysis.bootstrap_method`).

    A ``refit`` that returns a third array gives, per resample, the flat fit's
    fraction where that resample's fit is ``decreasing`` (NaN elsewhere):
    ``flat_bootstrap``/``flat_jackknife``, which the MAF of the resamples uses.

    Where the motions cannot be resampled (one motion, or one earthquake:
    ``stochpound.stats.resampling_obstacle``) ``result`` is returned
    without intervals, its attribute ``no_interval`` saying why.
    """
    obstacle = resampling_obstacle(motions, clusters)
    if obstacle:
        return result.assign_attrs(no_interval=obstacle)
    theta_b, beta_b, *flat_b = refit(bootstrap_weights(motions, resamples, seed, clusters))
    theta_j, beta_j, *flat_j = refit(jackknife_weights(motions, clusters))
    attrs = {"confidence": confidence, "method": bootstrap_method(clusters, ran), "seed": seed}
    variables = {}
    if flat_b:
        flat = {"units": "1", "long_name": "fraction of runs that exceeded, where the resample's fit is decreasing (flat)"}
        variables.update({"flat_bootstrap": ((*dims, "bootstrap"), flat_b[0], flat), "flat_jackknife": ((*dims, "jackknife"), flat_j[0], flat)})
    for name, sampled, left_out, units in (("theta", theta_b, theta_j, {}), ("beta", beta_b, beta_j, {"units": "1"})):
        lower, upper = interval(sampled, result[name].values, left_out, confidence)
        variables.update({
            f"{name}_lower": (dims, lower, {"long_name": f"lower bound of {name}", **units, **attrs}),
            f"{name}_upper": (dims, upper, {"long_name": f"upper bound of {name}", **units, **attrs}),
            f"{name}_bootstrap": ((*dims, "bootstrap"), sampled, {"long_name": f"{name} refitted to each resample of the motions", **units}),
            f"{name}_jackknife": ((*dims, "jackknife"), left_out, {"long_name": f"{name} refitted without each motion", **units}),
        })
    return result.assign(variables)
