"""Sample moments: mean, variance, std, skewness and coefficient of excess."""

from __future__ import annotations

import xarray as xr

from stochpound.stats import kernels
from stochpound.stats import reduce
from stochpound.store import VariableAttributes

MOMENT_NAMES = kernels.Moments._fields


def moments(data: xr.DataArray, dim: str | list[str] = "time") -> xr.Dataset:
    """Population moments of ``data`` along ``dim`` (the study's Table 3.2 convention).

    Parameters
    ----------
    data : xarray.DataArray
        Any response (e.g. a total displacement in m); may be dask-backed.
        NaN (padding, missing cases) is ignored.
    dim : str or list of str
        Dimension(s) to reduce: ``time`` for one record, ``realization`` for
        an ensemble at each time, or both.

    Returns
    -------
    xarray.Dataset
        ``mean`` and ``std`` in the units of ``data``, ``variance`` in its
        square, ``skewness`` = m3/m2^1.5 and ``excess`` = m4/m2² − 3
        (population moments, ddof = 0; :func:`stochpound.stats.kernels.moments`).
        Lazy if ``data`` is.
    """
    dims = [dim] if isinstance(dim, str) else list(dim)
    axes = tuple(range(-len(dims), 0))
    values = reduce(lambda x: tuple(kernels.moments(x, axes)), [data], dims, len(MOMENT_NAMES))
    units = VariableAttributes.of(data, units="").units
    squared = f"({units})2" if units else ""
    attrs = {
        "mean": {"units": units, "long_name": "mean"},
        "variance": {"units": squared, "long_name": "variance (population)"},
        "std": {"units": units, "long_name": "standard deviation (population)"},
        "skewness": {"units": "1", "long_name": "skewness m3/m2^1.5"},
        "excess": {"units": "1", "long_name": "coefficient of excess (kurtosis - 3)"},
    }
    return xr.Dataset({name: value.assign_attrs(attrs[name]) for name, value in zip(MOMENT_NAMES, values)})
