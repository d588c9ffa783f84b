"""The gap axes of a store's grid, their contact-free and wall-free cases: the one rule for all, in the store layer.

A grid axis is a gap axis when its name is ``gap`` or ``gap_<name>``
(:func:`is_gap_axis`). A gap axis sets the at-rest gaps of contacts between
buildings, or the clearances of walls beside a building, or both; a store
records which in the axis coordinate's attribute ``sets`` (:data:`SETS`:
``contacts``, ``walls`` or ``contacts and walls``; a store without it sets
contacts). A *wall axis* (:func:`wall_gap_dims`) sets walls only; the others
are *contact axes* (:func:`contact_gap_dims`).

An axis that holds ``inf`` makes cases whose gaps never close: by the gap
identity their peak closure answers every gap at once (docs/separation.md).
On the contact axes these are the *contact-free* cases
(:func:`contact_free`), on the wall axes the *wall-free* cases
(:func:`wall_free`: the walls are never reached, but the closure toward them
is located). The risk chain, the experiment layer (the definition's parser) and the
reports select them with these functions (``stochpound.store``, and
``ds.pound`` on an open store). They take a store, or any dataset
or array on its grid dimensions carrying the gap coordinates (statistics
over realizations, say).
"""

from __future__ import annotations

import re
from typing import Any, TypeVar

import numpy as np
import xarray as xr

from stochpound.model.fields import TomlTable

Data = TypeVar("Data", xr.Dataset, xr.DataArray)

SETS = "sets"
"""Attribute of a store's gap coordinate: what the axis sets (``contacts``, ``walls`` or ``contacts and walls``)."""

_GAP_AXIS = re.compile(r"^gap(_[A-Za-z0-9_]+)?$")


def is_gap_axis(name: str) -> bool:
    """Whether a grid axis (a store dimension) is a gap axis: ``gap`` or ``gap_<name>`` (letters, digits, _)."""
    return _GAP_AXIS.match(name) is not None


def gap_dims(data: xr.Dataset | xr.DataArray) -> list[str]:
    """The gap axes among the dimensions of ``data``, in grid order (a store's: those of its ``case_status``)."""
    dims = data["case_status"].dims if isinstance(data, xr.Dataset) and "case_status" in data else data.dims
    return [str(d) for d in dims if is_gap_axis(str(d))]


def wall_gap_dims(data: xr.Dataset | xr.DataArray) -> list[str]:
    """The wall axes of ``data``: gap axes whose coordinate says they set walls only (attribute :data:`SETS`)."""
    return [d for d in gap_dims(data) if data[d].attrs.get(SETS) == "walls"]


def contact_gap_dims(data: xr.Dataset | xr.DataArray) -> list[str]:
    """The contact axes of ``data``: its gap axes but the wall axes."""
    walls = wall_gap_dims(data)
    return [d for d in gap_dims(data) if d not in walls]


def has_contact_free(data: xr.Dataset | xr.DataArray) -> bool:
    """Whether ``data`` has contact axes and every one of them holds ``inf`` (contact-free cases)."""
    return _holds_inf(data, contact_gap_dims(data))


def contact_free(data: Data) -> Data:
    """The contact-free cases: ``inf`` on every contact axis, their coordinates dropped (``data`` itself without contact axes)."""
    return _at_inf(data, contact_gap_dims(data))


def with_contacts(data: Data) -> Data:
    """``data`` without its contact-free cases: the finite values of every contact axis."""
    return _at_finite(data, contact_gap_dims(data))


def has_wall_free(data: xr.Dataset | xr.DataArray) -> bool:
    """Whether ``data`` has wall axes and every one of them holds ``inf`` (wall-free cases)."""
    return _holds_inf(data, wall_gap_dims(data))


def wall_free(data: Data) -> Data:
    """The wall-free cases: ``inf`` on every wall axis, their coordinates dropped (``data`` itself without wall axes)."""
    return _at_inf(data, wall_gap_dims(data))


def with_walls(data: Data) -> Data:
    """``data`` without its wall-free cases: the finite clearances of every wall axis."""
    return _at_finite(data, wall_gap_dims(data))


def walls_only(data: xr.Dataset) -> bool:
    """Whether a store's only impact elements are walls (no contact): every impact is a wall hit, which has no phase (a wall moves with the ground)."""
    return data.sizes.get("contact", 0) == 0 and "peak_wall_penetration" in data


def wall_axis(store: xr.Dataset) -> tuple[str, Any] | None:
    """The axis that sets walls and its value without a wall reached: a gap axis over the walls only holding ``inf`` and
    finite clearances (``(axis, inf)``), or a variant axis whose first value without walls is the reference when the base
    scene has no wall and the axis's other values add some; else None."""
    for axis in wall_gap_dims(store):
        values = store[axis].values
        if np.isinf(values).any() and np.isfinite(values).any():
            return axis, float(np.inf)
    definition = store.pound.definition
    if TomlTable(definition.scene, "scene").tables("wall"):
        return None
    for axis in definition.variants:
        if axis.name not in store.dims:
            continue
        edits = {value: TomlTable(axis.overrides[value], f"variants.{axis.name}.{value}").table_or_empty("scene") for value in axis.values}
        walled = {value: bool(edit.tables("wall")) for value, edit in edits.items()}
        bare = [value for value, has in walled.items() if not has]
        if bare and any(walled.values()):
            return axis.name, bare[0]
    return None


def _holds_inf(data: xr.Dataset | xr.DataArray, dims: list[str]) -> bool:
    return bool(dims) and all(np.isinf(data[d].values).any() for d in dims)


def _at_inf(data: Data, dims: list[str]) -> Data:
    return data.sel({d: np.inf for d in dims}, drop=True)


def _at_finite(data: Data, dims: list[str]) -> Data:
    return data.sel({d: data[d].values[np.isfinite(data[d].values)] for d in dims})
