"""Selections of an experiment store by what its grid's values mean: contact-free cases, fixed-base twins.

A gap axis that holds ``inf`` makes *contact-free* cases: their gaps never
close, and by the gap identity their peak closure answers every gap at once
(docs/separation.md). A μ axis that holds :data:`~stochpound.experiment.FIXED_BASE`
makes, for each isolated case, its *fixed-base twin*: the same case with the
sliding base removed. These functions take a store, or any dataset or array
on its grid dimensions (statistics over realizations, say).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TypeVar

import numpy as np
import xarray as xr

from stochpound.experiment.definition import FIXED_BASE, is_fixed_base, is_gap_axis

Data = TypeVar("Data", xr.Dataset, xr.DataArray)


def gap_dims(data: xr.Dataset | xr.DataArray) -> list[str]:
    """The gap axes among the dimensions of ``data``, in grid order (a store's: those of its ``case_status``)."""
    dims = data["case_status"].dims if isinstance(data, xr.Dataset) and "case_status" in data else data.dims
    return [str(d) for d in dims if is_gap_axis(str(d))]


def has_contact_free(data: xr.Dataset | xr.DataArray) -> bool:
    """Whether ``data`` has gap axes and every one of them holds ``inf`` (contact-free cases)."""
    dims = gap_dims(data)
    return bool(dims) and all(np.isinf(data[d].values).any() for d in dims)


def contact_free(data: Data) -> Data:
    """The contact-free cases: ``inf`` on every gap axis, the gap coordinates dropped."""
    return data.sel({d: np.inf for d in gap_dims(data)}, drop=True)


def with_contacts(data: Data) -> Data:
    """``data`` without its contact-free cases: the finite values of every gap axis."""
    return data.sel({d: data[d].values[np.isfinite(data[d].values)] for d in gap_dims(data)})


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
