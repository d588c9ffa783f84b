"""Mechanisms of pounding in an ensemble's runs: a sliding base ratcheted by impacts, demands amplified by impacts.

Each run is compared with its *twin without impacts*: the same motion (the
same realization of the same ensemble) in the same cell without the impact
elements, i.e. the contact-free twin of a cell with contacts (gap = ``inf``,
:func:`stochpound.store.contact_free`) or the same building
without its moat wall (a variant without walls). Because a run and its twin
share the motion, their difference is taken run by run (paired), which
removes the variability between motions; every interval is the percentile
bootstrap of a mean over the realizations
(:func:`stochpound.analysis.mean_interval` with ``method="bootstrap"``, whose
bounds stay within the range of the values: never below zero for a
non-negative quantity, and of either sign for a difference).

Ratcheting
    Under repeated impacts from one side a sliding base is pushed the same
    way again and again and keeps a one-sided residual displacement. A cell
    *ratchets* (:func:`~stochpound.analysis.ratcheting`) when, over at least ``min_runs`` paired
    runs, both

    * the mean increase of abs(residual sliding) over the contact-free twin,
      mean(abs(r) − abs(r_free)), has an interval above 0 (pounding leaves
      the base further from where it started), and
    * the mean increase of the residual *away from the neighbour*,
      mean(a·r − a·r_free) with a = −1 for a building left of its
      neighbour and +1 right of it, has an interval above 0 (the impacts
      push it one way: away from the building it hits).

Amplification
    The mean of a peak demand (peak floor acceleration, peak storey drift)
    with impacts over its mean in the twins without impacts
    (:func:`~stochpound.analysis.amplification`): the ratio of the two means, and the mean of the
    per-run ratios with its interval; the impacts *raise* the demand where
    that interval lies above 1, and *lower* it where it lies below 1.
"""

from __future__ import annotations

import xarray as xr

from stochpound.analysis._intervals import mean_interval

ROUNDOFF = 1e-9
"""Changes within this of none are the rounding of runs that are the same, not a mechanism: m for a residual's paired
increase, relative for a ratio (a bound must exceed 0, or differ from 1, by more)."""


def _paired(data: xr.DataArray, twin: xr.DataArray, min_runs: int, dim: str) -> tuple[xr.DataArray, xr.DataArray, xr.DataArray]:
    """``data`` and ``twin`` (broadcast against ``data``'s cells) aligned on their common coordinates, NaN where either is missing
    (pairs only; other coordinates dropped), and where a cell has at least ``min_runs`` pairs along ``dim``."""
    if int(min_runs) < 2:
        raise ValueError(f"min_runs: must be at least 2, got {min_runs!r}")
    data, reference = xr.align(data.reset_coords(drop=True), twin.broadcast_like(data).reset_coords(drop=True), join="inner")
    both = data.notnull() & reference.notnull()
    return data.where(both), reference.where(both), both.sum(dim) >= int(min_runs)


def _interval(values: xr.DataArray, prefix: str, dim: str, confidence: float, enough: xr.DataArray) -> xr.Dataset:
    """``<prefix>_mean``, ``_lower``, ``_upper`` (NaN where not ``enough``) and ``_count`` of the bootstrap interval of the mean of ``values``."""
    result = mean_interval(values, dim, confidence, method="bootstrap")
    return xr.Dataset({
        f"{prefix}_mean": result["mean"].where(enough),
        f"{prefix}_lower": result["lower"].where(enough),
        f"{prefix}_upper": result["upper"].where(enough),
        f"{prefix}_count": result["count"],
    })


