"""The rate of a demand from a lognormal demand per stripe (stochpound.risk.stripe_demand_rate), against closed forms and the counts."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from scipy import special

from stochpound.risk import HazardCurve, limit_state_events, risk_curve, stripe_demand_moments, stripe_demand_rate, stripe_fragility

LEVELS = np.array([0.1, 0.2, 0.4, 0.8])
A, B, S = np.log(0.05), 1.2, 0.45  # ln D = A + B ln x + S z: median 0.05 m at x = 1 g


def _standard_sample(n: int) -> np.ndarray:
    """n values of exactly mean 0 and sample standard deviation 1."""
    z = special.ndtri((np.arange(n) + 0.5) / n)
    return (z - z.mean()) / z.std(ddof=1)


def _stripes(n: int = 20, scatter: float = S) -> xr.DataArray:
    z = _standard_sample(n)
    values = np.exp(A + B * np.log(LEVELS)[:, None] + scatter * z[None, :])
    return xr.DataArray(values, dims=("intensity", "record"), coords={"intensity": LEVELS})


def test_a_power_law_demand_under_a_power_law_hazard_gives_the_closed_form() -> None:
    """ln D | x normal with mean A + B ln x and σ S is a lognormal fragility in x, θ = exp((ln d − A)/B), β = S/B, and under
    λ = k0 x^−k its rate is k0 θ^−k exp(k²β²/2) (Cornell et al. 2002): the estimator is exact here, within its quadrature."""
    k0, k = 2.0e-4, 2.6
    hz = HazardCurve.power_law(k0, k)
    thresholds = np.array([0.005, 0.02, 0.05, 0.1])
    rate = stripe_demand_rate(_stripes(), thresholds, hz)
    theta, beta = np.exp((np.log(thresholds) - A) / B), S / B
    np.testing.assert_allclose(rate.values, k0 * theta ** (-k) * np.exp(0.5 * k**2 * beta**2), rtol=2e-3)


def test_it_agrees_with_the_fit_of_the_counts_where_many_runs_reach_the_threshold() -> None:
    """Two independent estimators of the same curve: with 400 runs per stripe the counts-based fragility fits (lognormal in x,
    as the demand here makes them) and the lognormal demand per stripe give the same rate under the bundled site's table."""
    hz = HazardCurve.bundled("fox_plaza_los_angeles_sa1p0s")
    demand = _stripes(400)
    thresholds = np.array([0.005, 0.01, 0.02])
    counted = risk_curve(stripe_fragility(limit_state_events(demand, thresholds), bootstrap=0), hz)["maf"]
    np.testing.assert_allclose(stripe_demand_rate(demand, thresholds, hz).values, counted.values, rtol=0.03)


def test_at_a_threshold_few_runs_reach_it_stays_near_the_rate_where_the_counts_cannot() -> None:
    """The point of the estimator: at a threshold that about 5 % of the top stripe's 20 runs reach, 40 samples of the same
    population: the lognormal demand's rate stays within a factor of 2 of the closed form in nearly every sample, the fit of
    the counts (0, 1 or 2 runs reach it) almost never is."""
    k0, k = 2.0e-4, 2.6
    hz = HazardCurve.power_law(k0, k)
    threshold = float(np.exp(A + B * np.log(LEVELS[-1]) + 1.6 * S))
    exact = k0 * np.exp((np.log(threshold) - A) / B) ** (-k) * np.exp(0.5 * k**2 * (S / B) ** 2)
    rng = np.random.default_rng(7)
    lognormal, counted = [], []
    for _ in range(40):
        values = np.exp(A + B * np.log(LEVELS)[:, None] + S * rng.standard_normal((LEVELS.size, 20)))
        demand = xr.DataArray(values, dims=("intensity", "record"), coords={"intensity": LEVELS})
        lognormal.append(float(stripe_demand_rate(demand, [threshold], hz)[0]) / exact)
        counted.append(float(risk_curve(stripe_fragility(limit_state_events(demand, [threshold]), bootstrap=0), hz)["maf"][0]) / exact)
    within = [int(np.sum((np.array(ratios) > 0.5) & (np.array(ratios) < 2.0))) for ratios in (lognormal, counted)]
    assert within[0] >= 36 and within[1] <= 4, within


def test_runs_that_never_reach_zero_count_as_below_every_threshold_and_unrun_motions_are_left_out() -> None:
    hz = HazardCurve.power_law(2.0e-4, 2.6)
    demand = _stripes(20)
    halved = xr.concat([demand, xr.full_like(demand, -1.0)], "record")  # as many runs that never close: p = 1/2 at every stripe
    unrun = xr.concat([demand, xr.full_like(demand, np.nan)], "record")  # motions not chosen for the stripes
    thresholds = [0.01, 0.05]
    full = stripe_demand_rate(demand, thresholds, hz)
    np.testing.assert_allclose(stripe_demand_rate(halved, thresholds, hz), 0.5 * full, rtol=1e-12)
    np.testing.assert_allclose(stripe_demand_rate(unrun, thresholds, hz), full, rtol=1e-12)


def test_the_moments_of_a_stripe_are_those_of_ln_d_over_its_runs_with_d_above_zero() -> None:
    """Stripe 1: ln D = ln 0.05 + 0.45 z (z of mean 0, sample σ 1) on 20 runs, 5 of them 0 and 5 not run; stripe 2: 3 runs, one 0."""
    z = _standard_sample(15)
    first = np.concatenate([0.05 * np.exp(0.45 * z), np.zeros(5), np.full(5, np.nan)])
    second = np.concatenate([[0.1, 0.4, 0.0], np.full(22, np.nan)])
    mean, std, fraction = stripe_demand_moments(np.stack([first, second]))
    assert mean == pytest.approx([np.log(0.05), 0.5 * np.log(0.04)], rel=1e-12)
    assert std == pytest.approx([0.45, np.log(4.0) / np.sqrt(2.0)], rel=1e-12)
    assert fraction == pytest.approx([15 / 20, 2 / 3], rel=1e-12)
    with pytest.raises(ValueError, match="every stripe needs at least two runs with a demand > 0"):
        stripe_demand_moments(np.array([[0.1, 0.0, np.nan]]))


def test_configurations_get_their_own_curve() -> None:
    hz = HazardCurve.power_law(2.0e-4, 2.6)
    demand = xr.concat([_stripes(), 2.0 * _stripes()], "neighbour").assign_coords(neighbour=["stiff", "flexible"])
    rate = stripe_demand_rate(demand, [0.01, 0.02, 0.04], hz)
    assert rate.dims == ("gap", "neighbour")
    np.testing.assert_allclose(rate.sel(neighbour="flexible", gap=0.04), rate.sel(neighbour="stiff", gap=0.02), rtol=1e-9)


@pytest.mark.parametrize(("change", "message"), [
    ({"thresholds": [0.0, 0.1]}, "thresholds:"),
    ({"demand": _stripes().isel(intensity=[0])}, "demand:"),
    ({"demand": _stripes().isel(record=[0])}, "demand:"),
    ({"demand": _stripes().rename(record="motion")}, "demand:"),
])
def test_bad_input_is_one_line_naming_the_argument(change: dict, message: str) -> None:
    arguments = {"demand": _stripes(), "thresholds": [0.01], "hz": HazardCurve.power_law(2.0e-4, 2.6), **change}
    with pytest.raises(ValueError, match=message) as error:
        stripe_demand_rate(**arguments)
    assert "\n" not in str(error.value)
