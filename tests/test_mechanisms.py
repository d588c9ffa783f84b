"""Ratcheting and amplification (stochpound.analysis.mechanisms) on synthetic paired runs whose answer is known."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from stochpound.analysis import amplification, ratcheting

N = 40


def _runs(values: np.ndarray, **cells: list) -> xr.DataArray:
    """Per-run values on (cells..., realization)."""
    dims = [*cells, "realization"]
    coords = {**cells, "realization": np.arange(values.shape[-1])}
    return xr.DataArray(values, dims=dims, coords=coords)


@pytest.fixture
def free() -> xr.DataArray:
    """Contact-free residuals, m: symmetric about 0 (no preferred side)."""
    return _runs(np.random.default_rng(1).normal(0.0, 0.05, N))


def test_a_base_pushed_away_from_its_neighbour_ratchets(free):
    pushed = free - 0.08 - np.abs(np.random.default_rng(2).normal(0.0, 0.01, N))  # left of its neighbour: pushed left
    found = ratcheting(pushed.expand_dims(gap=[0.02]), free, away=-1, min_runs=30)
    assert bool(found["ratchets"].sel(gap=0.02)) and not bool(found["lowers"].sel(gap=0.02))
    assert float(found["away_change_lower"].sel(gap=0.02)) > 0.08 > 0 < float(found["abs_change_lower"].sel(gap=0.02))
    np.testing.assert_allclose(float(found["abs_mean"].sel(gap=0.02)), float(np.abs(pushed).mean()), rtol=1e-12)
    # the same runs seen from a building right of its neighbour: pushed toward it, not away: no ratcheting
    assert not bool(ratcheting(pushed.expand_dims(gap=[0.02]), free, away=1, min_runs=30)["ratchets"].sel(gap=0.02))


def test_no_ratcheting_without_a_change_and_a_flip_where_pounding_recentres(free):
    noise = np.random.default_rng(3).normal(0.0, 0.002, N)
    same, recentred = free + noise, 0.2 * free
    found = ratcheting(xr.concat([same, recentred], dim="gap").assign_coords(gap=[0.01, 0.02]), free, away=-1, min_runs=30)
    assert not found["ratchets"].any()
    assert not bool(found["lowers"].sel(gap=0.01)) and bool(found["lowers"].sel(gap=0.02))


def test_too_few_pairs_give_no_estimate_and_no_verdict(free):
    pushed = (free - 0.1).where(free.realization < 20)
    found = ratcheting(pushed.expand_dims(gap=[0.02]), free, away=-1, min_runs=30)
    assert int(found["abs_count"].sel(gap=0.02)) == 20
    assert not bool(found["enough"].sel(gap=0.02)) and not bool(found["ratchets"].sel(gap=0.02))
    assert np.isnan(float(found["abs_change_mean"].sel(gap=0.02)))


def test_bad_arguments_name_the_field(free):
    with pytest.raises(ValueError, match="away: must be -1"):
        ratcheting(free, free, away=0, min_runs=30)
    with pytest.raises(ValueError, match="min_runs: must be at least 2"):
        amplification(free, free, min_runs=1)


def test_amplification_is_the_paired_ratio_with_its_interval():
    rng = np.random.default_rng(4)
    twin = _runs(rng.uniform(1.0, 3.0, N))
    factor = 5.0 * rng.uniform(0.9, 1.1, N)
    found = amplification(xr.concat([twin * factor, twin], dim="moat").assign_coords(moat=["w05", "w10"]), twin, min_runs=30)
    wall = found.sel(moat="w05")
    assert bool(wall["raises"]) and not bool(wall["lowers"])
    np.testing.assert_allclose(float(wall["ratio_mean"]), float(np.mean(factor)), rtol=1e-12)
    np.testing.assert_allclose(float(wall["ratio_of_means"]), float((twin * factor).mean() / twin.mean()), rtol=1e-12)
    assert float(wall["ratio_lower"]) < float(np.mean(factor)) < float(wall["ratio_upper"])
    same = found.sel(moat="w10")
    assert not bool(same["raises"]) and not bool(same["lowers"]) and float(same["ratio_mean"]) == 1.0


def test_runs_equal_to_their_twins_but_for_rounding_show_no_mechanism(free):
    """A cell whose runs never touch equals its twin to the last bits: neither ratcheting nor a change of demand."""
    rounded = free * (1.0 - 1e-15)
    assert not ratcheting(rounded, free, away=-1, min_runs=30)[["ratchets", "lowers"]].to_array().any()
    twin = _runs(np.random.default_rng(8).uniform(2.0, 4.0, N))
    assert not amplification(twin * (1.0 - 1e-15), twin, min_runs=30)[["raises", "lowers"]].to_array().any()
