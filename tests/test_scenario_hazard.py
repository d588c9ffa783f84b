"""The hazard of a site of one scenario (stochpound.analysis.scenario_hazard) and the scenario's distribution of a measure
(stochpound.motions.scenario_distribution): closed forms, the conditional spectrum's own moments, and the consistency of the
site's curves with each other through the conditional spectrum (the total probability theorem, exact for one scenario)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import ndtr

from stochpound import SiteError
from stochpound.analysis import scenario_hazard, stripe_rate_weights
from stochpound.motions import conditional_spectrum, recomputed_hazard, scenario_distribution

SCENARIO = {"magnitude": 7.0, "distance_km": 20.0, "vs30": 400.0, "mechanism": "strike_slip"}
RATE = 0.05


@pytest.mark.parametrize(("measure", "period"), [("pga", None), ("psa", 1.0), ("psa", 3.0)])
def test_the_curve_is_the_rate_times_the_scenarios_lognormal_exceedance(measure: str, period: float | None) -> None:
    median, sigma = scenario_distribution(measure, period, **SCENARIO)
    curve = scenario_hazard(measure, period, **SCENARIO, rate=RATE)
    assert curve(median) == pytest.approx(RATE / 2, rel=1e-12)
    k = np.array([-2.0, -1.0, 0.5, 1.0, 2.0, 3.0, 1.0137, 2.4711])  # the last two between the table's intensities
    np.testing.assert_allclose(curve(median * np.exp(k * sigma)), RATE * ndtr(-k), rtol=2e-3)
    assert "M 7 at 20 km" in curve.source and curve.units == "g"
    assert curve.measure == ("PGA" if period is None else f"PSA({period:g} s)")
    assert scenario_hazard("sa_avg", [0.5, 1.0, 4.0], **SCENARIO, rate=RATE).measure == "Sa_avg(0.5-4 s)"


def test_the_scenarios_distribution_is_the_conditional_spectrums_own() -> None:
    """PSA(T): the conditional spectrum's unconditional median and σ, and its ε* is 0 at that median; Sa_avg: the geometric mean's
    moments from the periods' medians, σ and correlation (Baker–Jayaram, as the conditional spectrum reports it)."""
    median, sigma = scenario_distribution("psa", 2.0, **SCENARIO)
    cs = conditional_spectrum("psa", 2.0, level=median, periods=[2.0], **SCENARIO)
    assert float(cs["unconditional_median"][0]) == pytest.approx(median, rel=1e-12)
    assert float(cs["unconditional_sigma_ln"][0]) == pytest.approx(sigma, rel=1e-12)
    assert cs.attrs["epsilon"] == pytest.approx(0.0, abs=1e-12)
    periods = [1.0, 2.0, 3.0]
    average_median, average_sigma = scenario_distribution("sa_avg", periods, **SCENARIO)
    unconditional = conditional_spectrum("psa", 1.0, level=0.3, periods=periods, **SCENARIO)
    from pygmm.baker_jayaram_2008 import calc_correls

    s = unconditional["unconditional_sigma_ln"].values
    rho = np.array([calc_correls(np.array(periods), t) for t in periods])
    assert average_median == pytest.approx(float(np.exp(np.log(unconditional["unconditional_median"].values).mean())), rel=1e-12)
    assert average_sigma == pytest.approx(float(np.sqrt(s @ rho @ s) / len(periods)), rel=1e-12)


def test_the_sites_curves_follow_from_each_other_through_the_conditional_spectrum() -> None:
    """λ(Sa(T') > y) = Σ_j P(Sa(T') > y | PGA = x_j) Δλ_PGA(x_j): exact for one scenario, to the fine grid's discretisation."""
    pga = scenario_hazard("pga", **SCENARIO, rate=RATE)
    median, sigma = scenario_distribution("pga", **SCENARIO)
    levels = median * np.exp(sigma * np.linspace(-3.8, 5.8, 600))
    weights = stripe_rate_weights(levels, pga)
    for period in (1.0, 3.0):
        other = scenario_hazard("psa", period, **SCENARIO, rate=RATE)
        other_median, other_sigma = scenario_distribution("psa", period, **SCENARIO)
        y = other_median * np.exp(other_sigma * np.array([-1.0, 0.0, 1.0, 2.0, 3.0]))
        (recomputed,) = recomputed_hazard("pga", None, levels, weights, [SCENARIO] * levels.size, [(period, y, other(y))])
        np.testing.assert_allclose(recomputed, other(y), rtol=0.01)


@pytest.mark.parametrize(("change", "error", "field"), [
    ({"rate": 0.0}, ValueError, "rate:"),
    ({"rate": float("nan")}, ValueError, "rate:"),
    ({"rate": -0.1}, ValueError, "rate:"),
    ({"magnitude": 9.5}, SiteError, "magnitude:"),
    ({"mechanism": "oblique"}, SiteError, "mechanism:"),
])  # fmt: skip
def test_bad_input_is_one_line_naming_the_field(change: dict, error: type, field: str) -> None:
    arguments = {**SCENARIO, "rate": RATE, **change}
    with pytest.raises(error, match=field) as raised:
        scenario_hazard("psa", 1.0, **arguments)
    assert "\n" not in str(raised.value)
    with pytest.raises(SiteError, match="period:"):
        scenario_distribution("psa", None, **SCENARIO)
