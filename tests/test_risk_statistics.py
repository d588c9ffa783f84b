"""The risk chain's statistics against known truths: the cluster bootstrap's coverage and the isotonic λ_P(g)."""

from __future__ import annotations

import numpy as np
import pytest

from stochpound.stats._bootstrap import bootstrap_weights, interval, jackknife_weights, motion_clusters
from stochpound.risk._maf import _separation_kernel, non_increasing as _nonincreasing_rate


def test_singleton_clusters_give_the_plain_resampler():
    plain = bootstrap_weights(12, 50, seed=7)
    clustered = bootstrap_weights(12, 50, seed=7, clusters=[f"m{i}" for i in range(12)])
    np.testing.assert_array_equal(plain, clustered)
    np.testing.assert_array_equal(jackknife_weights(12), jackknife_weights(12, clusters=range(12)))


def test_motions_of_a_cluster_are_drawn_together():
    clusters = ["a", "a", "b", "c", "c", "c"]
    weights = bootstrap_weights(6, 200, seed=3, clusters=clusters)
    assert np.all(weights[:, 0] == weights[:, 1]) and np.all(weights[:, 3] == weights[:, 5])
    assert np.all(weights[:, [0, 2, 3]].sum(axis=1) == 3)  # three clusters drawn per resample
    left_out = jackknife_weights(6, clusters)
    np.testing.assert_array_equal(left_out, [[0, 0, 1, 1, 1, 1], [1, 1, 0, 1, 1, 1], [1, 1, 1, 0, 0, 0]])


def test_motion_clusters_use_the_event_then_the_station():
    labels = motion_clusters(["Kobe", "Kobe", "", ""], ["KJM", "KJM", "S1", "S1"])
    assert labels[0] == labels[1] != labels[2] == labels[3]
    assert motion_clusters(["", ""], ["", ""]) is None
    with pytest.raises(ValueError, match="clusters: the bootstrap needs at least 2 clusters"):
        bootstrap_weights(4, 10, 0, clusters=["e"] * 4)


def _coverage(clusters: np.ndarray | None, replications: int = 300, resamples: int = 400) -> float:
    """Share of 95 % intervals for the mean that cover it: 22 events of 2 components correlated at 0.9."""
    rng = np.random.default_rng(2026)
    events, rho = 22, 0.9
    covered = 0
    for r in range(replications):
        shared = rng.standard_normal(events)
        own = rng.standard_normal((events, 2))
        values = (np.sqrt(rho) * shared[:, None] + np.sqrt(1.0 - rho) * own).ravel()
        weights = bootstrap_weights(values.size, resamples, seed=r, clusters=clusters)
        left_out = jackknife_weights(values.size, clusters)
        estimate = values.mean()
        sampled = weights @ values / weights.sum(axis=1)
        jackknife = left_out @ values / left_out.sum(axis=1)
        lower, upper = interval(sampled, np.array(estimate), jackknife, 0.95)
        covered += bool(lower <= 0.0 <= upper)
    return covered / replications


def test_cluster_bootstrap_covers_where_the_naive_one_does_not():
    events = np.repeat(np.arange(22), 2)
    naive = _coverage(None)
    cluster = _coverage(events)
    assert cluster >= 0.90, cluster
    assert naive < 0.90, naive  # components treated as independent: intervals too narrow by about sqrt(1 + rho)


def test_isotonic_rate_curve_is_unbiased_where_a_running_minimum_is_biased_low():
    gaps = np.linspace(0.01, 0.30, 30)
    truth = 1e-2 * (gaps / gaps[0]) ** -3.0
    rng = np.random.default_rng(11)
    noisy = truth * np.exp(0.3 * rng.standard_normal((400, gaps.size)))
    isotonic = _nonincreasing_rate(noisy)
    running = np.fmin.accumulate(noisy, axis=-1)
    assert np.all(np.diff(isotonic, axis=-1) <= 0.0)
    middle = slice(5, 25)
    bias_isotonic = np.mean(np.log(isotonic / truth)[:, middle])
    bias_running = np.mean(np.log(running / truth)[:, middle])
    assert abs(bias_isotonic) < 0.03, bias_isotonic
    assert bias_running < -0.05, bias_running
    rate = np.array([truth[15]])
    separation = _separation_kernel(isotonic, gaps, rate)[:, 0]
    assert abs(np.median(separation) / gaps[15] - 1.0) < 0.02


