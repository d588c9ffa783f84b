"""Probability of pounding in an ensemble, with its confidence interval."""

from __future__ import annotations

import xarray as xr

from stochpound.stats import kernels
from stochpound.stats import reduce


def pounded(impacts: xr.DataArray) -> xr.DataArray:
    """1 where a case has at least one impact, 0 where it has none, NaN where it is missing."""
    return (impacts > 0).astype(float).where(impacts.notnull())


def pounding_probability(impacts: xr.DataArray, dim: str = "realization", confidence: float = 0.95) -> xr.Dataset:
    """Fraction of realizations with at least one impact, and its Clopper–Pearson interval.

    Parameters
    ----------
    impacts : xarray.DataArray
        Number of impacts per realization (other dimensions, e.g. ``gap``,
        broadcast); NaN (a missing case) is left out.
    dim : str
        The ensemble dimension.
    confidence : float
        Confidence level of the exact binomial (Clopper–Pearson) interval, in (0, 1).

    Returns
    -------
    xarray.Dataset
        ``probability``, ``lower`` and ``upper`` (all in [0, 1]) and
        ``realizations`` (:func:`stochpound.stats.kernels.proportion_interval`).
        Lazy on dask-backed inputs.
    """
    kernels.check_confidence(confidence)
    values = reduce(lambda events: tuple(kernels.proportion_interval(events, confidence)), [pounded(impacts)], [dim], 4)
    attrs = {"units": "1", "confidence": confidence}
    names = {
        "probability": {"long_name": "probability of pounding", **attrs},
        "lower": {"long_name": "lower confidence bound (Clopper-Pearson)", **attrs},
        "upper": {"long_name": "upper confidence bound (Clopper-Pearson)", **attrs},
        "realizations": {"units": "1", "long_name": "number of realizations"},
    }
    return xr.Dataset({name: value.assign_attrs(names[name]) for name, value in zip(names, values)})
