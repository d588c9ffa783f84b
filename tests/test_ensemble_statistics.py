"""Ensemble statistics and their kernels against scipy on constructed data: intervals, quantiles, running estimates."""

import numpy as np
import pytest
import xarray as xr
from scipy import stats

from stochpound.analysis import ensemble_statistics, mean_interval, quantiles, running_mean, running_pounding_probability
from stochpound.stats import kernels
from stochpound.analysis.names import ENSEMBLE_ALIASES, with_aliases, without_aliases


@pytest.mark.parametrize("n", [1, 7, 40, 500])
def test_clopper_pearson_equals_scipys_exact_binomial_interval(n):
    for k in sorted({0, 1, n // 3, n - 1, n}):
        for confidence in (0.9, 0.95, 0.99):
            lower, upper = kernels.clopper_pearson(k, n, confidence)
            expected = stats.binomtest(k, n).proportion_ci(confidence_level=confidence, method="exact")
            assert float(lower) == pytest.approx(expected.low, abs=1e-12), (k, n)
            assert float(upper) == pytest.approx(expected.high, abs=1e-12), (k, n)


def test_clopper_pearson_of_no_trials_is_nan_and_confidence_is_checked():
    assert np.isnan(kernels.clopper_pearson(0, 0)).all()
    with pytest.raises(ValueError, match="confidence"):
        kernels.clopper_pearson(1, 2, 1.0)


def test_mean_interval_equals_scipys_t_interval_and_ignores_nan():
    rng = np.random.default_rng(11)
    values = rng.lognormal(0.0, 0.8, size=(4, 60))
    values[1, 5:9] = np.nan
    result = kernels.mean_interval(values, 0.95)
    for row, estimate, lower, upper, count in zip(values, *result):
        sample = row[~np.isnan(row)]
        expected = stats.t.interval(0.95, len(sample) - 1, loc=sample.mean(), scale=stats.sem(sample))
        assert count == len(sample)
        assert estimate == pytest.approx(sample.mean(), rel=1e-13)
        assert (lower, upper) == pytest.approx(expected, rel=1e-12)


def test_mean_interval_of_one_value_has_no_bounds():
    estimate, lower, upper, count = kernels.mean_interval(np.array([3.0, np.nan]))
    assert estimate == 3.0 and count == 1 and np.isnan(lower) and np.isnan(upper)


def test_bootstrap_mean_interval_agrees_with_scipys_percentile_bootstrap_and_ignores_nan():
    """Against scipy.stats.bootstrap (percentile, 99999 resamples): the bounds agree within 6 % of the interval's width (Monte Carlo error of both)."""
    rng = np.random.default_rng(12)
    values = np.stack([rng.lognormal(0.0, 1.0, 40), rng.exponential(2.0, 40), np.where(rng.random(40) < 0.8, 0.0, rng.lognormal(3.0, 1.0, 40))])
    values[1, 30:] = np.nan
    result = kernels.bootstrap_mean_interval(values, 0.9)
    for row, estimate, lower, upper, count in zip(values, *result):
        sample = row[~np.isnan(row)]
        reference = stats.bootstrap((sample,), np.mean, confidence_level=0.9, method="percentile", n_resamples=99999, random_state=3).confidence_interval
        assert count == len(sample) and estimate == pytest.approx(sample.mean(), rel=1e-13)
        assert lower == pytest.approx(reference.low, abs=0.06 * (upper - lower))
        assert upper == pytest.approx(reference.high, abs=0.06 * (upper - lower))


def test_bootstrap_mean_interval_of_two_values_is_their_range_and_of_one_value_has_no_bounds():
    """Closed form for n = 2: resampled means are a, (a + b)/2, b with probabilities 1/4, 1/2, 1/4, so the 2.5 % and 97.5 % quantiles are a and b."""
    estimate, lower, upper, count = kernels.bootstrap_mean_interval(np.array([[5.0, 1.0], [3.0, np.nan]]))
    assert list(estimate) == [3.0, 3.0] and list(count) == [2, 1]
    assert (lower[0], upper[0]) == (1.0, 5.0) and np.isnan(lower[1]) and np.isnan(upper[1])


def test_bootstrap_bounds_of_non_negative_data_are_never_negative_and_depend_on_the_values_only():
    """Property over 3000 constructed non-negative samples (2 to 60 values; zeros, a single spike, counts, heavy tails, NaN): 0 ≤ lower ≤ mean ≤ upper ≤ max."""
    rng = np.random.default_rng(8)
    samples = np.full((3000, 60), np.nan)
    for row in samples:
        n = rng.integers(2, 61)
        kind = rng.integers(4)
        row[:n] = (np.zeros(n), np.where(np.arange(n) == rng.integers(n), rng.lognormal(10, 2), 0.0), rng.poisson(0.3, n), rng.pareto(1.1, n))[kind]
    _, lower, upper, _ = kernels.bootstrap_mean_interval(samples)
    t_lower = kernels.mean_interval(samples).lower
    mean, largest = np.nanmean(samples, axis=-1), np.nanmax(samples, axis=-1)
    assert (lower >= 0).all() and (lower <= mean * (1 + 1e-12)).all() and (mean <= upper * (1 + 1e-12)).all() and (upper <= largest * (1 + 1e-12)).all()
    assert (t_lower < 0).any()  # the data would drive a t interval below zero
    shuffled = rng.permuted(samples[:, :10], axis=-1)  # order does not matter (NaN moved too: the count is the same)
    np.testing.assert_array_equal(kernels.bootstrap_mean_interval(shuffled).lower, kernels.bootstrap_mean_interval(samples[:, :10]).lower)


def test_t_interval_covers_the_true_mean_at_its_level():
    """Coverage on 4000 constructed normal samples of 12: 95 % within three binomial standard errors."""
    rng = np.random.default_rng(5)
    samples = rng.normal(2.0, 3.0, size=(4000, 12))
    _, lower, upper, _ = kernels.mean_interval(samples, 0.95)
    covered = np.mean((lower <= 2.0) & (2.0 <= upper))
    assert abs(covered - 0.95) < 3 * np.sqrt(0.95 * 0.05 / 4000)


def test_quantiles_equal_scipys_type_7():
    rng = np.random.default_rng(2)
    values = rng.gamma(2.0, size=(3, 101))
    values[2, :50] = np.nan
    q = (0.5, 0.84, 0.95)
    result = kernels.quantiles(values, q)
    for row, ours in zip(values, result):
        sample = row[~np.isnan(row)]
        np.testing.assert_allclose(ours, stats.mstats.mquantiles(sample, q, alphap=1, betap=1), rtol=1e-13)
    assert np.isnan(kernels.quantiles(np.full((2, 3), np.nan), q)).all()


def test_running_estimates_equal_the_estimates_of_each_prefix():
    rng = np.random.default_rng(8)
    values = rng.exponential(2.0, size=50)
    values[[3, 17]] = np.nan
    events = (rng.random(50) < 0.3).astype(float)
    events[4] = np.nan
    running = kernels.running_mean_interval(values)
    proportion = kernels.running_proportion_interval(events)
    for n in (1, 2, 5, 20, 50):
        direct = kernels.mean_interval(values[:n])
        np.testing.assert_allclose([r[n - 1] for r in running], list(direct), rtol=1e-12, equal_nan=True)
        k, trials = np.nansum(events[:n]), np.sum(~np.isnan(events[:n]))
        expected = stats.binomtest(int(k), int(trials)).proportion_ci(method="exact")
        assert proportion.estimate[n - 1] == pytest.approx(k / trials)
        assert (proportion.lower[n - 1], proportion.upper[n - 1]) == pytest.approx((expected.low, expected.high), abs=1e-12)


def test_moment_and_correlation_kernels_ignore_nan_like_scipy():
    rng = np.random.default_rng(4)
    a = rng.gamma(2.0, size=300)
    b = 0.5 * a + rng.normal(size=300)
    a_missing = a.copy()
    a_missing[[0, 100, 299]] = np.nan
    keep = ~np.isnan(a_missing)
    result = kernels.moments(a_missing)
    assert float(result.skewness) == pytest.approx(stats.skew(a[keep]), rel=1e-12)
    assert float(result.excess) == pytest.approx(stats.kurtosis(a[keep]), rel=1e-12)
    assert float(kernels.pearson(a_missing, b)) == pytest.approx(np.corrcoef(a[keep], b[keep])[0, 1], rel=1e-12)
    assert np.isnan(kernels.moments(np.ones(5)).skewness)


def constructed_store(realizations: int = 40) -> xr.Dataset:
    """A store-like dataset: gap x mu x realization, with a missing case and a reference."""
    rng = np.random.default_rng(21)
    shape = (3, 2, realizations)
    impacts = rng.poisson([[[3.0], [0.5]], [[1.0], [0.2]], [[0.0], [0.0]]], size=shape).astype(float)
    impacts[0, 0, 7] = np.nan  # a missing case
    force = np.where(impacts > 0, rng.lognormal(12.0, 0.5, size=shape), 0.0)
    force[np.isnan(impacts)] = np.nan
    coords = {"gap": [0.0, 0.02, 0.1], "mu": [0.1, np.inf], "realization": np.arange(realizations)}
    dims = ("gap", "mu", "realization")
    return xr.Dataset(
        {
            "impacts": (dims, impacts),
            "peak_impact_force": (dims, force, {"units": "N", "long_name": "largest impact force"}),
            "response_std": (dims, rng.lognormal(-4.0, 0.3, size=shape), {"units": "m"}),
            "peak_total_displacement": (dims + ("building",), rng.lognormal(-3.0, 0.4, size=shape + (2,)), {"units": "m"}),
            "reference_peak_total_displacement": (("realization",), rng.lognormal(-3.0, 0.4, size=realizations), {"units": "m"}),
        },
        coords={**coords, "building": ["B1", "B2"]},
    )


def test_ensemble_statistics_per_cell_are_lazy_and_match_the_kernels():
    store = constructed_store()
    lazy = ensemble_statistics(store.chunk({"gap": 1, "realization": 10}))
    assert all(variable.chunks is not None for variable in lazy.data_vars.values())
    result = lazy.compute()
    cell = {"gap": 0.0, "mu": 0.1}
    impacts = store["impacts"].sel(cell).values
    valid = impacts[~np.isnan(impacts)]
    interval = stats.binomtest(int((valid > 0).sum()), len(valid)).proportion_ci(method="exact")
    assert int(result["realizations"].sel(cell)) == len(valid) == 39
    assert float(result["pounding_probability_lower"].sel(cell)) == pytest.approx(interval.low, abs=1e-12)
    force = store["peak_impact_force"].sel(cell).values
    given = force[impacts > 0]
    assert float(result["peak_impact_force_mean"].sel(cell)) == pytest.approx(given.mean())
    assert int(result["peak_impact_force_count"].sel(cell)) == len(given)
    peaks = store["peak_total_displacement"].sel(cell | {"building": "B2"}).values
    expected = kernels.bootstrap_mean_interval(peaks)  # a peak cannot be negative: the percentile bootstrap
    b2 = cell | {"building": "B2"}
    assert (float(result["peak_total_displacement_lower"].sel(b2)), float(result["peak_total_displacement_upper"].sel(b2))) == (expected.lower, expected.upper)
    assert "bootstrap" in result["peak_impact_force_lower"].attrs["long_name"]
    for name in [n for n in result.data_vars if n.endswith("_lower")]:
        assert bool((result[name] >= 0).where(result[name].notnull(), True).all()), name
    np.testing.assert_allclose(result["peak_total_displacement_quantile"].sel(cell | {"building": "B2"}), np.quantile(peaks, [0.5, 0.84, 0.95]))
    assert list(result["reference_peak_total_displacement_quantile"].dims) == ["quantile"]
    never = result.sel(gap=0.1)
    assert (never["pounding_probability"] == 0).all() and np.isnan(never["peak_impact_force_mean"]).all()


def test_xarray_wrappers_are_lazy_and_keep_coordinates():
    store = constructed_store().chunk({"realization": 8})
    mean = mean_interval(store["response_std"])
    assert mean["mean"].chunks is not None and mean["mean"].attrs["units"] == "m"
    q = quantiles(store["response_std"], (0.1, 0.9))
    assert list(q["quantile"].values) == [0.1, 0.9] and q.dims == ("gap", "mu", "quantile")
    running = running_mean(store["response_std"]).compute()
    np.testing.assert_allclose(running["mean"].isel(realization=-1), mean["mean"].compute())
    probability = running_pounding_probability(store["impacts"]).compute()
    assert probability["probability"].dims == ("gap", "mu", "realization")
    assert float(probability["count"].sel(gap=0.0, mu=0.1).isel(realization=-1)) == 39


def test_aliases_share_the_data_and_can_be_dropped():
    data = xr.Dataset({"response_std": ("realization", [1.0, 2.0], {"units": "m"})})
    aliased = with_aliases(data, ENSEMBLE_ALIASES)
    assert aliased["top_floor_std"].attrs["alias_of"] == "response_std"
    np.testing.assert_array_equal(aliased["top_floor_std"], aliased["response_std"])
    assert "top_floor_mean" not in aliased
    assert list(without_aliases(aliased).data_vars) == ["response_std"]
