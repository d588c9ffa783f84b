"""Lognormal fragility fits: stripes by binomial MLE, IDA by log-moments (censored MLE), every gap at once, bootstrap over motions."""

import warnings

import numpy as np
import pytest
import xarray as xr
from scipy import optimize, special, stats

from stochpound.analysis import fit_fragility
from stochpound.risk import Fragility, fragility_band, fragility_surface, homogeneous_capacities, ida_fragility, limit_state_events, stripe_fragility
from stochpound.stats import kernels
from stochpound.stats._bootstrap import bootstrap_weights
from stochpound.risk._fragility import ALWAYS, DECREASING, FIT, NEVER, SEPARATED, stripe_mle


def independent_stripe_mle(levels, k, n):
    """θ, β maximising Σ k ln Φ + (n − k) ln(1 − Φ), by Nelder–Mead on (ln θ, ln β)."""
    levels, k, n = (np.asarray(v, float) for v in (levels, k, n))

    def negative(p):
        z = np.log(levels / np.exp(p[0])) / np.exp(p[1])
        return -np.sum(k * special.log_ndtr(z) + (n - k) * special.log_ndtr(-z))

    best = optimize.minimize(negative, [np.log(np.median(levels)), np.log(0.5)], method="Nelder-Mead",
                             options={"xatol": 1e-12, "fatol": 1e-14, "maxiter": 20000})
    return np.exp(best.x)


@pytest.mark.parametrize("seed", range(5))
def test_stripe_fit_equals_an_independent_maximum_likelihood_on_the_same_counts(seed):
    rng = np.random.default_rng(seed)
    levels = np.sort(rng.uniform(0.1, 1.5, 7))
    runs = rng.integers(5, 45, 7)
    pounded = rng.binomial(runs, stats.norm.cdf(np.log(levels / rng.uniform(0.3, 0.9)) / rng.uniform(0.2, 0.8)))
    frag = fit_fragility(levels, pounded, runs)
    if frag.status != FIT:
        pytest.skip("this draw is separated")
    theta, beta = independent_stripe_mle(levels, pounded, runs)
    assert frag.theta == pytest.approx(theta, rel=1e-6)
    assert frag.beta == pytest.approx(beta, rel=1e-6)
    assert frag(frag.theta) == pytest.approx(0.5)
    assert frag(levels) == pytest.approx(stats.norm.cdf(np.log(levels / theta) / beta), abs=1e-6)


def test_a_batch_of_stripe_fits_equals_the_fits_one_by_one():
    rng = np.random.default_rng(7)
    levels = np.array([0.2, 0.4, 0.6, 0.8, 1.0])
    runs = np.full((6, 5), 30)
    pounded = rng.binomial(runs, stats.norm.cdf(np.log(levels / 0.5) / 0.4))
    theta, beta, status = stripe_mle(levels, pounded, runs)
    for row in range(6):
        single = fit_fragility(levels, pounded[row], runs[row])
        assert (theta[row], beta[row], status[row]) == pytest.approx((single.theta, single.beta, single.status), nan_ok=True)


def test_ida_fit_is_the_log_moments_of_the_capacities():
    capacities = np.exp(np.random.default_rng(1).normal(np.log(0.5), 0.4, 44))
    frag = fit_fragility(capacities=capacities)
    assert frag.method == "ida"
    assert frag.theta == pytest.approx(np.exp(np.mean(np.log(capacities))), rel=1e-12)
    assert frag.beta == pytest.approx(np.std(np.log(capacities)), rel=1e-12)


def test_censored_ida_capacities_maximise_the_censored_lognormal_likelihood():
    capacities = np.exp(np.random.default_rng(2).normal(np.log(0.5), 0.4, 40))
    bound = 0.7
    observed = np.log(capacities[capacities <= bound])
    censored = np.count_nonzero(capacities > bound)
    frag = fit_fragility(capacities=np.where(capacities > bound, np.inf, capacities), censored_at=bound)

    def negative(p):
        return -(stats.norm.logpdf(observed, p[0], np.exp(p[1])).sum() + censored * stats.norm.logsf(np.log(bound), p[0], np.exp(p[1])))

    best = optimize.minimize(negative, [0.0, 0.0], method="Nelder-Mead", options={"xatol": 1e-12, "fatol": 1e-14, "maxiter": 20000})
    assert censored > 3
    assert frag.theta == pytest.approx(np.exp(best.x[0]), rel=1e-6)
    assert frag.beta == pytest.approx(np.exp(best.x[1]), rel=1e-6)


