"""The per-run scalars of MODEL.md §7, from one result dataset."""

from __future__ import annotations

import xarray as xr

from stochpound.analysis.correlation import correlation
from stochpound.analysis.impacts import impact_statistics
from stochpound.analysis.moments import moments
from stochpound.analysis.peaks import peak_response


def top_floor_total_displacement(run: xr.Dataset, building: str) -> xr.DataArray:
    """Total displacement (m) of the top floor of ``building`` over time."""
    y = run["total_displacement"].sel(building=building)
    top = int(y.notnull().any("time").sum("floor"))
    return y.sel(floor=top, drop=True)


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
        fixed base under the same motion (same ``time``); gives ``correlation``.

    Returns
    -------
    xarray.Dataset
        Peaks and residual sliding of the studied building (m), impact
        statistics of the whole run, moments of the top-floor total
        displacement (``mean``, ``variance``, ``std``, ``skewness``,
        ``excess``), ``energy_residual_ratio`` (max |residual| / max |input|)
        and, if given a reference, ``correlation``.
    """
    response = top_floor_total_displacement(run, building)
    summary = xr.merge(
        [
            peak_response(run).sel(building=building, drop=True),
            impact_statistics(run),
            moments(response, "time"),
        ]
    )
    summary["energy_residual_ratio"] = (abs(run["energy_residual"]).max() / abs(run["energy_input"]).max()).assign_attrs(
        units="1", long_name="largest energy residual relative to the largest input energy"
    )
    if fixed_base is not None:
        summary["correlation"] = correlation(response, fixed_base)
    return summary
