"""The motions each stripe of a store ran: which, their earthquakes (one name across suites), the largest share of one
earthquake, the pulse records and the motions shared with the stripe below (what a report's stripe and motion tables list)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

from stochpound.stats import earthquake_identities


def ran_motions(store: xr.Dataset) -> xr.DataArray:
    """Per stripe (``intensity``) and motion (``record``): whether some case of the motion at that stripe ran (a selection runs
    each motion at its own stripes only; the pool's other motions never ran)."""
    done = store["case_status"] == 1
    return done.any([d for d in done.dims if d not in ("intensity", "record")])


def motion_earthquakes(store: xr.Dataset) -> list[str]:
    """Each motion's earthquake, normalised across suites (:func:`~stochpound.motions.records.earthquake_identities`: "Northridge 1994"
    and "Northridge-01 1994" of one magnitude are one); a motion without an event (a simulated one) is its own."""
    names = [str(r) for r in store["record"].values]
    if "record_event" not in store.coords:
        return names
    magnitudes = store["record_magnitude"].values if "record_magnitude" in store.coords else None
    identities = earthquake_identities(store["record_event"].values, magnitudes)
    return [identity or name for identity, name in zip(identities, names)]


def stripe_holdings(store: xr.Dataset) -> pd.DataFrame:
    """Per stripe, what its motions are (the motions that ran there): ``motions``, ``earthquakes`` (normalised), the largest
    share of one earthquake, the pulse records (``unknown`` where the store's metadata do not classify a motion), and the
    motions shared with the stripe below. Indexed by ``intensity``."""
    ran = ran_motions(store).transpose("intensity", "record").values
    earthquakes = np.array(motion_earthquakes(store), dtype=object)
    pulse = store["record_pulse"].values.astype(float) if "record_pulse" in store.coords else np.full(ran.shape[1], np.nan)
    rows = []
    levels = store["intensity"].values
    order = np.argsort(levels)
    for position, j in enumerate(order):
        level, held = levels[j], ran[j]
        names, counts = np.unique(earthquakes[held], return_counts=True)
        largest = _largest_share(names, counts, int(held.sum())) if held.any() else "–"
        known = np.isfinite(pulse[held])
        pulses = f"{int(np.nansum(pulse[held]))}" + (f" of {int(known.sum())} classified" if 0 < known.sum() < held.sum() else "")
        rows.append({"intensity": level, "motions": int(held.sum()), "earthquakes": int(names.size), "largest share of one earthquake": largest,
                     "pulse records": pulses if known.any() else "unknown",
                     "shared with the stripe below": int((held & ran[order[position - 1]]).sum()) if position else "–"})
    return pd.DataFrame(rows).set_index("intensity")


def _largest_share(names: np.ndarray, counts: np.ndarray, motions: int) -> str:
    """``3 of 11 (Northridge-01 1994)``: the most motions of one earthquake in a stripe and which (``each its own`` where no
    earthquake has two; the first and how many more where several tie)."""
    most = int(counts.max())
    if most == 1:
        return f"1 of {motions} (each motion its own earthquake)"
    tied = [str(name) for name, count in zip(names, counts) if count == most]
    return f"{most} of {motions} ({tied[0]}" + (f" and {len(tied) - 1} more" if len(tied) > 1 else "") + ")"


def motions_that_ran(store: xr.Dataset) -> set[str]:
    """The labels of the motions some case of ``store`` ran (the ``record`` labels with a finished case): a selection's pool
    motions it never chose are not among them."""
    done = store["case_status"] == 1
    return {str(label) for label, flag in zip(store["record"].values, done.any([d for d in done.dims if d != "record"]).values) if flag}


def simulated_that_ran(store: xr.Dataset) -> list[str]:
    """The labels of the simulated motions (``[site] simulated_motions`` chosen for some stripe; ``record_kind`` simulated) some
    case of ``store`` ran, in ``record`` order: the definition's motions do not list them (they are drawn for the stripes)."""
    if "record_kind" not in store.coords:
        return []
    ran = motions_that_ran(store)
    return [str(label) for label, kind in zip(store["record"].values, store["record_kind"].values) if kind == "simulated" and str(label) in ran]
