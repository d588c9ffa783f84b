"""Reading experiment stores for a report: open them by experiment name, pick cases (the rest through ``ds.pound``)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

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


select = select_case
"""The store at the given labels (:func:`stochpound.store.select_case`)."""


def value(store: xr.Dataset | None, variable: str, scale: float = 1.0, **labels: Any) -> float:
    """One number of a store (NaN when the store, the variable or the case is missing, or it did not finish)."""
    if store is None or variable not in store:
        return float("nan")
    try:
        data = select(store, **labels)[variable]
    except KeyError:
        return float("nan")
    if data.size != 1:
        raise StochpoundError(f"{variable} at {labels}: {data.size} values, expected one (give every dimension: {dict(data.sizes)})")
    return float(data.values.reshape(())) * scale
