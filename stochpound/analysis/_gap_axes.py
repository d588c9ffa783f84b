"""The gap axes of a store's grid and its contact-free cases: the one rule for both, below the experiment layer.

A grid axis is a gap axis when its name is ``gap`` or ``gap_<name>``
(:func:`is_gap_axis`). A gap axis that holds ``inf`` makes *contact-free*
cases: their gaps never close, and by the gap identity their peak closure
answers every gap at once (docs/separation.md). The risk chain of
``stochpound.analysis`` and the experiment layer
(``stochpound.experiment._selections``, the definition's parser, the reports)
select them with these functions. They take a store, or any dataset or array
on its grid dimensions (statistics over realizations, say).
"""

from __future__ import annotations

import re
from typing import TypeVar

import numpy as np
import xarray as xr

Data = TypeVar("Data", xr.Dataset, xr.DataArray)

_GAP_AXIS = re.compile(r"^gap(_[A-Za-z0-9_]+)?$")


def is_gap_axis(name: str) -> bool:
    """Whether a grid axis (a store dimension) is a gap axis: ``gap`` or ``gap_<name>`` (letters, digits, _)."""
    return _GAP_AXIS.match(name) is not None


def gap_dims(data: xr.Dataset | xr.DataArray) -> list[str]:
    """The gap axes among the dimensions of ``data``, in grid order (a store's: those of its ``case_status``)."""
    dims = data["case_status"].dims if isinstance(data, xr.Dataset) and "case_status" in data else data.dims
    return [str(d) for d in dims if is_gap_axis(str(d))]


def has_contact_free(data: xr.Dataset | xr.DataArray) -> bool:
    """Whether ``data`` has gap axes and every one of them holds ``inf`` (contact-free cases)."""
    dims = gap_dims(data)
    return bool(dims) and all(np.isinf(data[d].values).any() for d in dims)


def contact_free(data: Data) -> Data:
    """The contact-free cases: ``inf`` on every gap axis, the gap coordinates dropped (``data`` itself without gap axes)."""
    return data.sel({d: np.inf for d in gap_dims(data)}, drop=True)


def with_contacts(data: Data) -> Data:
    """``data`` without its contact-free cases: the finite values of every gap axis."""
    return data.sel({d: data[d].values[np.isfinite(data[d].values)] for d in gap_dims(data)})
