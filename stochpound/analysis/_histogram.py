"""Histograms of a response with the fitted normal density (the study's Figures 4.6, 4.18, 4.19)."""

from __future__ import annotations

import numpy as np
import xarray as xr

from stochpound.stats import kernels
from stochpound.store import VariableAttributes


def normal_histogram(data: xr.DataArray, bins: int = 40) -> xr.Dataset:
    """Density histogram of all values of ``data`` and the normal density with its mean and std.

    Parameters
    ----------
    data : xarray.DataArray
        The sample (every element counts once); loaded into memory.
    bins : int
        Number of equal-width bins.

    Returns
    -------
    xarray.Dataset
        On dimension ``bin``: ``density`` (1/units), ``normal_density`` at the
        bin centres, and bin ``edges`` (dimension ``edge``); attributes
        ``mean`` and ``std`` of the fitted normal.
    """
    from scipy import stats

    values = np.asarray(data.values, dtype=float).ravel()
    values = values[np.isfinite(values)]
    density, edges = np.histogram(values, bins=bins, density=True)
    centres = 0.5 * (edges[:-1] + edges[1:])
    sample = kernels.moments(values)
    mean, std = float(sample.mean), float(sample.std)
    units = VariableAttributes.of(data, units="").units
    return xr.Dataset(
        {
            "density": ("bin", density, {"units": f"1/({units})" if units else "1", "long_name": "sample density"}),
            "normal_density": ("bin", stats.norm.pdf(centres, mean, std), {"long_name": "fitted normal density"}),
            "edges": ("edge", edges, {"units": units, "long_name": "bin edges"}),
        },
        coords={"bin": ("bin", centres, {"units": units, "long_name": "bin centre"})},
        attrs={"mean": mean, "std": std},
    )
