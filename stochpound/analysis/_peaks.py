"""Peak displacements and residual sliding of a run."""

from __future__ import annotations

import xarray as xr

from stochpound.stats import kernels
from stochpound.stats import reduce


def peak_response(run: xr.Dataset, dim: str = "time") -> xr.Dataset:
    """Peak absolute total (y), relative (u) and sliding (s) displacement per building and the residual sliding at the end of the motion.

    Parameters
    ----------
    run : xarray.Dataset
        With ``total_displacement`` and ``relative_displacement`` (building,
        floor, time) and ``sliding_displacement`` (building, time), in m.
    dim : str
        The time dimension.

    Returns
    -------
    xarray.Dataset
        Per building (and any other dimension of the input), in m:
        ``peak_total_displacement`` and ``peak_relative_displacement`` (over
        floors and time), ``peak_sliding_displacement`` and ``residual_sliding``
        (the last value that is not NaN). Lazy on dask-backed inputs.
    """

    def over_floors(name: str) -> xr.DataArray:
        return reduce(lambda values: kernels.abs_peak(values, (-2, -1)), [run[name]], [dim, "floor"])

    sliding = run["sliding_displacement"]
    return xr.Dataset(
        {
            "peak_total_displacement": over_floors("total_displacement").assign_attrs(units="m", long_name="peak |total displacement| over floors and time"),
            "peak_relative_displacement": over_floors("relative_displacement").assign_attrs(
                units="m", long_name="peak |displacement relative to the base| over floors and time"
            ),
            "peak_sliding_displacement": reduce(kernels.abs_peak, [sliding], [dim]).assign_attrs(units="m", long_name="peak |sliding displacement|"),
            "residual_sliding": reduce(kernels.final_value, [sliding], [dim]).assign_attrs(units="m", long_name="sliding displacement at the end of the motion"),
        }
    )
