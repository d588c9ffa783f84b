"""The cases of a store's records (one realization each): in how many of them each record made the buildings pound."""

from __future__ import annotations

from dataclasses import dataclass

import xarray as xr


@dataclass(frozen=True)
class RecordPounding:
    """Per record: the cases that ran (``done``) and those among them with at least one impact (``pounded``), in record order."""

    records: list[str]
    pounded: list[int]
    done: list[int]

    @classmethod
    def of(cls, store: xr.Dataset, records: list[str]) -> RecordPounding:
        """From a store's ``impacts`` and ``case_status`` (1: done) at the first realization of each record of ``records``."""
        impacts = store["impacts"].sel(record=records).isel(realization=0)
        done = store["case_status"].sel(record=records).isel(realization=0) == 1
        return cls(list(records), [int(((impacts.sel(record=label) > 0) & done.sel(record=label)).sum()) for label in records],
                   [int(done.sel(record=label).sum()) for label in records])
