"""The answer without an intensity measure (stochpound.analysis.measure_free_risk): λ(D > x) = Σ_r ν_r P(D > x | r) from simulated motions.

Checked against an independent integration of a linear pair of oscillators under the same motions (each run's closure and the
sum over the ruptures by hand), the level at a target rate against its definition, the bootstrap interval's coverage against a
known truth, the allocation of the extra runs, reproducibility whatever the batches, and one-line errors naming the field.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import brentq
from scipy.special import ndtr

import stochpound
from stochpound._errors import SiteError
from stochpound.analysis import RuptureSite, measure_free_risk, rate_from_probability, rate_weighted_levels
from stochpound.analysis import _measure_free
from stochpound.motions import site_motions

STIFFNESS = {"A": 4.0e7, "B": 1.0e7}  # N/m: periods 0.31 s and 0.63 s with 1e5 kg
MASS, DAMPING = 1.0e5, 0.05


def linear_pair(gap: float = math.inf) -> stochpound.Scene:
    """Two one-storey linear buildings, A left of B, one contact."""
    return stochpound.scene_from_dict({
        "g": 9.81,
        "building": [{"name": name, "mass": [MASS], "stiffness": [k], "damping_ratio": DAMPING} for name, k in STIFFNESS.items()],
        "contact": [{"between": [["A", 1], ["B", 1]], "gap": gap, "stiffness": 1.0e8, "restitution": 0.5}],
        "motion": {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 0.5},
    })


def two_ruptures(magnitude: float = 6.0) -> RuptureSite:
    return RuptureSite(magnitude=(7.0, magnitude), distance_rup_km=(20.0, 10.0), distance_jb_km=(20.0, 10.0), distance_x_km=(-20.0, -10.0),
                       ztor_km=(0.0, 0.0), dip=(90.0, 90.0), mechanism=("strike_slip", "reverse"), rate=(0.01, 0.05), vs30=400.0)


def oscillator_displacements(acceleration: np.ndarray, dt: float, stiffness: float) -> np.ndarray:
    """u at the samples of ü + 2ζωu̇ + ω²u = −a_g from rest, a_g linear between samples: the exact discretisation (matrix exponential)."""
    omega = math.sqrt(stiffness / MASS)
    system = np.zeros((4, 4))
    system[:2, :2] = ((0.0, 1.0), (-omega**2, -2.0 * DAMPING * omega))
    system[:2, 2], system[2, 3] = (0.0, -1.0), 1.0  # state (u, v, a_g, da_g/dt)
    step = expm(system * dt)
    u = np.zeros((acceleration.shape[0], acceleration.shape[1]))
    state = np.zeros((acceleration.shape[0], 2))
    for k in range(acceleration.shape[1] - 1):
        slope = (acceleration[:, k + 1] - acceleration[:, k]) / dt
        state = state @ step[:2, :2].T + acceleration[:, k, None] * step[:2, 2] + slope[:, None] * step[:2, 3]
        u[:, k + 1] = state[:, 0]
    return u


@pytest.fixture(scope="module")
def pair_result():
    return measure_free_risk(linear_pair(), two_ruptures(), motions=6, extra=4, seed=5, bootstrap=200)


def test_every_run_and_the_sum_over_ruptures_agree_with_an_independent_integration(pair_result):
    """The same motions (site_motions of each rupture's seed and window) through an exact linear recursion: each run's closure, and
    λ(x) = Σ_r ν_r #{D > x}/n_r by hand at thresholds no run lies near."""
    result, site = pair_result, two_ruptures()
    closures = []
    for r in range(len(site)):
        n = int(result.motions[r])
        motions = site_motions(float(result.magnitude[r]), float(result.distance_km[r]), site.vs30, str(result.mechanism.values[r]), n=6 + 4,
                               seed=int(result.motion_seed[r]), duration=float(result.motion_duration[r]), realizations=list(range(n)))
        a = motions["acceleration"].values
        closure = (oscillator_displacements(a, 0.01, STIFFNESS["A"]) - oscillator_displacements(a, 0.01, STIFFNESS["B"])).max(axis=1)
        solver = result.response_value.values[r, :n]
        assert np.all(solver >= closure * (1 - 1e-9)) and np.allclose(solver, closure, rtol=0.01), (solver, closure)  # the peak lies between samples
        closures.append(closure)
    everything = np.sort(np.concatenate(closures))
    middles = (everything[:-1] + everything[1:]) / 2.0
    middles = middles[np.diff(everything) > 0.03 * everything[1:]]  # clear of every run by 1.5 %
    assert middles.size >= 3
    by_hand = sum(site.rate[r] * np.mean(closures[r][:, None] > middles, axis=0) for r in range(len(site)))
    again = measure_free_risk(linear_pair(), site, motions=6, extra=4, seed=5, bootstrap=200, thresholds=middles)
    np.testing.assert_allclose(again.rate_of_exceedance.values, by_hand, rtol=1e-12)
    np.testing.assert_allclose(again.exceedance_probability.values, [np.mean(c[:, None] > middles, axis=0) for c in closures])


def test_the_level_is_the_smallest_response_whose_rate_meets_the_target(pair_result):
    result = pair_result
    values = result.response_value.values
    weights = result.rate.values[:, None] / result.motions.values[:, None]
    np.testing.assert_allclose(result.target_rate.values, rate_from_probability([0.10, 0.02], 50.0))
    for level, target in zip(result.level.values, result.target_rate.values):
        rate_at = float(np.nansum(np.where(values > level, weights, 0.0)))
        rate_below = float(np.nansum(np.where(values >= level, weights, 0.0)))
        assert rate_at <= target < rate_below
        assert result.level_lower.values.min() <= level <= result.level_upper.values.max()
    assert result.attrs["runs"] == 2 * 6 + 4 == int(result.motions.sum())


def test_rate_weighted_levels_is_where_the_weights_summed_from_the_largest_first_exceed_the_target(pair_result):
    """Two ruptures, ν 0.2 on 2 runs and 0.3 on 3: the runs' weights 0.1 (0.9, 0.3) and 0.1 (0.5, 0.1, 0.7), summed from the largest
    0.1, 0.2, 0.3, 0.4, 0.5; and the estimator's own levels are this function's on its runs."""
    values, rates = [np.array([0.9, 0.3]), np.array([0.5, 0.1, 0.7])], [0.2, 0.3]
    np.testing.assert_array_equal(rate_weighted_levels(values, rates, [0.05, 0.15, 0.25, 0.45, 0.5, 0.6]), [0.9, 0.7, 0.5, 0.1, 0.0, 0.0])
    result = pair_result
    runs = [row[np.isfinite(row)] for row in result.response_value.values]
    np.testing.assert_array_equal(rate_weighted_levels(runs, result.rate.values, result.target_rate.values), result.level.values)


def test_the_same_seed_gives_the_same_result_whatever_the_batches(pair_result, monkeypatch):
    monkeypatch.setattr(_measure_free, "CHUNK", 4)
    again = measure_free_risk(linear_pair(), two_ruptures(), motions=6, extra=4, seed=5, bootstrap=200)
    for name in ("response_value", "rate_of_exceedance", "rate_lower", "level", "level_upper", "motion_seed"):
        np.testing.assert_array_equal(again[name].values, pair_result[name].values)
    other = measure_free_risk(linear_pair(), two_ruptures(), motions=6, seed=6, bootstrap=200)
    assert not np.array_equal(other.response_value.values[:, :6], pair_result.response_value.values[:, :6])


@pytest.mark.slow
def test_two_worker_processes_give_the_same_runs(pair_result):
    again = measure_free_risk(linear_pair(), two_ruptures(), motions=6, extra=4, seed=5, bootstrap=200, workers=2)
    np.testing.assert_array_equal(again.response_value.values, pair_result.response_value.values)
    np.testing.assert_array_equal(again.level.values, pair_result.level.values)


def test_neyman_allocation_sends_the_extra_runs_where_the_rate_is_carried():
    rng = np.random.default_rng(0)
    carrying, quiet = rng.lognormal(np.log(0.05), 0.5, 40), rng.lognormal(np.log(0.005), 0.5, 40)
    counts = _measure_free.neyman_allocation([carrying, quiet], np.array([0.01, 0.01]), 2.0e-3, 101)
    assert counts.sum() == 101 and counts[1] <= 1  # the quiet one's lognormal puts almost nothing beyond the level
    # two alike ruptures, one twice as frequent: twice the runs (n_r ∝ ν_r at equal p_r)
    counts = _measure_free.neyman_allocation([carrying, carrying.copy()], np.array([0.02, 0.01]), 2.0e-3, 90)
    assert counts.tolist() == [60, 30]


def test_the_bootstrap_intervals_cover_a_known_truth():
    """Three lognormal strata of 60 runs, λ(x) = Σ ν_r Φc((ln x − μ_r)/σ_r) exactly: the 95 % intervals of λ at a level and of the
    level at the 10 %/50 yr rate cover the truth in about 95 % of 150 repeats."""
    rates, mu, sigma = np.array([0.01, 0.002, 0.05]), np.log([0.05, 0.08, 0.01]), np.array([0.5, 0.4, 0.6])
    target = float(rate_from_probability(0.10, 50.0))

    def exact(x: float) -> float:
        return float(np.sum(rates * ndtr(-(math.log(x) - mu) / sigma)))

    truth = brentq(lambda x: exact(x) - target, 1e-4, 10.0)
    rate_hits = level_hits = 0
    repeats = 150
    for repeat in range(repeats):
        rng = np.random.default_rng(repeat)
        values = [rng.lognormal(m, s, 60) for m, s in zip(mu, sigma)]
        estimate = _measure_free._estimate(values, rates, np.array([target]), [truth], 0.95, 400, repeat, np.zeros(3, bool))
        rate_hits += estimate.rate_interval[0][0] <= target <= estimate.rate_interval[1][0]
        level_hits += estimate.level_interval[0][0] <= truth <= estimate.level_interval[1][0]
    assert 0.88 <= rate_hits / repeats <= 0.99 and 0.88 <= level_hits / repeats <= 0.99, (rate_hits, level_hits)


def test_a_rupture_outside_the_model_is_refused_in_one_line_or_clamped_and_given_apart():
    site = two_ruptures(magnitude=5.25)
    with pytest.raises(SiteError, match=r"^site rupture 1 \(r2\): magnitude: 5.25 is outside the site-motion model's range 5.5-8 ") as error:
        measure_free_risk(linear_pair(), site, motions=2, bootstrap=100)
    assert "\n" not in str(error.value)
    result = measure_free_risk(linear_pair(), site, motions=4, seed=1, bootstrap=100, outside="clamp")
    assert result.clamped.values.tolist() == ["", "magnitude 5.25 -> 5.5"] and result.magnitude.values.tolist() == [7.0, 5.5]
    values = result.response_value.values
    np.testing.assert_allclose(result.clamped_rate.values, site.rate[1] * np.mean(values[1][:, None] > result.threshold.values, axis=0))
    assert np.all(result.level_without_clamped.values <= result.level.values)


def test_base_displacement_of_a_sliding_building():
    scene = stochpound.scene_from_dict({
        "g": 9.81,
        "building": [{"name": "A", "mass": [MASS], "stiffness": [STIFFNESS["A"]], "damping_ratio": DAMPING, "base": {"mass": 5.0e4, "mu": 0.05, "radius": 2.24}}],
        "contact": [],
        "motion": {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 0.5},
    })
    result = measure_free_risk(scene, two_ruptures(), "base_displacement", building="A", motions=3, seed=2, bootstrap=100, targets=[0.5])
    values = result.response_value.values
    assert result.attrs["units"] == "m" and np.all(values >= 0.0) and np.any(values > 0.0)
    assert np.nanmin(values) <= result.level.values[0] <= np.nanmax(values)


@pytest.mark.parametrize(("arguments", "message"), [
    ({"response": "impact_force"}, r"^response: must be one of closure, base_displacement, peak_storey_drift"),
    ({"motions": 1}, r"^motions: must be an integer >= 2"),
    ({"seed": -1}, r"^seed: must be an integer >= 0"),
    ({"bootstrap": 10}, r"^bootstrap: must be an integer >= 100"),
    ({"targets": [1.5]}, r"^targets: must be one or more probabilities in \(0, 1\)"),
    ({"outside": "drop"}, r"^outside: must be one of refuse, clamp"),
    ({"confidence": 1.5}, r"confidence"),
    ({"response": "base_displacement", "building": "A"}, r"^building: 'A' has a fixed base"),
    ({"response": "peak_storey_drift", "building": "A", "floor": 3}, r"^floor: must be a storey of 'A', 1 .. 1"),
    ({"contact": 2}, r"^contact: must be a contact index in \[0, 0\]"),
])
def test_bad_arguments_are_one_line_naming_the_field(arguments, message):
    with pytest.raises(ValueError, match=message) as error:
        measure_free_risk(linear_pair(), two_ruptures(), **arguments)
    assert "\n" not in str(error.value)


def test_a_scene_that_can_pound_is_refused_for_the_closure():
    with pytest.raises(ValueError, match=r"^scene: contact 0 has gap 0.02 m; the closure needs a contact-free scene"):
        measure_free_risk(linear_pair(gap=0.02), two_ruptures())


def test_several_demands_are_read_from_the_same_runs_as_each_alone():
    """measure_free_demands: the first demand allocates the extra runs and is measure_free_risk's answer; every other demand is
    read from those same runs (with extra = 0, each alone gives the same runs: the motions' window is fixed by the runs a rupture
    may get); a storey drift without a storey is the largest over the storeys."""
    closure, drift = _measure_free.measure_free_demands(
        linear_pair(), two_ruptures(), [_measure_free.MeasureFreeDemand(), _measure_free.MeasureFreeDemand("peak_storey_drift", "B")],
        motions=3, extra=2, seed=4, bootstrap=100)
    alone = measure_free_risk(linear_pair(), two_ruptures(), motions=3, extra=2, seed=4, bootstrap=100)
    for name in ("response_value", "rate_of_exceedance", "level", "level_lower", "motions"):
        np.testing.assert_array_equal(closure[name].values, alone[name].values)
    assert drift.attrs["allocated_on"] == "closure (largest over the contacts)" and drift.attrs["demand"] == "storey drift of B (largest over its storeys)"
    np.testing.assert_array_equal(drift.motions.values, alone.motions.values)
    _, drift = _measure_free.measure_free_demands(
        linear_pair(), two_ruptures(), [_measure_free.MeasureFreeDemand(), _measure_free.MeasureFreeDemand("peak_storey_drift", "B")],
        motions=3, seed=4, bootstrap=100)
    storey = measure_free_risk(linear_pair(), two_ruptures(), "peak_storey_drift", building="B", floor=1, motions=3, seed=4, bootstrap=100)
    np.testing.assert_array_equal(drift.response_value.values, storey.response_value.values)
    np.testing.assert_array_equal(drift.level.values, storey.level.values)
    with pytest.raises(ValueError, match=r"^demands: must be one or more MeasureFreeDemand"):
        _measure_free.measure_free_demands(linear_pair(), two_ruptures(), [])
