"""Opening an experiment store: the netCDF file ``stochpound experiment run`` writes, lazily, on dask."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import xarray as xr

from stochpound._errors import ExperimentError

__all__ = ["open_store"]


def open_store(path: str | Path, chunks: Any = None) -> xr.Dataset:
    """Open an experiment store lazily (dask-chunked).

    Parameters
    ----------
    path : str or Path
        The store file written by ``stochpound experiment run``.
    chunks : optional
        Dask chunks (default ``{}``: the file's own chunking, blocks of
        consecutive realizations).

    Returns
    -------
    xarray.Dataset
        Summaries on the grid's dimensions, time histories, the impact table
        and the provenance attributes, loaded when computed; only the impact
        table's string coordinates (``impact_case_id`` and the string labels
        of the grid's dimensions) are read on opening, as xarray decodes
        variable-length strings eagerly (0.2–0.3 KB per impact row).

    Raises
    ------
    ExperimentError
        If the file is missing or not an experiment store.
    """
    path = Path(path)
    if not path.is_file():
        raise ExperimentError(f"{path}: store not found")
    try:
        dataset = xr.open_dataset(path, engine="h5netcdf", chunks={} if chunks is None else chunks)
    except (OSError, ValueError) as error:
        raise ExperimentError(f"{path}: not a readable netCDF4/HDF5 file ({error})") from None
    if "definition_sha256" not in dataset.attrs:
        dataset.close()
        raise ExperimentError(f"{path}: not a stochpound experiment store (no definition_sha256 attribute)")
    return dataset

