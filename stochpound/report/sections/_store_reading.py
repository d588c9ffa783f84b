"""Reading experiment stores for a report: open them by experiment name, pick cases (the rest through ``ds.pound``)."""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import hashlib
import weakref

import xarray as xr

from stochpound._errors import StochpoundError
from stochpound.experiment import open_store
from stochpound.store import select_case


def open_stores(paths: Sequence[str | Path], edited: str = "warn") -> dict[str, xr.Dataset]:
    """Open experiment stores, keyed by their experiment name.

    Parameters
    ----------
    paths : sequence of path
        Store files written by ``stochpound experiment run``.
    edited : {"warn", "refuse", "accept"}
        A store whose definition does not match its recorded sha256 (:func:`~stochpound.open_store`).

    Returns
    -------
    dict
        ``experiment_name`` -> lazily opened store.

    Raises
    ------
    StochpoundError
        If a file is missing, is not a store (or, with ``edited="refuse"``, one changed since
        it was written), or two stores have the same experiment name.
    """
    stores: dict[str, xr.Dataset] = {}
    for path in map(Path, paths):
        if not path.is_file():
            raise StochpoundError(f"store {path}: no such file")
        try:
            store = open_store(path, edited=edited)
        except StochpoundError:
            raise
        except (OSError, ValueError, KeyError) as error:
            raise StochpoundError(f"store {path}: not a readable stochpound store ({error})") from None
        name = store.pound.provenance.experiment_name
        if not name:
            raise StochpoundError(f"store {path}: not a stochpound store (no experiment_name attribute)")
        if name in stores:
            raise StochpoundError(f"store {path}: experiment {name!r} is given twice")
        stores[name] = store
    return stores


def definition_source(store: xr.Dataset) -> str:
    """Where a store's definition comes from, in words: the experiment file it names, where a file with the text it ran is
    at that path (relative to the working directory), else the text the store records of itself, saying why the file is not
    named (not at that path, or changed since the run): a report never names as the source a file that is not the store's."""
    written = store.pound.provenance
    path = Path(written.experiment_file) if written.experiment_file else None
    if path is not None and path.is_file():
        text = path.read_text(encoding="utf-8", errors="replace")
        if not written.experiment_sha256 or hashlib.sha256(text.encode()).hexdigest() == written.experiment_sha256:
            return written.experiment_file
        why = f"its file {written.experiment_file} has changed since the run"
    else:
        why = f"its file {written.experiment_file} is not at that path" if written.experiment_file else "it names no file"
    recorded = f", text sha256 {written.experiment_sha256[:16]}…" if written.experiment_sha256 else ""
    return f"the experiment text recorded in the store ({why}{recorded})"


select = select_case
"""The store at the given labels (:func:`stochpound.store.select_case`)."""


#: The variables :func:`value` has read whole, by store: ``id(store)`` -> (a weak reference to the store, its variables in
#: memory). The reference does not keep the store (and its file) open; it tells a live store from a later one that got the
#: same ``id``. The last :data:`_READ_STORES` stores only.
_READ: OrderedDict[int, tuple[weakref.ref, dict[str, xr.DataArray]]] = OrderedDict()
_READ_STORES = 4
#: The largest variable (values) :func:`value` reads whole; a larger one is read at the case only.
_READ_MAX_VALUES = 1_000_000


def _variable(store: xr.Dataset, variable: str) -> xr.DataArray:
    """``store[variable]`` in memory, read once per store (a report reads hundreds of its values: 0.5 ms each from memory,
    7 ms each through dask, measured 2026-12-03), or lazily if it has more than :data:`_READ_MAX_VALUES` values."""
    array = store[variable]
    if array.size > _READ_MAX_VALUES:
        return array
    entry = _READ.get(id(store))
    if entry is None or entry[0]() is not store:  # none yet, or that of a store gone since, whose id this one reuses
        entry = _READ[id(store)] = (weakref.ref(store), {})
        while len(_READ) > _READ_STORES:
            _READ.popitem(last=False)
    _READ.move_to_end(id(store))
    if variable not in entry[1]:
        entry[1][variable] = array.compute()
    return entry[1][variable]


def value(store: xr.Dataset | None, variable: str, scale: float = 1.0, **labels: Any) -> float:
    """One number of a store (NaN when the store, the variable or the case is missing, or it did not finish)."""
    if store is None or variable not in store:
        return float("nan")
    array = _variable(store, variable)  # alone: selecting the whole store slices every variable (a report reads hundreds of values)
    try:
        for dim in set(labels) & set(store.dims) - set(array.dims):
            if dim in store.indexes:  # a label the store lacks is a missing case, whether or not the variable has its dimension
                store.indexes[dim].get_loc(labels[dim])
        data = select(array, **labels)
    except KeyError:
        return float("nan")
    if data.size != 1:
        raise StochpoundError(f"{variable} at {labels}: {data.size} values, expected one (give every dimension: {dict(data.sizes)})")
    return float(data.values.reshape(())) * scale