def ratcheting(residual: xr.DataArray, contact_free: xr.DataArray, away: float, min_runs: int, dim: str = "realization",
               confidence: float = 0.95) -> xr.Dataset:
    """Whether pounding ratchets a sliding base, cell by cell (module docstring: the definition).

    Parameters
    ----------
    residual : xarray.DataArray
        Residual sliding of one building in the cells with contacts (the
        store's ``residual_sliding``, m, signed: positive to the right), with
        dimension ``dim`` and the cells' dimensions (finite gaps, μ, ...).
    contact_free : xarray.DataArray
        The same in the contact-free twins (gap = ``inf``, the gap
        dimensions dropped: :func:`stochpound.store.contact_free`);
        broadcast against ``residual``'s cells, paired by ``dim``.
    away : float
        −1 for a building left of its neighbour, +1 for one right of it: the
        sign of a displacement away from the neighbour.
    min_runs : int
        Fewest paired runs behind a cell's estimates; fewer give NaN
        estimates and no verdict.
    dim : str
        The ensemble dimension (the pairing).
    confidence : float
        Level of every interval, in (0, 1).

    Returns
    -------
    xarray.Dataset
        On ``residual``'s cells (m): ``abs_*`` and ``free_abs_*`` (mean,
        lower, upper, count of abs(residual) with contacts and in the twins),
        ``abs_change_*`` (paired mean of abs(r) − abs(r_free)), ``away_*`` and
        ``away_change_*`` (the mean residual away from the neighbour, a·r,
        and its paired increase over the twin's), and the booleans
        ``ratchets`` (both paired increases have intervals above 0),
        ``lowers`` (the paired change of abs(residual) has an interval below
        0), each by more than :data:`~stochpound.analysis.mechanisms.ROUNDOFF`, and ``enough`` (at least
        ``min_runs`` pairs).
    """
    if away not in (-1, 1, -1.0, 1.0):
        raise ValueError(f"away: must be -1 (the building is left of its neighbour) or +1 (right of it), got {away!r}")
    with_contacts, free, enough = _paired(residual, contact_free, min_runs, dim)
    result = xr.merge([
        _interval(abs(with_contacts), "abs", dim, confidence, enough),
        _interval(abs(free), "free_abs", dim, confidence, enough),
        _interval(abs(with_contacts) - abs(free), "abs_change", dim, confidence, enough),
        _interval(away * with_contacts, "away", dim, confidence, enough),
        _interval(away * (with_contacts - free), "away_change", dim, confidence, enough),
    ])
    result["ratchets"] = enough & (result["abs_change_lower"] > ROUNDOFF) & (result["away_change_lower"] > ROUNDOFF)
    result["lowers"] = enough & (result["abs_change_upper"] < -ROUNDOFF)
    result["enough"] = enough
    return result


def amplification(demand: xr.DataArray, twin: xr.DataArray, min_runs: int, dim: str = "realization", confidence: float = 0.95) -> xr.Dataset:
    """How much impacts raise a peak demand over the same runs without impacts, cell by cell (module docstring).

    Parameters
    ----------
    demand : xarray.DataArray
        A non-negative per-run peak with impacts (e.g. the store's
        ``peak_floor_acceleration`` of the studied building, m/s²), with
        dimension ``dim`` and the cells' dimensions.
    twin : xarray.DataArray
        The same peak of the twins without impacts (contact-free, or without
        a wall), broadcast against ``demand``'s cells, paired by ``dim``.
    min_runs : int
        Fewest paired runs behind a cell's estimates (fewer: NaN, no verdict).
    dim : str
        The ensemble dimension (the pairing).
    confidence : float
        Level of every interval, in (0, 1).

    Returns
    -------
    xarray.Dataset
        On ``demand``'s cells: ``with_*`` and ``twin_*`` (mean, lower, upper,
        count; units of ``demand``), ``ratio_of_means`` (1), ``ratio_*`` (the
        mean of the per-run ratios demand / twin with its interval and count)
        and the booleans ``raises`` (ratio interval above 1), ``lowers``
        (below 1), each by more than :data:`~stochpound.analysis.mechanisms.ROUNDOFF`, and ``enough`` (at
        least ``min_runs`` pairs).
    """
    with_impacts, without, enough = _paired(demand, twin, min_runs, dim)
    result = xr.merge([
        _interval(with_impacts, "with", dim, confidence, enough),
        _interval(without, "twin", dim, confidence, enough),
        _interval(with_impacts / without.where(without > 0), "ratio", dim, confidence, enough),
    ])
    result["ratio_of_means"] = result["with_mean"] / result["twin_mean"]
    result["raises"] = enough & (result["ratio_lower"] > 1 + ROUNDOFF)
    result["lowers"] = enough & (result["ratio_upper"] < 1 - ROUNDOFF)
    result["enough"] = enough
    return result
