"""How far a store's runs went: its cases done of its cases, and the refusal to answer from an unfinished store as if it were whole.

A store written while its experiment runs (or after a run that was stopped
or had cases fail) holds only the cases that finished; its statistics would
count the missing ones as if they did not exist, silently. The commands
that answer from a store (``stochpound risk``, ``stochpound report build``)
refuse such a store unless asked to answer from the cases that ran.
"""

from __future__ import annotations

import xarray as xr

from stochpound._errors import StochpoundError


class UnfinishedStoreError(StochpoundError, ValueError):
    """A store with missing cases was given where a whole one is needed; the message says how many ran and what to do."""


def cases_done(store: xr.Dataset) -> tuple[int, int]:
    """The cases a store holds finished and its experiment's cases (case and reference cases), from its provenance attributes.

    A store without them (written by hand) counts its ``case_status`` and
    ``reference_status`` flags (1 done, 0 missing).
    """
    if "cases_done" in store.attrs and "cases_total" in store.attrs:
        return int(store.attrs["cases_done"]), int(store.attrs["cases_total"])
    flags = [store[name] for name in ("case_status", "reference_status") if name in store]
    return sum(int((flag == 1).sum()) for flag in flags), sum(int((flag >= 0).sum()) for flag in flags)


def check_finished(store: xr.Dataset, name: str, partial: bool, option: str = "--partial") -> None:
    """Refuse a store with missing cases unless ``partial``.

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store.
    name : str
        The store in the message (its file or experiment name).
    partial : bool
        Answer from the cases that ran: no error.
    option : str
        How the caller asks for ``partial``, in the message (``--partial`` or ``partial=True``).

    Raises
    ------
    UnfinishedStoreError
        ``<name>: 288/704 cases done: ...``, saying how to finish it or to pass ``option``.
    """
    done, total = cases_done(store)
    if done < total and not partial:
        raise UnfinishedStoreError(f"{name}: {done}/{total} cases done: an answer from it would take the cases that ran for the whole "
                                   f"experiment; finish it (run the experiment again: it runs the missing cases) or pass {option} to "
                                   f"answer from the {done} cases that ran")
