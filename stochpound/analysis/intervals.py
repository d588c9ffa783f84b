"""Ensemble estimates with their uncertainty: means with confidence intervals, quantiles, running estimates.

Each function reduces (or runs along) the ensemble dimension of an xarray
object with a kernel of :mod:`stochpound.analysis.kernels`, lazily on dask;
NaN (a missing case) is left out.
"""

from __future__ import annotations

from collections.abc import Sequence

import xarray as xr

from stochpound.analysis import kernels
from stochpound.analysis.pounding import pounded
from stochpound.analysis.ufunc import reduce

#: Quantiles reported for peaks (median, ~mean + 1 sigma of a normal, 95 %).
QUANTILES = (0.5, 0.84, 0.95)


def _interval_dataset(values: tuple, estimate: str, data: xr.DataArray, confidence: float, method: str) -> xr.Dataset:
    units = data.attrs.get("units", "1")
    what = data.attrs.get("long_name", data.name or "value")
    return xr.Dataset(
        {
            estimate: values[0].assign_attrs(units=units, long_name=f"{estimate} of {what}"),
            "lower": values[1].assign_attrs(units=units, long_name=f"lower {confidence:g} confidence bound ({method})", confidence=confidence),
            "upper": values[2].assign_attrs(units=units, long_name=f"upper {confidence:g} confidence bound ({method})", confidence=confidence),
            "count": values[3].assign_attrs(units="1", long_name="number of values used"),
        }
    )


def mean_interval(data: xr.DataArray, dim: str = "realization", confidence: float = 0.95) -> xr.Dataset:
    """Mean of ``data`` along ``dim`` with its Student-t confidence interval.

    Parameters
    ----------
    data : xarray.DataArray
        E.g. a per-case summary of an experiment store (other dimensions are
        kept: one estimate per grid cell).
    dim : str
        The ensemble dimension.
    confidence : float
        Two-sided confidence level, in (0, 1).

    Returns
    -------
    xarray.Dataset
        ``mean``, ``lower``, ``upper`` (units of ``data``; NaN bounds for
        fewer than two values) and ``count``
        (:func:`stochpound.analysis.kernels.mean_interval`).
    """
    kernels.check_confidence(confidence)
    values = reduce(lambda x: tuple(kernels.mean_interval(x, confidence)), [data], [dim], 4)
    return _interval_dataset(values, "mean", data, confidence, "Student t")


def quantiles(data: xr.DataArray, q: Sequence[float] = QUANTILES, dim: str = "realization") -> xr.DataArray:
    """Sample quantiles of ``data`` along ``dim``, on a new dimension ``quantile`` (linear interpolation, type 7)."""
    result = reduce(lambda x: kernels.quantiles(x, q), [data], [dim], new_dims={"quantile": len(q)})
    return result.assign_coords(quantile=list(q)).assign_attrs(units=data.attrs.get("units", "1"), long_name=f"quantiles of {data.attrs.get('long_name', data.name or 'value')}")


def running_mean(data: xr.DataArray, dim: str = "realization", confidence: float = 0.95) -> xr.Dataset:
    """The mean of the first n values along ``dim`` and its t interval, for every n (convergence).

    Returns
    -------
    xarray.Dataset
        ``mean``, ``lower``, ``upper`` and ``count`` on the same dimensions
        as ``data`` (:func:`stochpound.analysis.kernels.running_mean_interval`).
    """
    kernels.check_confidence(confidence)
    values = reduce(lambda x: tuple(kernels.running_mean_interval(x, confidence)), [data], [dim], 4, new_dims={dim: data.sizes[dim]})
    return _interval_dataset(values, "mean", data, confidence, "Student t").assign_coords({dim: data[dim]} if dim in data.coords else {})


def running_pounding_probability(impacts: xr.DataArray, dim: str = "realization", confidence: float = 0.95) -> xr.Dataset:
    """The probability of pounding over the first n realizations and its Clopper–Pearson interval, for every n.

    Returns
    -------
    xarray.Dataset
        ``probability``, ``lower``, ``upper`` and ``count`` on the dimensions
        of ``impacts`` (:func:`stochpound.analysis.kernels.running_proportion_interval`).
    """
    kernels.check_confidence(confidence)
    events = pounded(impacts).assign_attrs(units="1", long_name="pounding (at least one impact)")
    values = reduce(lambda x: tuple(kernels.running_proportion_interval(x, confidence)), [events], [dim], 4, new_dims={dim: impacts.sizes[dim]})
    result = _interval_dataset(values, "probability", events, confidence, "Clopper-Pearson")
    return result.assign_coords({dim: impacts[dim]} if dim in impacts.coords else {})
