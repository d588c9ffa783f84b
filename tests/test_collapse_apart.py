"""Collapse counted apart in any demand (issue 45 item 3): λ = ∫ [P(C | im) + (1 − P(C | im)) P(D ≥ x | im, no C)] |dλ(im)|.

Small hand-made stripes (three levels, eight runs each) at a power-law site λ(im) = k0 im^-k, checked against
closed forms and an independent quadrature (scipy.integrate.quad of the hand-fitted lognormals), and the stripes-only
bound of a step at the lowest stripe and the 'not identified' flag of a lognormal fit.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from scipy import integrate, stats

from stochpound.hazard import HazardCurve
from stochpound.risk import (
    UNIDENTIFIED_BETA,
    at_lowest_stripe,
    beyond_model,
    fit_fragility,
    rate_collapses_apart,
    stripe_fragility,
    stripes_only_maf,
    unidentified,
)

LEVELS = [0.2, 0.5, 1.2]
K0, K = 1.0e-3, 2.0
HAZARD = HazardCurve.power_law(K0, K)
#: Peak storey drift ratio of every run (stripe x run): 0, 2 and 5 of 8 pass 5 % (collapses).
DRIFT = np.array([[0.004, 0.006, 0.008, 0.010, 0.012, 0.015, 0.018, 0.020], [0.010, 0.015, 0.020, 0.025, 0.030, 0.040, 0.060, 0.070], [0.020, 0.030, 0.045, 0.060, 0.070, 0.080, 0.090, 0.100]])
#: Another demand of the same runs (a base displacement, m).
DISPLACEMENT = np.array([[0.02, 0.03, 0.05, 0.06, 0.08, 0.10, 0.12, 0.15], [0.08, 0.10, 0.15, 0.20, 0.25, 0.30, 0.35, 0.40], [0.20, 0.25, 0.30, 0.35, 0.45, 0.55, 0.65, 0.80]])


def _runs(values: np.ndarray) -> xr.DataArray:
    return xr.DataArray(values, dims=("intensity", "record"), coords={"intensity": LEVELS, "record": np.arange(values.shape[1])})


def _hazard_density(im: float) -> float:
    """|dλ/dim| of the power law."""
    return K * K0 * im ** (-K - 1.0)


def _integral(probability) -> float:
    """∫ probability(im) |dλ(im)| by adaptive quadrature in ln im (an integrator independent of the code's trapezoids)."""
    value, _ = integrate.quad(lambda u: probability(math.exp(u)) * _hazard_density(math.exp(u)) * math.exp(u), math.log(1e-4), math.log(1e3), limit=400, points=[math.log(level) for level in LEVELS])
    return value


def _lognormal(theta: float, beta: float):
    return lambda im: stats.norm.cdf(math.log(im / theta) / beta)


def test_the_collapses_are_counted_by_hand():
    collapsed = beyond_model(_runs(DRIFT))
    np.testing.assert_array_equal(collapsed.sum("record").values, [0, 2, 5])
    drift = _runs(DRIFT).expand_dims(building=["B1", "B2"]).copy()
    drift[1] = 0.0  # the largest over the buildings counts
    np.testing.assert_array_equal(beyond_model(drift).values, collapsed.values)
    gaps = drift.where(drift > 0.015)  # a run that did not run stays NaN
    assert int(beyond_model(gaps).isnull().sum()) == int(gaps.max("building").isnull().sum()) > 0


def test_total_probability_against_hand_fits_and_quadrature():
    """P(C | IM) and P(D ≥ x | IM, no C) fitted by hand (fit_fragility of the counts below), their combination integrated by quad."""
    collapsed = beyond_model(_runs(DRIFT))
    threshold = 0.25
    rate, collapse, credible = rate_collapses_apart(_runs(DISPLACEMENT), collapsed, [threshold], "level", HAZARD)
    # by hand: collapses 0, 2, 5 of 8; the credible runs reaching 0.25 m: none of 8, 2 of 6 (0.25, 0.30), 2 of 3 (0.25, 0.30)
    hand_collapse = fit_fragility(LEVELS, [0, 2, 5], [8, 8, 8])
    hand_demand = fit_fragility(LEVELS, [0, 2, 2], [8, 6, 3])
    # the credible runs' fit handed back is the one combined: those counts and that fit
    np.testing.assert_array_equal(credible["exceeded"].squeeze().values, [0, 2, 2])
    np.testing.assert_array_equal(credible["runs"].squeeze().values, [8, 6, 3])
    assert float(credible["theta"].squeeze()) == pytest.approx(float(hand_demand.theta), rel=1e-9)
    assert float(credible["beta"].squeeze()) == pytest.approx(float(hand_demand.beta), rel=1e-9)
    # a collapse fit given is used, not refitted: the same rate from it
    again, given, _ = rate_collapses_apart(_runs(DISPLACEMENT), collapsed, [threshold], "level", HAZARD, collapse)
    assert given is collapse and float(again.squeeze()) == float(rate.squeeze())
    assert float(collapse["theta"]) == pytest.approx(float(hand_collapse.theta), rel=1e-9)
    assert float(collapse["beta"]) == pytest.approx(float(hand_collapse.beta), rel=1e-9)
    pc = _lognormal(float(hand_collapse.theta), float(hand_collapse.beta))
    pd = _lognormal(float(hand_demand.theta), float(hand_demand.beta))
    expected = _integral(lambda im: pc(im) + (1.0 - pc(im)) * pd(im))
    assert float(rate.sel(level=threshold)) == pytest.approx(expected, rel=2e-3)
    # the collapse rate alone has the closed form of a lognormal at a power law: k0 θ^-k exp((k β)² / 2)
    closed = K0 * float(hand_collapse.theta) ** -K * math.exp((K * float(hand_collapse.beta)) ** 2 / 2)
    assert float(collapse["maf"]) == pytest.approx(closed, rel=1e-6)
    # counting collapses apart adds rate: the combination is at least either part
    assert float(rate.sel(level=threshold)) > max(closed, _integral(pd)) * (1 - 2e-3)


def test_a_level_no_credible_run_reaches_has_the_collapse_rate_and_no_collapse_gives_the_fit_itself():
    collapsed = beyond_model(_runs(DRIFT))
    rate, collapse, _ = rate_collapses_apart(_runs(DISPLACEMENT), collapsed, [0.9], "level", HAZARD)
    assert float(rate.sel(level=0.9)) == pytest.approx(float(collapse["maf"]), rel=2e-3)
    none = beyond_model(_runs(DRIFT), limit=1.0)
    assert float(none.sum()) == 0.0
    rate, _, _ = rate_collapses_apart(_runs(DISPLACEMENT), none, [0.25], "level", HAZARD)
    fit = fit_fragility(LEVELS, [0, 4, 7], [8, 8, 8])  # every run reaching 0.25 m, by hand
    assert float(rate.sel(level=0.25)) == pytest.approx(_integral(_lognormal(float(fit.theta), float(fit.beta))), rel=2e-3)


def test_the_drift_limit_state_at_the_models_limit_is_the_collapse_rate_both_ways():
    """Drift ≥ 5 % as run counts the same runs the collapses are (none exactly at 5 %): its λ as run is λ_C, and with the
    collapses apart no credible run reaches it, so λ is λ_C again (the integrators agree to 2e-3)."""
    from stochpound.risk import limit_state_events, mean_annual_frequency

    drift = _runs(DRIFT)
    as_run = mean_annual_frequency(stripe_fragility(limit_state_events(drift, [0.05], "level"), bootstrap=0), HAZARD)
    apart, collapse, _ = rate_collapses_apart(drift, beyond_model(drift), [0.05], "level", HAZARD)
    assert float(as_run.squeeze()) == pytest.approx(float(collapse["maf"]), rel=1e-9)
    assert float(apart.squeeze()) == pytest.approx(float(collapse["maf"]), rel=2e-3)


def test_a_step_at_the_lowest_stripe_is_a_bound_from_the_stripes_alone():
    """Every run reaches 0.004 (always); 0.01 every run above the lowest stripe and 5 of 8 there (separated at the lowest stripe):
    λ⁻ = Σ p_j (λ(x_j) − λ(x_{j+1})); 0.03 (0, 4 and 7 of 8) is a lognormal."""
    events = xr.concat([_runs((DRIFT >= c).astype(float)) for c in (0.004, 0.010, 0.03)], "level").assign_coords(level=[0.004, 0.010, 0.03])
    fit = stripe_fragility(events, bootstrap=0)
    np.testing.assert_array_equal(at_lowest_stripe(fit).values, [True, True, False])
    rates = [K0 * x**-K for x in LEVELS]
    bound = stripes_only_maf(fit, HAZARD)
    assert float(bound.sel(level=0.004)) == pytest.approx(rates[0], rel=1e-12)
    hand = 5 / 8 * (rates[0] - rates[1]) + 1.0 * (rates[1] - rates[2]) + 1.0 * rates[2]
    assert float(bound.sel(level=0.010)) == pytest.approx(hand, rel=1e-12)


def test_the_stripes_bound_a_rate_from_above_and_the_fit_lies_between_the_bounds():
    """λ⁺ = p_1 (λ(lo) − λ(x_1)) + Σ_{j≥2} p_j (λ(x_{j−1}) − λ(x_j)) + λ(x_n), by hand at the power law and at a table hazard
    (lo = 0.05 g): the 0.03 drift (0, 4 and 7 of 8) and a level no run reaches (λ⁺ = λ(x_n): only the rate beyond the top
    stripe is left open); a lognormal through the stripes lies between λ⁻ and λ⁺."""
    from stochpound.risk import mean_annual_frequency, stripes_upper_maf

    events = xr.concat([_runs((DRIFT >= c).astype(float)) for c in (0.03, 1.0)], "level").assign_coords(level=[0.03, 1.0])
    fit = stripe_fragility(events, bootstrap=0)
    rates = [K0 * x**-K for x in LEVELS]
    upper = stripes_upper_maf(fit, HAZARD)  # no lower end: p_1 = 0 adds nothing (not 0 × inf)
    assert float(upper.sel(level=0.03)) == pytest.approx(4 / 8 * (rates[0] - rates[1]) + 7 / 8 * (rates[1] - rates[2]) + rates[2], rel=1e-12)
    assert float(upper.sel(level=1.0)) == pytest.approx(rates[2], rel=1e-12)
    lower = stripes_only_maf(fit, HAZARD)
    assert float(lower.sel(level=0.03)) == pytest.approx(4 / 8 * (rates[1] - rates[2]) + 7 / 8 * rates[2], rel=1e-12)
    assert float(lower.sel(level=1.0)) == 0.0
    assert float(lower.sel(level=0.03)) < float(mean_annual_frequency(fit, HAZARD).sel(level=0.03)) < float(upper.sel(level=0.03))
    table = HazardCurve([0.05, 0.2, 0.5, 1.2, 3.0], [K0 * x**-K for x in (0.05, 0.2, 0.5, 1.2, 3.0)])
    some = fit.assign(exceeded=fit["exceeded"] * 0 + xr.DataArray([1, 4, 7], dims="intensity", coords={"intensity": LEVELS}))
    hand = 1 / 8 * (K0 * 0.05**-K - rates[0]) + 4 / 8 * (rates[0] - rates[1]) + 7 / 8 * (rates[1] - rates[2]) + rates[2]
    assert float(stripes_upper_maf(some, table).sel(level=0.03)) == pytest.approx(hand, rel=1e-9)


def test_a_lognormal_beyond_the_top_stripe_or_too_wide_is_not_identified():
    events = np.zeros((3, 8))
    events[1, :1] = events[2, :2] = 1.0  # 0, 1 and 2 of 8: the median lies beyond the top stripe
    fit = stripe_fragility(_runs(events), bootstrap=0)
    assert float(fit["theta"]) > LEVELS[-1]
    assert "beyond the top stripe" in str(unidentified(fit).item())
    wide = xr.Dataset({"status": ("c", [0, 0, 1]), "theta": ("c", [0.5, 0.5, 0.5]), "beta": ("c", [0.4, UNIDENTIFIED_BETA, 0.0])}, coords={"intensity": LEVELS})
    assert list(unidentified(wide).values) == ["", f"β = {UNIDENTIFIED_BETA:.2g} ≥ {UNIDENTIFIED_BETA:g}", ""]


def test_the_level_at_a_targets_rate_is_read_off_each_curve_both_ways():
    """λ(D > x) = 1e-3 x^-2 as run, λ_C + that counted apart; at 10 % in 50 yr (2.107e-3 /yr) x = (1e-3/λ)^½, exact in log-log
    for the power law, and (1e-3/(λ − λ_C))^½ to the grid's interpolation counted apart; a λ_C above the target's rate: inf."""
    from stochpound.hazard import rate_from_probability
    from stochpound.risk import StoreDemands

    levels = np.geomspace(0.1, 10.0, 41)
    curve = xr.Dataset({"maf": ("level", 1e-3 * levels**-2.0)}, coords={"level": levels})
    for collapse, expected_inf in ((4.0e-4, False), (5.0e-3, True)):
        demands = StoreDemands({"d": curve}, {"d": "m"}, None, apart={"d": curve["maf"] + collapse})
        frame = demands.levels_at([0.1], 50.0)
        rate = float(rate_from_probability(0.1, 50.0))
        assert float(frame["as run"].iloc[0]) == pytest.approx(math.sqrt(1e-3 / rate), rel=1e-9)
        if expected_inf:
            assert math.isinf(frame["collapses apart"].iloc[0])
        else:
            assert float(frame["collapses apart"].iloc[0]) == pytest.approx(math.sqrt(1e-3 / (rate - collapse)), rel=2e-2)
    assert list(frame["demand"]) == ["d (m)"] and list(frame["target"]) == ["10 % in 50 yr"]


def test_a_collapse_fit_the_stripes_do_not_identify_is_said_so_with_its_bounds():
    """Issue 45: the flagships' P(C | IM) had θ = 2.88–6.71 beyond the top stripe 1.8 g and its λ_C was printed as identified. One
    collapse of 8 at the top stripe only: a step there, no lognormal; the text says so and gives λ⁻ = λ(x_3)/8 and
    λ⁺ = (λ(x_2) − λ(x_3))/8 + λ(x_3)."""
    from stochpound.risk._fragility import FIT

    from stochpound.risk import CollapseRisk
    from stochpound.risk._collapse import collapse_fit

    drift = _runs(np.where(np.arange(8)[None, :] < np.array([0, 0, 1])[:, None], 0.06, 0.01))
    collapse = collapse_fit(beyond_model(drift), HAZARD)
    assert int(collapse["status"]) != FIT
    rates = [K0 * x**-K for x in LEVELS]
    separation = xr.Dataset({"separation": ("target", [0.1])}, coords={"target": [0.1]})
    text = CollapseRisk(collapse, separation, xr.DataArray(0.0), 1, 24).text()
    low, high = rates[2] / 8, (rates[1] - rates[2]) / 8 + rates[2]
    assert (f"(the stripes do not identify P(C | IM) in 1 of 1 configurations: a step, or a lognormal with its median beyond the top "
            f"stripe or β ≥ 0.8, so λ_C there rests on the fit's extrapolation; the stripes' fractions alone bound it to {low:.3g}–{high:.3g} /yr)") in text
    identified = collapse_fit(beyond_model(_runs(DRIFT)), HAZARD)  # 0, 2 and 5 of 8: a lognormal within the stripes
    assert "do not identify" not in CollapseRisk(identified, separation, xr.DataArray(0.0), 7, 24).text()
    # the table of g* both ways gives those bounds beside λ_C where P(C | IM) is not identified
    from stochpound.risk._collapse import COLLAPSE_BOUNDS

    frame = CollapseRisk(collapse, xr.Dataset({"separation": ("target", [0.1])}, coords={"target": [0.1]}), xr.DataArray(0.0), 1,
                         24).both_ways(xr.Dataset({"separation": ("target", [0.1])}, coords={"target": [0.1]}))
    assert list(frame[COLLAPSE_BOUNDS]) == [f"[{low:.3g}, {high:.3g}]"]
