"""Impact statistics from the impact table of a run (or of many runs)."""

from __future__ import annotations

import numpy as np
import xarray as xr


def impact_statistics(run: xr.Dataset, dim: str = "impact") -> xr.Dataset:
    """Counts and extremes of the impacts listed along ``dim``.

    Parameters
    ----------
    run : xarray.Dataset
        Holds the impact table (``impact_in_phase``, ``impact_peak_force``,
        ``impact_duration``, ``impact_impulse``), e.g. a result of
        :func:`stochpound.simulate`, or one selection of an experiment's
        table. Use ``run.groupby(...)`` to get statistics per case or contact.
    dim : str
        The table's dimension.

    Returns
    -------
    xarray.Dataset
        ``impacts`` (total), ``impacts_in_phase`` (both floors moving the same
        way at onset), ``impacts_out_of_phase``, ``peak_impact_force`` (N),
        ``longest_impact`` (s) and ``total_impulse`` (N·s); extremes are 0
        when there is no impact.
    """
    in_phase = run["impact_in_phase"].astype(bool)
    count = in_phase.count(dim)
    n_in_phase = in_phase.sum(dim)

    def largest(name: str) -> xr.DataArray:
        values = run[name]
        return values.max(dim) if values.sizes[dim] else xr.zeros_like(count, dtype=float)

    return xr.Dataset(
        {
            "impacts": count.assign_attrs(units="1", long_name="number of impacts"),
            "impacts_in_phase": n_in_phase.assign_attrs(units="1", long_name="impacts with both floors moving the same way at onset"),
            "impacts_out_of_phase": (count - n_in_phase).assign_attrs(units="1", long_name="impacts with the floors moving towards each other at onset"),
            "peak_impact_force": largest("impact_peak_force").fillna(0.0).assign_attrs(units="N", long_name="largest impact force"),
            "longest_impact": largest("impact_duration").fillna(0.0).assign_attrs(units="s", long_name="longest impact duration"),
            "total_impulse": run["impact_impulse"].sum(dim).assign_attrs(units="N s", long_name="sum of impact impulses"),
        }
    )


def in_phase(left_velocity: np.ndarray, right_velocity: np.ndarray) -> np.ndarray:
    """In-phase classification at onset: both floors moving the same way (velocities in m/s)."""
    return np.asarray(left_velocity) * np.asarray(right_velocity) > 0.0
