"""Selections of an experiment store by what its grid's values mean: contact-free and wall-free cases, fixed-base twins.

A gap axis that holds ``inf`` makes *contact-free* cases (an axis setting
contacts) or *wall-free* cases (an axis setting walls only): their gaps
never close, and by the gap identity their peak closure answers every gap at
once (docs/separation.md). That rule is ``stochpound.store._gap_axes``'s (the risk chain uses it too), given
here too. A μ axis that holds :data:`~stochpound.experiment.FIXED_BASE`
makes, for each isolated case, its *fixed-base twin*: the same case with the
sliding base removed. These functions take a store, or any dataset or array
on its grid dimensions (statistics over realizations, say).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any, TypeVar

import xarray as xr

from stochpound.model.friction import FIXED_BASE, is_fixed_base
from stochpound.store._gap_axes import contact_free, contact_gap_dims, gap_dims, has_contact_free, has_wall_free, wall_free, wall_gap_dims, with_contacts, with_walls

__all__ = [
    "contact_free", "contact_gap_dims", "fixed_base", "gap_dims", "has_contact_free", "has_fixed_base_twins", "has_wall_free",
    "isolated_mus", "wall_free", "wall_gap_dims", "with_contacts", "with_walls",
]

Data = TypeVar("Data", xr.Dataset, xr.DataArray)


def has_fixed_base_twins(mus: Iterable[float]) -> bool:
    """Whether a μ axis holds both :data:`~stochpound.experiment.FIXED_BASE` and finite values (isolated cases with their twins)."""
    fixed = [is_fixed_base(m) for m in mus]
    return any(fixed) and not all(fixed)


def isolated_mus(mus: Iterable[float]) -> list[float]:
    """The finite values of a μ axis (the cases on a sliding base), in order."""
    return [float(m) for m in mus if not is_fixed_base(m)]


def fixed_base(data: Data) -> Data:
    """The fixed-base cases (μ = :data:`~stochpound.experiment.FIXED_BASE`), the ``mu`` coordinate kept."""
    return data.sel(mu=FIXED_BASE)


def select_case(store: Data, **labels: Any) -> Data:
    """The store (or one of its variables) at the given labels; labels of dimensions it lacks are ignored.

    A ``realization`` of length 1 is squeezed. A label missing from its
    dimension raises ``KeyError`` (callers show such cells as missing).
    """
    present = {dim: value for dim, value in labels.items() if dim in store.dims}
    selected = store.sel(present)
    if "realization" in selected.dims and selected.sizes["realization"] == 1:
        selected = selected.isel(realization=0)
    return selected
