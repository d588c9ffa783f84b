"""Selecting an experiment store's intensity stripes for the risk chain.

A store with intensity stripes holds, per case, ``peak_contact_closure``
over the grid's dimensions (``gap``, ``mu``, variants, ``record``,
``intensity``) and ``contact``; its contact-free cases are those at
``gap = inf``. By the gap identity, their largest closure over the contacts
decides pounding at every gap, so the pounding fragility of every gap and
configuration comes from that one selection.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import xarray as xr

from stochpound.analysis.fragility_ensemble import BOOTSTRAP, limit_state_events, stripe_fragility

CLOSURE = "peak_contact_closure"
"""The store's variable of per-case, per-contact peak closures (m)."""


def contact_free_closure(store: xr.Dataset, contact_dim: str = "contact", gap_dim: str = "gap") -> xr.DataArray:
    """The largest peak closure over the contacts of every contact-free case (``gap = inf``) of a store (m)."""
    if CLOSURE not in store:
        raise ValueError(f"store: has no {CLOSURE!r}")
    closure = store[CLOSURE]
    if gap_dim in closure.dims:
        gaps = np.asarray(closure[gap_dim].values, dtype=float)
        if not np.isinf(gaps).any():
            raise ValueError(f"store: no contact-free cases ({gap_dim} = inf) on its {gap_dim!r} axis: add inf to the gaps")
        closure = closure.sel({gap_dim: np.inf})
    if contact_dim in closure.dims:
        closure = closure.max(contact_dim, skipna=False)
    return closure.assign_attrs(units="m", long_name="largest contact-free peak closure over the contacts")


def pounding_fragility(store: xr.Dataset, gaps: Sequence[float] | np.ndarray, intensity_dim: str = "intensity", record_dim: str = "record",
                       confidence: float = 0.95, bootstrap: int = BOOTSTRAP, seed: int = 0) -> xr.Dataset:
    """The stripes' pounding fragility at every gap of ``gaps`` (m) and every configuration of a store.

    Returns
    -------
    xarray.Dataset
        :func:`~stochpound.analysis.stripe_fragility` over
        ``gap`` (the given gaps) and the store's other grid dimensions.
    """
    events = limit_state_events(contact_free_closure(store), gaps, "gap")
    return stripe_fragility(events, intensity_dim, record_dim, confidence, bootstrap, seed)