@pytest.mark.parametrize(("pounded", "status", "theta"), [
    ([0, 0, 0], NEVER, np.inf),
    ([5, 5, 5], ALWAYS, 0.0),
    ([0, 0, 5], SEPARATED, np.sqrt(0.4 * 0.6)),
    ([0, 3, 5], SEPARATED, 0.4),
])
def test_degenerate_stripes_give_a_documented_step(pounded, status, theta):
    frag = fit_fragility([0.2, 0.4, 0.6], pounded, [5, 5, 5])
    assert frag.status == status and frag.beta == 0.0
    assert frag.theta == pytest.approx(theta)
    assert frag([0.1, 10.0]).tolist() == ([0.0, 0.0] if status == NEVER else [1.0, 1.0] if status == ALWAYS else [0.0, 1.0])


def test_counts_falling_with_intensity_are_reported_not_fitted():
    frag = fit_fragility([0.2, 0.4, 0.6], [4, 2, 1], [5, 5, 5])
    assert frag.status == DECREASING and frag.status_name == "decreasing"
    assert np.isnan(frag.theta) and np.isnan(frag(0.5))


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"levels": [0.2, 0.4], "pounded": [3, 1], "runs": [2, 5]}, "pounded"),
    ({"levels": [0.0, 0.4], "pounded": [0, 1], "runs": [2, 5]}, "levels"),
    ({"levels": [0.2, 0.4], "pounded": [0, 1]}, "levels, pounded, runs"),
    ({"capacities": [0.3, np.inf]}, "censored_at"),
    ({"capacities": [0.3, -1.0]}, "capacities"),
    ({"capacities": [0.3, 0.5], "levels": [1.0]}, "capacities"),
])
def test_bad_input_names_the_field(kwargs, field):
    with pytest.raises(ValueError, match=f"^{field}"):
        fit_fragility(**kwargs)


def synthetic_stripes(rng, records=40, theta=0.5, beta=0.4, repetitions=None):
    """Each motion has a lognormal capacity; at level x it exceeds iff its capacity ≤ x (one outcome per motion and stripe)."""
    levels = theta * np.exp(beta * np.array([-1.5, -0.75, 0.0, 0.75, 1.5]))
    shape = (records,) if repetitions is None else (repetitions, records)
    capacity = theta * np.exp(beta * rng.standard_normal(shape))
    events = (capacity[..., None, :] <= levels[:, None]).astype(float)
    dims = ("intensity", "record") if repetitions is None else ("repetition", "intensity", "record")
    return xr.DataArray(events, dims=dims, coords={"intensity": levels}), capacity


def test_every_gap_at_once_equals_a_fit_per_gap_with_clopper_pearson_points():
    rng = np.random.default_rng(3)
    levels = np.array([0.1, 0.3, 0.5, 0.8])
    closure = xr.DataArray(levels[:, None, None] * np.exp(rng.normal(np.log(0.1), 0.5, (1, 30, 2))),
                           dims=("intensity", "record", "contact"), coords={"intensity": levels, "gap": np.inf})
    gaps = [0.01, 0.03, 0.05]
    result = stripe_fragility(limit_state_events(closure, gaps, contact_dim="contact"), bootstrap=0)
    for gap in gaps:
        k = (closure.max("contact") >= gap).sum("record").values
        single = fit_fragility(levels, k, np.full(4, 30))
        fitted = result.sel(gap=gap)
        assert (float(fitted.theta), float(fitted.beta)) == pytest.approx((single.theta, single.beta), rel=1e-9)
        assert fitted.exceeded.values.tolist() == k.tolist()
        for j, count in enumerate(k):
            interval = stats.binomtest(int(count), 30).proportion_ci(0.95, method="exact")
            assert (float(fitted.probability_lower[j]), float(fitted.probability_upper[j])) == pytest.approx((interval.low, interval.high))
    surface = fragility_surface(result, [0.2, 0.4])
    assert surface.dims == ("im", "gap")
    assert float(surface.sel(gap=0.03, im=0.4)) == pytest.approx(float(Fragility(result.theta.sel(gap=0.03), result.beta.sel(gap=0.03))(0.4)))


def test_homogeneous_capacities_give_the_intensity_of_first_pounding():
    closure = xr.DataArray([0.02, 0.05, 0.0], dims="record")
    intensity = xr.DataArray([0.3, 0.4, 0.5], dims="record")
    capacity = homogeneous_capacities(closure, intensity, [0.01, 0.1])
    assert capacity.sel(gap=0.1).values.tolist() == pytest.approx([1.5, 0.8, np.inf])
    assert capacity.sel(gap=0.01).values[:2].tolist() == pytest.approx([0.15, 0.08])
    with pytest.raises(ValueError, match="^gaps"):
        homogeneous_capacities(closure, intensity, [0.0])


def test_the_bootstrap_resamples_motions_reproducibly():
    events, _ = synthetic_stripes(np.random.default_rng(4))
    first, second = stripe_fragility(events, bootstrap=50, seed=9), stripe_fragility(events, bootstrap=50, seed=9)
    assert np.array_equal(first.theta_bootstrap.values, second.theta_bootstrap.values)
    assert not np.array_equal(first.theta_bootstrap.values, stripe_fragility(events, bootstrap=50, seed=10).theta_bootstrap.values)
    weights = bootstrap_weights(40, 50, 9)
    assert weights.shape == (50, 40) and np.all(weights.sum(1) == 40)


