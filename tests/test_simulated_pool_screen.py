"""The pool of simulated motions made fast (issue 43): its spectra in one compiled call per batch, equal to the old path bit for bit,
and the pre-screen of a pool larger than ``SCREEN_BASE``: it keeps every motion beyond its threshold, whatever the threads, and
chooses as the full pool does where the full pool's choices lie beyond it."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from stochpound.experiment import _stripe_pools
from stochpound.motions import (
    Scenario, conditional_spectrum, response_spectrum, scenario_distribution, select_motions, selection_pool, site_model_provenance, site_motions,
)  # fmt: skip
from stochpound.motions import _site_model
from stochpound.motions._selection import array_pool, pool_intensity
from stochpound.motions._spectrum import pseudo_spectra
from stochpound.motions.records import Record, load_record

SCENARIO = Scenario(6.5, 20.0, 400.0, "strike_slip")
PERIODS = np.geomspace(0.05, 3.0, 12)
G = 9.81
TABLE = {"type": "site_motions", "magnitude": 6.5, "distance_km": 20.0, "vs30": 400.0, "mechanism": "strike_slip", "n": 48, "seed": 5,
         "dt": 0.01, "model": "hazard_compatible", "calibration": site_model_provenance("hazard_compatible")}


@pytest.fixture(scope="module")
def motions() -> np.ndarray:
    return site_motions(scenario=SCENARIO, n=6, seed=3, duration=20.0)["acceleration"].values


def test_the_batched_spectra_are_response_spectrum_s_bit_for_bit(motions):
    """Simulated motions and a record's first 20 s: pseudo_spectra's PSA is response_spectrum's, every bit (the same recurrence and
    located maxima, the total acceleration's left out)."""
    record = load_record("el_centro_1940_ngaw2_rsn6").acceleration(G)[: motions.shape[1]]
    rows = np.vstack([motions, record])
    expected = np.array([response_spectrum(row, 0.01, PERIODS).psa.values for row in rows])
    np.testing.assert_array_equal(pseudo_spectra(rows, 0.01, PERIODS), expected)


@pytest.mark.parametrize("measure, period", [("psa", 1.0), ("pga", None), ("sa_avg", [0.2, 0.5, 1.0, 2.0])])
def test_the_array_pool_is_the_records_pool_bit_for_bit(motions, measure, period):
    """array_pool gives selection_pool's dataset of the same motions as records (their names as earthquakes), identical."""
    names = [f"m{i}" for i in range(len(motions))]
    records = [Record(name, 0.01, row, "m/s2", metadata={"magnitude": 6.5, "distance": 20.0, "vs30": 400.0, "event": name})
               for name, row in zip(names, motions)]
    expected = selection_pool(records, PERIODS, measure, period, 0.05, G)
    xr.testing.assert_identical(array_pool(motions, 0.01, names, PERIODS, measure, period, 0.05, G, magnitude=6.5, distance_km=20.0, vs30=400.0),
                                expected)


@pytest.fixture(scope="module")
def full_pool() -> xr.Dataset:
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(_stripe_pools, "SIMULATED_CHUNK", 16)
        return _stripe_pools.simulated_pool(TABLE, PERIODS, "psa", 1.0, G)


def _screened(monkeypatch, screen: float, threads: int = 1) -> xr.Dataset:
    monkeypatch.setattr(_stripe_pools, "SIMULATED_CHUNK", 16)
    monkeypatch.setattr(_stripe_pools, "SCREEN_BASE", 12)
    monkeypatch.setattr(_site_model, "motion_threads", lambda: threads)
    return _stripe_pools.simulated_pool(TABLE, PERIODS, "psa", 1.0, G, screen)


def test_the_pool_is_every_motion_of_the_table_with_its_realization(full_pool):
    """Chunk by chunk, the pool holds the table's n motions in order, each the spectrum of the motion its realization regenerates."""
    assert full_pool["motion"].values.tolist() == [str(i) for i in range(TABLE["n"])]
    again = _stripe_pools.table_accelerations(TABLE, [7, 30])
    np.testing.assert_array_equal(full_pool["psa"].values[[7, 30]], pseudo_spectra(again, 0.01, PERIODS) / G)
    np.testing.assert_array_equal(full_pool["intensity"].values[[7, 30]], pool_intensity(again, 0.01, "psa", 1.0, 0.05, G))


def test_a_table_of_another_calibration_is_refused_not_regenerated_with_this_one():
    """A store's table names the calibration its motions came from; another calibration's motions are not given in their place."""
    from stochpound import SiteError

    unnamed = {key: value for key, value in TABLE.items() if key != "calibration"}
    np.testing.assert_array_equal(_stripe_pools.table_accelerations(TABLE, [3]), _stripe_pools.table_accelerations(unnamed, [3]))
    stale = "rezaeian_der_kiureghian_2010 + nga_west2_calibration_3"
    with pytest.raises(SiteError, match=r"^calibration: 'rezaeian_der_kiureghian_2010 \+ nga_west2_calibration_3' is not the calibration of model"):
        _stripe_pools.table_accelerations({**TABLE, "calibration": stale}, [3])


def test_the_screen_keeps_the_first_motions_and_every_one_beyond_its_level(monkeypatch, full_pool):
    """Beyond SCREEN_BASE (here 12) exactly the motions whose conditioning measure reaches the screen join, with the full pool's
    values; the same on 1 and 2 threads."""
    intensity = full_pool["intensity"].values
    screen = float(np.quantile(intensity[12:], 0.7))
    expected = [i for i in range(TABLE["n"]) if i < 12 or intensity[i] >= screen]
    assert 12 < len(expected) < TABLE["n"]
    screened = _screened(monkeypatch, screen)
    xr.testing.assert_identical(screened, full_pool.isel(motion=expected))
    xr.testing.assert_identical(_screened(monkeypatch, screen, threads=2), screened)