def test_isotonic_rate_keeps_a_monotone_curve_and_fills_missing_gaps():
    curve = np.array([3e-2, 1e-2, np.nan, 4e-3, 1e-3])
    np.testing.assert_allclose(_nonincreasing_rate(curve), [3e-2, 1e-2, 1e-2, 4e-3, 1e-3], rtol=1e-12)
    rising = np.array([1e-2, 1e-3, 4e-3, 1e-4])
    np.testing.assert_allclose(_nonincreasing_rate(rising), [1e-2, 2e-3, 2e-3, 1e-4], rtol=1e-12)  # the pooled pair's geometric mean


def test_isotonic_rate_gives_back_the_zeros_of_gaps_no_run_closes():
    """Trailing zeros (no run pounds at the wider gaps) stay 0, weighted or not, so g* interpolates linearly in λ into them
    (they entered the fit as the smallest double, and exp(ln tiny) rounds above tiny); g* of a target between 4e-3 at 0.1 m
    and 0 at 0.2 m lies a fraction 1 − 1e-3 / 4e-3 of the way in ln g: 0.1 · 2^0.75."""
    curve = np.array([1e-2, 4e-3, 0.0, 0.0])
    gaps = np.array([0.05, 0.1, 0.2, 0.4])
    np.testing.assert_array_equal(_nonincreasing_rate(curve)[2:], 0.0)
    np.testing.assert_array_equal(_nonincreasing_rate(curve, np.array([1.0, 0.7, 0.3, 0.5]))[2:], 0.0)
    np.testing.assert_allclose(_separation_kernel(curve, gaps, np.array([1e-3])), [0.1 * 2.0**0.75], rtol=1e-12)


def test_stripe_fragility_resamples_the_events_of_a_store():
    import xarray as xr

    from stochpound.risk import stripe_fragility

    rng = np.random.default_rng(4)
    levels = np.array([0.2, 0.4, 0.8, 1.6])
    events = rng.random((4, 12)) < levels[:, None] / 1.2
    data = xr.DataArray(events.astype(float), dims=("intensity", "record"),
                        coords={"intensity": levels, "record": [f"m{i}" for i in range(12)],
                                "record_event": ("record", [f"quake {i // 2}" for i in range(12)]),
                                "record_station": ("record", [f"station {i // 2}" for i in range(12)])})
    clustered = stripe_fragility(data, bootstrap=200, seed=1)
    assert clustered.sizes["jackknife"] == 6 and "cluster bootstrap over events (6 clusters of the 12 motions that ran;" in clustered["theta_lower"].attrs["method"]
    plain = stripe_fragility(data.drop_vars(["record_event", "record_station"]), bootstrap=200, seed=1)
    assert plain.sizes["jackknife"] == 12 and plain["theta_lower"].attrs["method"] == "BCa bootstrap over motions"
    np.testing.assert_array_equal(clustered["theta"], plain["theta"])  # the estimate itself does not change


def test_the_bootstrap_counts_the_clusters_and_motions_that_ran_not_the_pool():
    """A selection runs some motions of a pool per stripe: the method's words count the runs' clusters and motions, per stripe."""
    import xarray as xr

    from stochpound.risk import stripe_fragility
    from stochpound.stats import bootstrap_method

    rng = np.random.default_rng(5)
    levels = np.array([0.2, 0.4, 0.8])
    events = (rng.random((3, 12)) < levels[:, None] / 1.0).astype(float)
    chosen = np.zeros((3, 12), dtype=bool)  # a pool of 12 motions of 6 quakes; each stripe runs 4 of them, from 2 or 3 quakes
    chosen[0, [0, 1, 2, 3]] = chosen[1, [2, 3, 4, 5]] = chosen[2, [0, 2, 4, 6]] = True
    data = xr.DataArray(np.where(chosen, events, np.nan), dims=("intensity", "record"),
                        coords={"intensity": levels, "record": [f"m{i}" for i in range(12)],
                                "record_event": ("record", [f"quake {i // 2}" for i in range(12)])})
    method = stripe_fragility(data, bootstrap=50, seed=1)["theta_lower"].attrs["method"]
    assert method == ("BCa cluster bootstrap over events (4 clusters of the 7 motions that ran, of the 12 the store holds; per stripe 2–4 clusters "
                      "of 4 motions; station where the event is unknown)")
    assert "12 motions that ran" not in method and "6 clusters" not in method  # the pool is not what was resampled
    every = bootstrap_method(np.array(["a", "a", "b"], dtype=object), np.ones((2, 3), dtype=bool))
    assert every == "BCa cluster bootstrap over events (2 clusters of the 3 motions that ran; station where the event is unknown)"