def test_the_fragility_bootstrap_and_the_mean_interval_draw_from_the_one_resampler():
    """Both callers reproduced from ``bootstrap_weights``: a fragility resample is the fit to the motions repeated as often
    as the weights say, and the percentile bootstrap of the mean is the quantiles of the weighted means."""
    events, _ = synthetic_stripes(np.random.default_rng(4), records=20)
    fitted = stripe_fragility(events, bootstrap=6, seed=9)
    weights = bootstrap_weights(20, 6, 9)
    for resample, counts in enumerate(weights.astype(int)):
        repeated = stripe_fragility(events.isel(record=np.repeat(np.arange(20), counts)), bootstrap=0)
        assert fitted.theta_bootstrap.values[resample] == pytest.approx(float(repeated.theta), rel=1e-9)
        assert fitted.beta_bootstrap.values[resample] == pytest.approx(float(repeated.beta), rel=1e-9)
    values = np.sort(np.random.default_rng(5).lognormal(0.0, 1.0, 30))
    resampled_means = bootstrap_weights(30, kernels.BOOTSTRAP_RESAMPLES, (kernels.BOOTSTRAP_SEED, 30)) @ values / 30
    _, lower, upper, _ = kernels.bootstrap_mean_interval(values)
    assert [lower, upper] == pytest.approx(np.quantile(resampled_means, [0.025, 0.975]), rel=1e-12)
    counts = bootstrap_weights(50, 4000, 1)  # each count is Binomial(50, 1/50): mean 1, variance 0.98
    assert counts.mean() == pytest.approx(1.0, abs=0.01) and counts.var() == pytest.approx(0.98, abs=0.03)


def test_bootstrap_intervals_cover_the_true_median_about_95_percent_of_the_time():
    repetitions, theta, beta = 200, 0.5, 0.4
    events, capacity = synthetic_stripes(np.random.default_rng(5), theta=theta, beta=beta, repetitions=repetitions)
    stripes = stripe_fragility(events, bootstrap=200, seed=1)
    covered = (stripes.theta_lower <= theta) & (theta <= stripes.theta_upper)
    assert 0.90 <= float(covered.mean()) <= 0.98
    capacities = xr.DataArray(capacity, dims=("repetition", "record"))
    ida = ida_fragility(capacities, bootstrap=400, seed=2)
    for name, truth in (("theta", theta), ("beta", beta)):
        covered = (ida[f"{name}_lower"] <= truth) & (truth <= ida[f"{name}_upper"])
        assert 0.90 <= float(covered.mean()) <= 0.98, name


def test_ida_fragility_with_censoring_matches_the_single_fit():
    capacity = np.exp(np.random.default_rng(6).normal(np.log(0.5), 0.4, 30))
    capacity[capacity > 0.8] = np.inf
    result = ida_fragility(xr.DataArray(capacity, dims="record"), censored_at=0.8, bootstrap=20)
    single = fit_fragility(capacities=capacity, censored_at=0.8)
    assert (float(result.theta), float(result.beta)) == pytest.approx((single.theta, single.beta))
    assert float(result.theta_lower) < single.theta < float(result.theta_upper)


def test_the_fitted_curve_has_a_band_around_it_at_every_intensity():
    events, _ = synthetic_stripes(np.random.default_rng(8))
    fitted = stripe_fragility(events, bootstrap=200)
    band = fragility_band(fitted, [0.2, 0.5, 1.0])
    assert band.probability.values == pytest.approx(Fragility(float(fitted.theta), float(fitted.beta))([0.2, 0.5, 1.0]))
    assert np.all(band.lower <= band.probability) and np.all(band.probability <= band.upper)
    assert np.all(band.lower < band.upper)
    with pytest.raises(ValueError, match="^fragility"):
        fragility_band(stripe_fragility(events, bootstrap=0), [0.5])


def test_flat_counts_in_a_batch_raise_no_overflow_and_leave_the_other_fits_alone():
    # nearly every run pounds at every stripe: the probit slope ends at or below 0, where exp(-a/b) overflowed
    levels, runs = [0.2, 0.4, 0.6], [20, 20, 20]
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        theta, beta, status = stripe_mle(levels, [[19, 19, 19], [20, 19, 20], [1, 8, 14]], runs)
    assert status.tolist() == [DECREASING, DECREASING, FIT]
    assert np.isnan(theta[:2]).all() and np.isnan(beta[:2]).all()
    alone = stripe_mle(levels, [1, 8, 14], runs)
    assert (theta[2], beta[2]) == (pytest.approx(float(alone[0]), rel=1e-12), pytest.approx(float(alone[1]), rel=1e-12))
