"""Peak displacements and residual sliding of a run."""

from __future__ import annotations

import xarray as xr


def peak_response(run: xr.Dataset, dim: str = "time") -> xr.Dataset:
    """Peak |y|, |u|, |s| per building and the residual sliding at the end of the motion.

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
        floors and time), ``peak_sliding_displacement`` and ``residual_sliding``.
    """
    return xr.Dataset(
        {
            "peak_total_displacement": abs(run["total_displacement"]).max([dim, "floor"]).assign_attrs(
                units="m", long_name="peak |total displacement| over floors and time"
            ),
            "peak_relative_displacement": abs(run["relative_displacement"]).max([dim, "floor"]).assign_attrs(
                units="m", long_name="peak |displacement relative to the base| over floors and time"
            ),
            "peak_sliding_displacement": abs(run["sliding_displacement"]).max(dim).assign_attrs(
                units="m", long_name="peak |sliding displacement|"
            ),
            "residual_sliding": run["sliding_displacement"].isel({dim: -1}, drop=True).assign_attrs(
                units="m", long_name="sliding displacement at the end of the motion"
            ),
        }
    )
