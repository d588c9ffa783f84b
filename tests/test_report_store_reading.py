"""A report's reading of one value of a store (stochpound.report.sections._store_reading.value): each variable is read into
memory once per store, and the numbers are those of the store at the labels, whichever stores were read before."""

from __future__ import annotations

import gc
from collections import OrderedDict

import numpy as np
import pytest
import xarray as xr

from stochpound._errors import StochpoundError
from stochpound.report.sections import _store_reading
from stochpound.report.sections._store_reading import value


def _store(offset: float) -> xr.Dataset:
    """A store-like dataset: a summary over gap and mu, lazily on dask (as open_store gives it)."""
    values = offset + np.arange(6.0).reshape(2, 3)
    return xr.Dataset({"peak": (("gap", "mu"), values)}, coords={"gap": [0.01, 0.02], "mu": [0.1, 0.2, 0.3]}).chunk({"gap": 1})


@pytest.fixture(autouse=True)
def no_store_read_before(monkeypatch):
    """Each test starts with no variable read (the cache is the module's, shared by every report of a process)."""
    monkeypatch.setattr(_store_reading, "_READ", OrderedDict())


def test_a_variable_is_read_once_per_store_and_gives_the_store_s_own_numbers():
    for offset in (0.0, 100.0, 200.0, 300.0, 400.0, 500.0):  # more stores than are kept; a store's id may be a collected one's
        store = _store(offset)
        assert value(store, "peak", gap=0.02, mu=0.3) == offset + 5.0
        assert value(store, "peak", 2.0, gap=0.01, mu=0.2) == 2.0 * (offset + 1.0)
        kept = _store_reading._READ[id(store)]
        assert kept[0]() is store and isinstance(kept[1]["peak"].data, np.ndarray)  # in memory, not dask
        del store, kept
        gc.collect()
        assert all(reference() is None for reference, _ in _store_reading._READ.values())  # the cache keeps no store alive
    assert len(_store_reading._READ) <= _store_reading._READ_STORES
    assert np.isnan(value(_store(0.0), "peak", gap=0.05, mu=0.3)) and np.isnan(value(_store(0.0), "missing", gap=0.01, mu=0.1))


def test_a_variable_larger_than_the_limit_is_read_at_the_case_only(monkeypatch):
    monkeypatch.setattr(_store_reading, "_READ_MAX_VALUES", 5)
    store = _store(10.0)
    assert value(store, "peak", gap=0.02, mu=0.1) == 13.0
    assert id(store) not in _store_reading._READ
    with pytest.raises(StochpoundError, match="6 values, expected one"):
        value(store, "peak")
