"""How a store's stripes got their motions, in words read off the store: one suite scaled to every level, or a selection per stripe."""

from __future__ import annotations


import numpy as np
import xarray as xr

from stochpound._plurals import counted
from stochpound.store import Intensity, scenario_ranges


def is_selected(setting: Intensity | None) -> bool:
    """Whether the intensity setting chooses motions per stripe (``selection``) rather than scaling every motion to every level."""
    return setting is not None and setting.selection_method != "scale"


def stripe_motions_text(store: xr.Dataset) -> str:
    """The motions of the stripes: ``"100 motions, each scaled to every level"``, or the selection's method, pool, motions per stripe, scale factors and scenario."""
    pool = store.sizes["record"]
    if "selection_scale_factor" not in store:
        return f"{counted(pool, 'motion')}, each scaled to every level"
    scale = store["selection_scale_factor"].transpose("intensity", "record").values
    per_stripe = np.isfinite(scale).sum(axis=1)
    count = counted(int(per_stripe.min()), "motion") if per_stripe.min() == per_stripe.max() else f"{per_stripe.min()}–{per_stripe.max()} motions"
    selection = store.pound.intensity.selection if store.pound.intensity is not None else None
    method = (selection.method if selection is not None else "a selection").replace("_", "-")
    if selection is not None and selection.simulated is not None:  # the record axis holds the chosen simulated motions only
        pool = f"{int(np.sum(store['record_kind'].values != 'simulated'))} records and {selection.simulated.pool_words}"
    text = (f"{count} per stripe, chosen by {method} selection from a pool of {pool} and scaled to the stripe's level "
            f"(scale factors {np.nanmin(scale):.3g}–{np.nanmax(scale):.3g})")
    ranges = scenario_ranges(store)
    return text if ranges is None else f"{text}; target scenario {ranges}"
