"""Opening an experiment store: the netCDF file ``stochpound experiment run`` writes, lazily, on dask.

A store records its definition (the ``definition`` attribute, canonical JSON)
and that definition's identity (``definition_sha256``). A store whose
definition no longer hashes to its recorded identity was changed since it
was written (by hand, say): :func:`open_store` says so, or refuses it.
"""

from __future__ import annotations

import hashlib
import json
import warnings
from pathlib import Path
from typing import Any

import xarray as xr

from stochpound._errors import ExperimentError
from stochpound.store._definition import definition_sha256
from stochpound.store._provenance import Provenance

__all__ = ["open_store"]

EDITED = ("warn", "refuse", "accept")
"""What :func:`open_store` does with a store whose definition does not match its recorded sha256."""


def open_store(path: str | Path, chunks: Any = None, *, edited: str = "warn") -> xr.Dataset:
    """Open an experiment store lazily (dask-chunked).

    Parameters
    ----------
    path : str or Path
        The store file written by ``stochpound experiment run``.
    chunks : optional
        Dask chunks (default ``{}``: the file's own chunking, blocks of
        consecutive realizations).
    edited : {"warn", "refuse", "accept"}
        A store whose ``definition`` attribute does not hash to its recorded
        ``definition_sha256`` (``identity_mismatch``: changed since it was
        written): warn (a ``UserWarning`` naming the store), refuse it
        (``ExperimentError``), or open it silently.

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
        If the file is missing or not an experiment store, or, with
        ``edited="refuse"``, its definition does not match its sha256.
    """
    if edited not in EDITED:
        raise ValueError(f"edited: must be one of {', '.join(EDITED)}, got {edited!r}")
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
    mismatch = identity_mismatch(dataset) if edited != "accept" else None
    if mismatch is not None:
        message = f"{path}: {mismatch}: changed since it was written (edited by hand?); its answers may not be its runs'"
        if edited == "refuse":
            dataset.close()
            raise ExperimentError(f"{message}; give --accept-edited to use it anyway")
        warnings.warn(message, stacklevel=2)
    return dataset


def identity_mismatch(store: xr.Dataset) -> str | None:
    """What is wrong with a store's identity, from its attributes, or None when its definition hashes to its ``definition_sha256``.

    The recorded sha256 is today's identity (:func:`~stochpound.store.definition_sha256`)
    or, for a store written before the entries of :data:`~stochpound.store.NOT_IN_IDENTITY`
    left the identity, the whole definition's. A store without a ``definition``
    attribute (the oldest) has nothing to check.
    """
    if "definition" not in store.attrs:
        return None
    recorded = Provenance.of(store).definition_sha256
    text = str(store.attrs["definition"])
    try:
        definition = json.loads(text)
    except ValueError:
        return "its definition attribute is not JSON"
    if not isinstance(definition, dict):
        return "its definition attribute is not a JSON table"
    if recorded in (definition_sha256(definition), hashlib.sha256(text.encode()).hexdigest()):
        return None
    return f"its definition does not match its recorded definition_sha256 {recorded[:12]}… (it hashes to {definition_sha256(definition)[:12]}…)"
