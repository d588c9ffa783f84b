"""Impact statistics from the impact table of a run (or of many runs)."""

from __future__ import annotations

import numpy as np
import xarray as xr

from stochpound.stats import kernels
from stochpound.stats import reduce

TABLE_COLUMNS = ("impact_in_phase", "impact_peak_force", "impact_duration", "impact_impulse")
"""The impact-table columns :func:`impact_statistics` reads."""
_ATTRS = {
    "impacts": {"units": "1", "long_name": "number of impacts"},
    "impacts_in_phase": {"units": "1", "long_name": "impacts with both floors moving the same way at onset"},
    "impacts_out_of_phase": {"units": "1", "long_name": "impacts with the floors moving towards each other at onset"},
    "peak_impact_force": {"units": "N", "long_name": "largest impact force"},
    "longest_impact": {"units": "s", "long_name": "longest impact duration"},
    "total_impulse": {"units": "N s", "long_name": "sum of impact impulses"},
}


def impact_statistics(run: xr.Dataset, dim: str = "impact", valid: xr.DataArray | None = None) -> xr.Dataset:
    """Counts and extremes of the impacts listed along ``dim``.

    Works on a run's table and on padded tables, e.g. (realization, impact)
    with each realization's impacts followed by NaN rows; lazy on dask-backed
    tables (:func:`stochpound.stats.kernels.impact_counts`).

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
    """
    valid = run["impact_peak_force"].notnull() if valid is None else valid.astype(bool)
    columns = [run[name] for name in TABLE_COLUMNS]
    names = kernels.ImpactCounts._fields
    values = reduce(lambda *arrays: tuple(kernels.impact_counts(*arrays)), [*columns, valid], [dim], len(names), [np.int64] * 3 + [float] * 3)
    return xr.Dataset({name: value.assign_attrs(_ATTRS[name]) for name, value in zip(names, values)})


def in_phase(left_velocity: np.ndarray, right_velocity: np.ndarray) -> np.ndarray:
    """In-phase classification at onset: both floors moving the same way (velocities in m/s)."""
    return np.asarray(left_velocity) * np.asarray(right_velocity) > 0.0
