"""Impact statistics from the impact table of a run (or of many runs)."""

from __future__ import annotations

import numpy as np
import xarray as xr


def impact_statistics(run: xr.Dataset, dim: str = "impact", valid: xr.DataArray | None = None) -> xr.Dataset:
    """Counts and extremes of the impacts listed along ``dim``.

    Works on a run's table and on padded tables, e.g. (realization, impact)
    with each realization's impacts followed by NaN rows; lazy on dask-backed
    tables.

    Parameters
    ----------
    run : xarray.Dataset
        Holds the impact table (``impact_in_phase``, ``impact_peak_force``,
        ``impact_duration``, ``impact_impulse``), e.g. a result of
        :func:`stochpound.simulate`, or one selection of an experiment's
        table. Use ``run.groupby(...)`` to get statistics per case or contact.
    dim : str
        The table's dimension.
    valid : xarray.DataArray of bool, optional
        Which rows are impacts (False for padding). Default: the rows with a
        peak force (padding is NaN there).

    Returns
    -------
    xarray.Dataset
        ``impacts`` (total), ``impacts_in_phase`` (both floors moving the same
        way at onset), ``impacts_out_of_phase``, ``peak_impact_force`` (N),
        ``longest_impact`` (s) and ``total_impulse`` (N·s); extremes are 0
        when there is no impact.

    Notes
    -----
    ``total_impulse`` is summed in table order, so a realization's statistics
    do not depend on how far its table is padded.
    """
    valid = run["impact_peak_force"].notnull() if valid is None else valid.astype(bool)
    count = valid.sum(dim)
    n_in_phase = run["impact_in_phase"].where(valid, False).astype(bool).sum(dim)

    def largest(name: str) -> xr.DataArray:
        values = run[name].where(valid)
        return values.max(dim).fillna(0.0) if values.sizes[dim] else xr.zeros_like(count, dtype=float)

    return xr.Dataset(
        {
            "impacts": count.assign_attrs(units="1", long_name="number of impacts"),
            "impacts_in_phase": n_in_phase.assign_attrs(units="1", long_name="impacts with both floors moving the same way at onset"),
            "impacts_out_of_phase": (count - n_in_phase).assign_attrs(units="1", long_name="impacts with the floors moving towards each other at onset"),
            "peak_impact_force": largest("impact_peak_force").assign_attrs(units="N", long_name="largest impact force"),
            "longest_impact": largest("impact_duration").assign_attrs(units="s", long_name="longest impact duration"),
            "total_impulse": _running_total(run["impact_impulse"].where(valid, 0.0), dim).assign_attrs(units="N s", long_name="sum of impact impulses"),
        }
    )


def _running_total(values: xr.DataArray, dim: str) -> xr.DataArray:
    """Sum along ``dim`` in table order (a cumulative sum): trailing padding zeros cannot change its last bit."""
    if not values.sizes[dim]:
        return values.sum(dim)
    return values.cumsum(dim).isel({dim: -1}, drop=True)


def in_phase(left_velocity: np.ndarray, right_velocity: np.ndarray) -> np.ndarray:
    """In-phase classification at onset: both floors moving the same way (velocities in m/s)."""
    return np.asarray(left_velocity) * np.asarray(right_velocity) > 0.0
