"""The per-run scalars of the model's outputs (one result dataset, one studied building)."""

from __future__ import annotations

import xarray as xr

from stochpound.stats import kernels
from stochpound.stats import correlation
from stochpound.analysis._impacts import impact_statistics
from stochpound.analysis._moments import moments
from stochpound.analysis.names import RESPONSE_MOMENTS, RUN_SUMMARY_ALIASES, with_aliases
from stochpound.analysis._peaks import peak_response
from stochpound.stats import reduce


def top_floor_total_displacement(run: xr.Dataset, building: str) -> xr.DataArray:
    """Total displacement (m) of the top floor of ``building`` over time."""
    y = run["total_displacement"].sel(building=building)
    top = int(y.notnull().any("time").sum("floor"))
    return y.sel(floor=top, drop=True)


def response_moments(response: xr.DataArray) -> xr.Dataset:
    """The moments of a response over time under their quantity names (``response_mean`` … ``response_excess``)."""
    return moments(response, "time").rename(RESPONSE_MOMENTS)


def run_summary(run: xr.Dataset, building: str, fixed_base: xr.DataArray | None = None) -> xr.Dataset:
    """Scalars that summarise one run, for the studied ``building``.

    Parameters
    ----------
    run : xarray.Dataset
        A result of :func:`stochpound.simulate`.
    building : str
        The studied building (its top floor's total displacement is the
        response whose moments are reported).
    fixed_base : xarray.DataArray, optional
        The same building's top-floor total displacement when alone on a
        fixed base under the same motion (same ``time``); gives
        ``fixed_base_correlation``.

    Returns
    -------
    xarray.Dataset
        Peaks and residual sliding of the studied building (m), impact
        statistics of the whole run, moments of the top-floor total
        displacement (``response_mean``, ``response_variance``,
        ``response_std``, ``response_skewness``, ``response_excess``),
        ``energy_residual_ratio`` (largest absolute residual over largest absolute input) and, if
        given a reference, ``fixed_base_correlation``; the earlier names
        ``mean`` … ``excess`` and ``correlation`` as aliases
        (:mod:`stochpound.analysis.names`).
    """
    response = top_floor_total_displacement(run, building)
    summary = xr.merge([peak_response(run).sel(building=building, drop=True), impact_statistics(run), response_moments(response)])
    summary["energy_residual_ratio"] = reduce(kernels.energy_residual_ratio, [run["energy_residual"], run["energy_input"]], ["time"]).assign_attrs(
        units="1", long_name="largest energy residual relative to the largest input energy"
    )
    if fixed_base is not None:
        summary["fixed_base_correlation"] = correlation(response, fixed_base)
    return with_aliases(summary, RUN_SUMMARY_ALIASES)
