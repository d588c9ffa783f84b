"""Ensemble estimates with their uncertainty: means with confidence intervals, quantiles, running estimates.

Each function reduces (or runs along) the ensemble dimension of an xarray
object with a kernel of :mod:`stochpound.stats.kernels`, lazily on dask;
NaN (a missing case) is left out.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Literal

import xarray as xr

from stochpound.stats import kernels
from stochpound.analysis._pounding import pounded
from stochpound.stats import reduce
from stochpound.store import VariableAttributes

MIN_RUNS = 30
"""Fewest runs (values) behind an ensemble estimate that a conclusion is drawn from, that is compared or drawn as a
running estimate: below about 30 values neither the t nor the percentile-bootstrap interval of a mean of skewed,
non-negative peaks covers at its level (the bootstrap's is too narrow for a handful of values), and a proportion's
Clopper–Pearson interval is wider than most differences it would be compared with (±0.18 at P = 0.5 with 30 runs).
The one threshold of the reports (ensemble findings, convergence figures, contact laws compared)."""
#: Quantiles reported for peaks (median, ~mean + 1 sigma of a normal, 95 %).
QUANTILES = (0.5, 0.84, 0.95)
#: Interval of a mean: ``t`` (Student t, for a quantity of either sign) or ``bootstrap`` (percentile bootstrap, for a
#: quantity that cannot be negative: its bounds stay within the sample's range).
Method = Literal["t", "bootstrap"]
_MEAN_KERNELS = {"t": (kernels.mean_interval, "Student t"), "bootstrap": (kernels.bootstrap_mean_interval, "percentile bootstrap")}


def _mean_kernel(method: Method) -> tuple:
    """The interval kernel of ``method`` and its name."""
    if method not in _MEAN_KERNELS:
        raise ValueError(f"method: must be one of {', '.join(_MEAN_KERNELS)}, got {method!r}")
    return _MEAN_KERNELS[method]


def _interval_dataset(values: tuple, estimate: str, data: xr.DataArray, confidence: float, method: str) -> xr.Dataset:
    described = VariableAttributes.of(data, units="1", long_name=str(data.name or "value"))
    units, what = described.units, described.long_name
    return xr.Dataset(
        {
            estimate: values[0].assign_attrs(units=units, long_name=f"{estimate} of {what}"),
            "lower": values[1].assign_attrs(units=units, long_name=f"lower {confidence:g} confidence bound ({method})", confidence=confidence),
            "upper": values[2].assign_attrs(units=units, long_name=f"upper {confidence:g} confidence bound ({method})", confidence=confidence),
            "count": values[3].assign_attrs(units="1", long_name="number of values used"),
        }
    )


def mean_interval(data: xr.DataArray, dim: str = "realization", confidence: float = 0.95, method: Method = "t") -> xr.Dataset:
    """Mean of ``data`` along ``dim`` with its confidence interval (Student t, or a percentile bootstrap for a non-negative quantity).

    Parameters
    ----------
    data : xarray.DataArray
        E.g. a per-case summary of an experiment store (other dimensions are
        kept: one estimate per grid cell).
    dim : str
        The ensemble dimension.
    confidence : float
        Two-sided confidence level, in (0, 1).
    method : {"t", "bootstrap"}
        ``t``: Student t (:func:`stochpound.stats.kernels.mean_interval`),
        for a quantity of either sign; ``bootstrap``: the percentile bootstrap
        of the mean (:func:`stochpound.stats.kernels.bootstrap_mean_interval`),
        for a quantity that cannot be negative (counts, forces, peaks): never a
        negative bound.

    Returns
    -------
    xarray.Dataset
        ``mean``, ``lower``, ``upper`` (units of ``data``; NaN bounds for
        fewer than two values) and ``count``; the bounds' ``long_name`` names the method.
    """
    kernels.check_confidence(confidence)
    kernel, name = _mean_kernel(method)
    values = reduce(lambda x: tuple(kernel(x, confidence)), [data], [dim], 4)
    return _interval_dataset(values, "mean", data, confidence, name)


def quantiles(data: xr.DataArray, q: Sequence[float] = QUANTILES, dim: str = "realization") -> xr.DataArray:
    """Sample quantiles of ``data`` along ``dim``, on a new dimension ``quantile`` (linear interpolation, type 7)."""
    result = reduce(lambda x: kernels.quantiles(x, q), [data], [dim], new_dims={"quantile": len(q)})
    described = VariableAttributes.of(data, units="1", long_name=str(data.name or "value"))
    return result.assign_coords(quantile=list(q)).assign_attrs(units=described.units, long_name=f"quantiles of {described.long_name}")


def running_mean(data: xr.DataArray, dim: str = "realization", confidence: float = 0.95) -> xr.Dataset:
    """The mean of the first n values along ``dim`` and its t interval, for every n (convergence).

    Returns
    -------
    xarray.Dataset
        ``mean``, ``lower``, ``upper`` and ``count`` on the same dimensions
        as ``data`` (:func:`stochpound.stats.kernels.running_mean_interval`).
    """
    kernels.check_confidence(confidence)
    values = reduce(lambda x: tuple(kernels.running_mean_interval(x, confidence)), [data], [dim], 4, new_dims={dim: data.sizes[dim]})
    return _interval_dataset(values, "mean", data, confidence, "Student t").assign_coords({dim: data[dim]} if dim in data.coords else {})


def of_first(estimate: Callable[[xr.DataArray], xr.Dataset], data: xr.DataArray, counts: Sequence[int], dim: str = "realization") -> xr.Dataset:
    """``estimate`` (e.g. :func:`~stochpound.analysis.mean_interval`) of the first n entries of ``data`` along ``dim``, for each n of ``counts``.

    Convergence at chosen sample sizes, for an estimate without a running
    kernel (the percentile bootstrap): on a new dimension ``first`` (the n of
    ``counts``; missing entries among the first n are left out by ``estimate``).
    """
    return xr.concat([estimate(data.isel({dim: slice(0, int(n))})) for n in counts], dim="first").assign_coords(first=[int(n) for n in counts])


def running_pounding_probability(impacts: xr.DataArray, dim: str = "realization", confidence: float = 0.95) -> xr.Dataset:
    """The probability of pounding over the first n realizations and its Clopper–Pearson interval, for every n.

    Returns
    -------
    xarray.Dataset
        ``probability``, ``lower``, ``upper`` and ``count`` on the dimensions
        of ``impacts`` (:func:`stochpound.stats.kernels.running_proportion_interval`).
    """
    kernels.check_confidence(confidence)
    events = pounded(impacts).assign_attrs(units="1", long_name="pounding (at least one impact)")
    values = reduce(lambda x: tuple(kernels.running_proportion_interval(x, confidence)), [events], [dim], 4, new_dims={dim: impacts.sizes[dim]})
    result = _interval_dataset(values, "probability", events, confidence, "Clopper-Pearson")
    return result.assign_coords({dim: impacts[dim]} if dim in impacts.coords else {})
