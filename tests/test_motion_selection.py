"""Selection and scaling of the FEMA P695 records to conditional spectra (Jayaram, Lin & Baker 2011)."""

from __future__ import annotations

import numpy as np
import pytest

from stochpound import SiteError
from stochpound.motions import conditional_spectrum, select_motions, selection_periods, selection_pool
from stochpound.motions.records import load_suite

PERIODS = selection_periods([0.5, 1.2, 3.0], [1.0])  # a pair of 0.5 and 1.2 s, isolated at 3 s; T* = 1 s


@pytest.fixture(scope="module")
def pool():
    records = load_suite("fema_p695_far_field") + load_suite("fema_p695_near_field")
    return selection_pool(records, PERIODS, "psa", 1.0)


def target(level: float, magnitude: float, distance_km: float):
    return conditional_spectrum("psa", 1.0, level=level, periods=PERIODS, magnitude=magnitude, distance_km=distance_km, vs30=400.0, mechanism="strike_slip")


def test_the_range_covers_the_structure() -> None:
    assert PERIODS[0] == pytest.approx(0.1) and PERIODS[-1] == pytest.approx(9.0) and 1.0 in PERIODS


def test_the_pool_has_the_p695_metadata(pool) -> None:
    assert pool.sizes["motion"] == 100
    assert set(pool["mechanism"].values) == {"strike_slip", "reverse", "normal"}
    assert np.all(np.isfinite(pool["magnitude"])) and np.all(np.isfinite(pool["vs30"]))
    assert np.allclose(pool["psa"].sel(period=1.0), pool["intensity"])  # T* among the periods


@pytest.mark.parametrize("level, magnitude, distance_km, motions", [(0.1, 6.5, 30.0, 20), (0.3, 7.0, 15.0, 20), (0.8, 7.3, 10.0, 30), (0.3, 7.0, 15.0, 11)])
def test_the_selected_set_matches_the_target_mean_and_std(pool, level: float, magnitude: float, distance_km: float, motions: int) -> None:
    cs = target(level, magnitude, distance_km)
    selection = select_motions(pool, cs, motions, max_scale_factor=4.0, seed=3)
    chosen = pool.sel(motion=selection["motion"].values)
    scale = level / chosen["intensity"].values
    assert np.allclose(selection["scale_factor"], scale) and np.all(scale <= 4.0)
    assert len(set(selection["motion"].values)) == motions
    ln_sa = np.log(chosen["psa"].values * scale[:, None])  # recomputed from the pool, not read back
    assert np.max(np.abs(ln_sa.mean(axis=0) - np.log(cs["median"].values))) < 0.1
    assert np.max(np.abs(ln_sa.std(axis=0, ddof=1) - cs["sigma_ln"].values)) < 0.1
    assert np.allclose(ln_sa[:, list(PERIODS).index(1.0)], np.log(level))


def test_the_same_seed_gives_the_same_selection(pool) -> None:
    cs = target(0.3, 7.0, 15.0)
    first, again, other = (select_motions(pool, cs, 15, 4.0, seed=seed) for seed in (5, 5, 6))
    assert list(first["motion"].values) == list(again["motion"].values)
    assert np.array_equal(first["scale_factor"].values, again["scale_factor"].values)
    assert list(first["motion"].values) != list(other["motion"].values)


@pytest.mark.parametrize(
    "arguments, field",
    [({"motions": 60, "max_scale_factor": 1.5}, "motions"), ({"motions": 1}, "motions"), ({"max_scale_factor": 0.5}, "max_scale_factor")],
)
def test_bad_input_is_one_line_naming_the_field(pool, arguments: dict, field: str) -> None:
    with pytest.raises(SiteError) as error:
        select_motions(pool, target(0.8, 7.3, 10.0), **({"motions": 10, "max_scale_factor": 4.0} | arguments))
    assert str(error.value).startswith(f"{field}:") and "\n" not in str(error.value)