def test_the_screen_level_is_the_top_stripe_s_epsilon_less_the_margin(monkeypatch):
    """A motion of the scenario joins iff its own ε, (ln IM − ln median)/σ in the scenario's model, is at least the top stripe's ε
    less SCREEN_MARGIN; pools of at most SCREEN_BASE motions are not screened; stripes of another scenario do not count."""
    from stochpound.store import SimulatedMotions

    median, sigma = scenario_distribution("psa", 1.0, scenario=SCENARIO)
    other = Scenario(7.5, 20.0, 400.0, "strike_slip")
    scenarios = [SCENARIO, SCENARIO, other]
    targets = [conditional_spectrum("psa", 1.0, level=level, periods=PERIODS, scenario=scenario)
               for level, scenario in zip((median * 2.0, median * 4.0, median * 20.0), scenarios)]
    top = float(targets[1].attrs["epsilon"])
    assert top > float(targets[0].attrs["epsilon"])
    big = SimulatedMotions(_stripe_pools.SCREEN_BASE + 1, "hazard_compatible", "any", 1, 0.01)
    level = _stripe_pools.screen_level(big, 0, scenarios, targets, "psa", 1.0)
    assert np.log(level / median) / sigma == pytest.approx(top - _stripe_pools.SCREEN_MARGIN, abs=1e-12)
    assert _stripe_pools.screen_level(big, 1, scenarios, targets, "psa", 1.0) == level
    assert _stripe_pools.screen_level(SimulatedMotions(_stripe_pools.SCREEN_BASE, "hazard_compatible", "any", 1, 0.01), 0, scenarios, targets, "psa", 1.0) is None


def test_the_screened_pool_chooses_as_the_full_pool_where_its_choices_lie_beyond_the_screen(monkeypatch, full_pool):
    """A stripe at a high level: the full pool's chosen motions beyond SCREEN_BASE all reach the screen (the least of their measures),
    and the screened pool, which leaves out motions below it, chooses the same motions at the same scale factors (in another
    order where a draw's nearest motion was screened out: the swaps end at the same set)."""
    intensity = full_pool["intensity"].values
    target = conditional_spectrum("psa", 1.0, level=float(np.quantile(intensity, 0.9)), periods=PERIODS, scenario=SCENARIO)
    full = select_motions(full_pool, target, 6, 4.0, seed=3)
    picked = [int(m) for m in full["motion"].values]
    beyond = [i for i in picked if i >= 12]
    assert beyond
    screen = float(min(intensity[beyond]))
    screened_pool = _screened(monkeypatch, screen)
    assert screened_pool.sizes["motion"] < full_pool.sizes["motion"]
    screened = select_motions(screened_pool, target, 6, 4.0, seed=3)
    def chosen(selection):  # a stripe's motions are a set (their order is the draws' and changes nothing)
        return sorted(zip(selection["motion"].values.tolist(), selection["scale_factor"].values.tolist()))

    assert chosen(screened) == chosen(full)


def test_an_experiment_s_stripes_select_from_the_screened_pool(tmp_path, monkeypatch):
    """An experiment of one scenario with more simulated motions than SCREEN_BASE (here 6 of 16): every stripe's pool is the records,
    the first 6 motions and those of the 16 whose own ε reaches the top stripe's less SCREEN_MARGIN, counted independently."""
    from stochpound.experiment._runner import load_experiment
    from tests.helpers import SITE_SCENE, write_experiment

    monkeypatch.setattr(_stripe_pools, "SCREEN_BASE", 6)
    monkeypatch.setattr(_stripe_pools, "SCREEN_MARGIN", 0.5)
    records = "".join(f'\n[[records]]\nrecord = "fema_p695_far_field/{i:02d}{c}"\nduration = 5.0\n' for i in (1, 2) for c in "ab")
    intensity = ('[intensity]\nmeasure = "psa"\nperiod = 0.5\nlevels = [0.3, 0.1]\nselection = "conditional_spectrum"\nmotions = 4\n'
                 'max_scale_factor = 5.0\nseed = 2\n')
    site = '[site]\nvs30 = 400.0\nmagnitude = 7.0\ndistance_km = 20.0\nmechanism = "strike_slip"\nsimulated_motions = 16\n'
    text = f'[experiment]\nname = "screen"\n{SITE_SCENE}\n[grid]\ngap = ["inf"]\n{records}\n{intensity}\n{site}\n[solver]\nmethod = "exact"\n'
    selection = load_experiment(write_experiment(tmp_path, text, "screen.toml")).selection
    scenario = Scenario(7.0, 20.0, 400.0, "strike_slip")
    median, sigma = scenario_distribution("psa", 0.5, scenario=scenario)
    top = max(float(target.attrs["epsilon"]) for target in selection.targets)
    table = {**TABLE, "magnitude": 7.0, "n": 16, "seed": 2}
    own = np.log(pool_intensity(_stripe_pools.table_accelerations(table, range(16)), 0.01, "psa", 0.5, 0.05, G) / median) / sigma
    kept = 6 + int(np.sum(own[6:] >= top - 0.5))
    assert 6 < kept < 16  # the screen leaves some out and keeps some
    assert all(chosen.attrs["pool"] == 4 + kept for chosen in selection.selections)
