"""Applying a numpy kernel (:mod:`stochpound.stats.kernels`) to xarray objects, lazily on dask."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import xarray as xr


def reduce(
    kernel: Callable,
    inputs: Sequence[xr.DataArray],
    dims: Sequence[str],
    outputs: int = 1,
    dtypes: Sequence[Any] | None = None,
    new_dims: Mapping[str, int] | None = None,
) -> Any:
    """``kernel`` applied over the core dimensions ``dims`` of every input.

    Parameters
    ----------
    kernel : callable
        Takes the inputs as numpy arrays with ``dims`` last (in that order)
        and returns one array, or a tuple of ``outputs`` arrays, with those
        dimensions reduced (and ``new_dims`` appended, if any).
    inputs : sequence of xarray.DataArray
        Aligned on their common coordinates (inner join); other dimensions
        broadcast.
    dims : sequence of str
        The dimensions the kernel reduces (the same for every input).
    outputs : int
        How many arrays the kernel returns.
    dtypes : sequence, optional
        The outputs' dtypes (default float).
    new_dims : mapping, optional
        Trailing dimensions (name -> size) the kernel appends to every output;
        a reduced dimension named again here is kept (a running statistic).

    Returns
    -------
    xarray.DataArray or tuple of xarray.DataArray
        Dask-backed (chunked like the inputs, the core dimensions in one
        chunk) when an input is, computed otherwise; no coordinates on the
        new dimensions (the caller's).
    """
    new_dims = dict(new_dims or {})
    return xr.apply_ufunc(
        kernel,
        *inputs,
        input_core_dims=[list(dims)] * len(inputs),
        output_core_dims=[list(new_dims)] * outputs if outputs > 1 else [list(new_dims)],
        join="inner",
        dask="parallelized",
        output_dtypes=list(dtypes or [float] * outputs),
        dask_gufunc_kwargs={"allow_rechunk": True, "output_sizes": new_dims},
    )
