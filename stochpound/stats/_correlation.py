"""Correlation of a response with a reference response (e.g. its fixed-base twin)."""

from __future__ import annotations

import xarray as xr

from stochpound.stats import kernels
from stochpound.stats._ufunc import reduce


def correlation(response: xr.DataArray, reference: xr.DataArray, dim: str = "time") -> xr.DataArray:
    """Pearson correlation coefficient of ``response`` with ``reference`` along ``dim``.

    The study's Tables 4.9–4.10 correlate Building 1's top-floor total
    displacement with the single fixed-base building's under the same motion.
    Dimensions other than ``dim`` broadcast (e.g. a grid over μ against one
    fixed-base reference); pairs with a NaN are dropped
    (:func:`stochpound.stats.kernels.pearson`). Lazy on dask-backed inputs.
    """
    result = reduce(kernels.pearson, [response, reference], [dim])
    return result.assign_attrs(units="1", long_name=f"correlation along {dim}")
