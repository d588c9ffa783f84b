"""Sample moments: mean, variance, std, skewness and coefficient of excess."""

from __future__ import annotations

import xarray as xr

MOMENT_NAMES = ("mean", "variance", "std", "skewness", "excess")


def moments(data: xr.DataArray, dim: str | list[str] = "time") -> xr.Dataset:
    """Population moments of ``data`` along ``dim`` (the study's Table 3.2 convention).

    Parameters
    ----------
    data : xarray.DataArray
        Any response (e.g. a total displacement in m); may be dask-backed.
    dim : str or list of str
        Dimension(s) to reduce: ``time`` for one record, ``realization`` for
        an ensemble at each time, or both.

    Returns
    -------
    xarray.Dataset
        ``mean`` and ``std`` in the units of ``data``, ``variance`` in its
        square, ``skewness`` = m3/m2^1.5 and ``excess`` = m4/m2² − 3
        (population moments, ddof = 0). Lazy if ``data`` is.
    """
    mean = data.mean(dim)
    deviation = data - mean
    m2 = (deviation**2).mean(dim)
    m3 = (deviation**3).mean(dim)
    m4 = (deviation**4).mean(dim)
    units = data.attrs.get("units", "")
    squared = f"({units})2" if units else ""
    return xr.Dataset(
        {
            "mean": mean.assign_attrs(units=units, long_name="mean"),
            "variance": m2.assign_attrs(units=squared, long_name="variance (population)"),
            "std": (m2**0.5).assign_attrs(units=units, long_name="standard deviation (population)"),
            "skewness": (m3 / m2**1.5).assign_attrs(units="1", long_name="skewness m3/m2^1.5"),
            "excess": (m4 / m2**2 - 3.0).assign_attrs(units="1", long_name="coefficient of excess (kurtosis - 3)"),
        }
    )
