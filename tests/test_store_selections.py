"""Store selections: contact-free cases and fixed-base twins, on a small store-shaped dataset."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

from stochpound.store import contact_free, fixed_base, gap_dims, has_contact_free, has_fixed_base_twins, isolated_mus, with_contacts


def _store(gaps: list[float], top: list[float]) -> xr.Dataset:
    """Dims in grid order (neighbour, gap_top, gap, mu); ``closure`` = 100·gap + 10·gap_top + μ (finite μ), so every cell is known."""
    coords = {"neighbour": ["stiff", "flexible"], "gap_top": top, "gap": gaps, "mu": [0.1, math.inf]}
    shape = tuple(len(v) for v in coords.values())
    g = np.asarray(gaps)[None, None, :, None]
    t = np.asarray(top)[None, :, None, None]
    closure = np.broadcast_to(100.0 * g + 10.0 * t + np.array([0.1, 0.0]), shape)
    return xr.Dataset(
        {"case_status": (tuple(coords), np.ones(shape, np.int8)), "closure": (("mu", "gap", "gap_top", "neighbour"), closure.transpose(3, 2, 1, 0))},
        coords=coords,
    )


def test_gap_dims_follow_the_grid_order() -> None:
    """A store's gap axes in the order of its case_status (the grid's), not of its other variables."""
    store = _store([0.01, math.inf], [0.02, math.inf])
    assert gap_dims(store) == ["gap_top", "gap"]
    assert gap_dims(store["closure"]) == ["gap", "gap_top"]


@pytest.mark.parametrize(("gaps", "top", "free"), [([0.01, math.inf], [0.02, math.inf], True), ([0.01, math.inf], [0.02], False), ([0.01], [math.inf], False)])
def test_contact_free_needs_inf_on_every_gap_axis(gaps: list[float], top: list[float], free: bool) -> None:
    """Contact-free cases exist only when every gap axis holds inf."""
    assert has_contact_free(_store(gaps, top)) is free


def test_contact_free_and_with_contacts_split_the_grid() -> None:
    """contact_free: inf on every gap axis, gap coordinates dropped; with_contacts: every finite gap, the rest kept."""
    store = _store([0.01, 0.03, math.inf], [0.02, math.inf])
    free = contact_free(store)
    assert "gap" not in free.dims and "gap" not in free.coords and "gap_top" not in free.coords
    assert free["closure"].sizes == {"mu": 2, "neighbour": 2}
    assert np.all(np.isinf(free["closure"].values))
    finite = with_contacts(store)
    assert finite.sizes["gap"] == 2 and finite.sizes["gap_top"] == 1
    np.testing.assert_array_equal(finite["gap"].values, [0.01, 0.03])
    np.testing.assert_allclose(finite["closure"].sel(mu=0.1, neighbour="stiff", gap_top=0.02).values, [1.3, 3.3])
    assert not has_contact_free(_store([0.01], [0.02]))
    assert not gap_dims(xr.Dataset({"x": ("mu", [1.0, 2.0])}, coords={"mu": [0.1, 0.2]}))


def test_fixed_base_twins() -> None:
    """The μ axis's fixed base beside its finite values: the twins, and the finite values in order."""
    store = _store([0.01], [0.02])
    assert has_fixed_base_twins([0.2, math.inf, 0.05]) and not has_fixed_base_twins([0.1, 0.2]) and not has_fixed_base_twins([math.inf])
    assert isolated_mus([0.2, math.inf, 0.05]) == [0.2, 0.05]
    twin = fixed_base(store)
    assert float(twin["mu"]) == math.inf and "mu" not in twin.dims
    np.testing.assert_allclose(twin["closure"].sel(neighbour="stiff").values.ravel(), [1.2])


def test_a_report_value_reads_one_case_of_one_variable_and_a_missing_label_is_nan() -> None:
    """``value`` (the reports' one number) selects its variable alone: the same number as the whole store at the labels, a
    realization of one squeezed; a label the store lacks is a missing case (NaN) even on a dimension the variable does not have,
    as when the whole store was selected."""
    from stochpound.report.sections import value

    store = _store([0.01, 0.02], [0.03]).assign(peak=("neighbour", [1.5, 2.5])).expand_dims(realization=[0])
    assert value(store, "closure", neighbour="flexible", gap_top=0.03, gap=0.02, mu=0.1) == pytest.approx(2.0 + 0.3 + 0.1)
    assert value(store, "peak", scale=2.0, neighbour="flexible", gap=0.02, mu=0.1) == 5.0
    assert math.isnan(value(store, "peak", neighbour="flexible", gap=0.05))
    assert math.isnan(value(store, "closure", neighbour="flexible", gap_top=0.03, gap=0.05, mu=0.1))
    assert math.isnan(value(store, "missing", neighbour="flexible"))
