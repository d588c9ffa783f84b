"""Reading experiment stores for a report: open them by experiment name, pick cases and their impacts."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from stochpound._errors import StochpoundError
from stochpound.experiment import Experiment, open_store
from stochpound.experiment import read_definition
from stochpound.model.scene import Scene
from stochpound.model.scene_file import scene_from_dict


def open_stores(paths: Sequence[str | Path]) -> dict[str, xr.Dataset]:
    """Open experiment stores, keyed by their experiment name.

    Parameters
    ----------
    paths : sequence of path
        Store files written by ``stochpound experiment run``.

    Returns
    -------
    dict
        ``experiment_name`` -> lazily opened store.

    Raises
    ------
    StochpoundError
        If a file is missing, is not a store, or two stores have the same experiment name.
    """
    stores: dict[str, xr.Dataset] = {}
    for path in map(Path, paths):
        if not path.is_file():
            raise StochpoundError(f"store {path}: no such file")
        try:
            store = open_store(path)
        except (OSError, ValueError, KeyError) as error:
            raise StochpoundError(f"store {path}: not a readable stochpound store ({error})") from None
        name = str(store.attrs.get("experiment_name", ""))
        if not name:
            raise StochpoundError(f"store {path}: not a stochpound store (no experiment_name attribute)")
        if name in stores:
            raise StochpoundError(f"store {path}: experiment {name!r} is given twice")
        stores[name] = store
    return stores


def select(store: xr.Dataset, **labels: Any) -> xr.Dataset:
    """The store at the given labels; labels of dimensions the store lacks are ignored.

    A ``realization`` of length 1 is squeezed. A label missing from its
    dimension raises ``KeyError`` (callers show such cells as missing).
    """
    present = {dim: value for dim, value in labels.items() if dim in store.dims}
    selected = store.sel(present)
    if "realization" in selected.dims and selected.sizes["realization"] == 1:
        selected = selected.isel(realization=0)
    return selected


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


def case_impacts(store: xr.Dataset, **labels: Any) -> xr.Dataset:
    """The rows of the impact table that belong to one case.

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store (impact table on dimension ``impact`` with
        coordinates ``impact_<dim>``).
    **labels
        The case's label on each grid dimension.

    Returns
    -------
    xarray.Dataset
        The ``impact_*`` variables of that case.
    """
    table = store[[name for name in store.data_vars if name.startswith("impact_") and store[name].dims == ("impact",)]]
    keep = np.ones(table.sizes["impact"], dtype=bool)
    for dim, label in labels.items():
        coordinate = f"impact_{dim}"
        if coordinate in table.coords:
            values = table[coordinate].values
            keep &= np.isclose(values, label) if np.issubdtype(values.dtype, np.number) else values == label
    return table.isel(impact=np.flatnonzero(keep)).load()


def store_experiment(store: xr.Dataset) -> Experiment:
    """The store's experiment, from its definition (:func:`~stochpound.experiment.read_definition`).

    The grid's values are numbers again (μ = ∞ is a float), as when the
    experiment file was read; case ids are unchanged.
    """
    return Experiment(read_definition(store))


def case_scene(store: xr.Dataset, **labels: Any) -> Scene:
    """The scene (structure and motion) of one stored case, rebuilt from the store's definition.

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store.
    **labels
        The case's label on every grid dimension of the store.
    """
    experiment = store_experiment(store)
    case = experiment.case_index[str(select(store, **labels)["case_id"].values)]
    where = case.label_dict
    return scene_from_dict({**experiment.structure(case), "motion": experiment.motion_table(where["record"], where.get("realization"))})

