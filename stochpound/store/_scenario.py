"""The stripes' site scenario as a store keeps it: how it was obtained (the definition's ``site``) and its values (``site_*`` variables)."""

from __future__ import annotations

import numpy as np
import xarray as xr

SCENARIO_KINDS = ("given", "fitted", "ruptures")
"""How a scenario was obtained: as the ``[site]`` table gives it, fitted to the site's hazard curves, or from the site's ruptures
(the exact conditional spectrum's mixture; the stored M and R its means)."""


def scenario_kind(store: xr.Dataset) -> str | None:
    """``"given"``, ``"fitted"`` or ``"ruptures"``: how the store's stripes' scenario was obtained; None for a store without a ``[site]`` table
    (or written before the definition kept it)."""
    site = store.pound.definition.site
    return None if site is None else site.scenario


def scenario_ranges(store: xr.Dataset) -> str | None:
    """The stored scenario's ranges over the stripes, ``"M 7.5–8, R 30 km, Vs30 400 m/s"`` (one value where every stripe has it;
    values rounded to 0.01); None for a store without a scenario (``site_magnitude``)."""
    if "site_magnitude" not in store:
        return None

    def span(name: str) -> str:
        values = np.unique(np.round(store[name].values.astype(float), 2))
        return "–".join(f"{v:g}" for v in (values[0], values[-1])) if values.size > 1 else f"{values[0]:g}"

    return f"M {span('site_magnitude')}, R {span('site_distance_km')} km, Vs30 {span('site_vs30')} m/s"
