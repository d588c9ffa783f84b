"""Probability of pounding in an ensemble, with its confidence interval."""

from __future__ import annotations

import xarray as xr
from scipy import stats


def pounding_probability(impacts: xr.DataArray, dim: str = "realization", confidence: float = 0.95) -> xr.Dataset:
    """Fraction of realizations with at least one impact, and its Clopper–Pearson interval.

    Parameters
    ----------
    impacts : xarray.DataArray
        Number of impacts per realization (other dimensions, e.g. ``gap``, broadcast).
    dim : str
        The ensemble dimension.
    confidence : float
        Confidence level of the exact binomial (Clopper–Pearson) interval, in (0, 1).

    Returns
    -------
    xarray.Dataset
        ``probability``, ``lower`` and ``upper`` (all in [0, 1]) and ``realizations``.
    """
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be in (0, 1), got {confidence}")
    pounded = (impacts > 0).sum(dim)
    total = impacts.count(dim)
    alpha = 1.0 - confidence

    def lower(k, n):
        return xr.where(k > 0, stats.beta.ppf(alpha / 2, k, n - k + 1), 0.0)

    def upper(k, n):
        return xr.where(k < n, stats.beta.ppf(1 - alpha / 2, k + 1, n - k), 1.0)

    attrs = {"units": "1", "confidence": confidence}
    return xr.Dataset(
        {
            "probability": (pounded / total).assign_attrs(long_name="probability of pounding", **attrs),
            "lower": xr.apply_ufunc(lower, pounded, total, dask="allowed").assign_attrs(long_name="lower confidence bound", **attrs),
            "upper": xr.apply_ufunc(upper, pounded, total, dask="allowed").assign_attrs(long_name="upper confidence bound", **attrs),
            "realizations": total.assign_attrs(units="1", long_name="number of realizations"),
        }
    )
