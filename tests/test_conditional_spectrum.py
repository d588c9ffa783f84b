"""conditional_spectrum against an independent computation: the four pygmm models called here, Baker & Jayaram (2008) coded from the paper."""

from __future__ import annotations

import math

import numpy as np
import pygmm
import pytest

from stochpound import SiteError
from stochpound.motions import conditional_spectrum

SCENARIO = dict(magnitude=7.0, distance_km=12.0, vs30=450.0)
PERIODS = [0.02, 0.1, 0.15, 0.3, 0.5, 1.0, 2.0, 4.0]


def bj08(t1: float, t2: float) -> float:
    """Baker & Jayaram (2008), Earthquake Spectra 24(1), eq. (C1)-(C4) and the four cases."""
    t_min, t_max = min(t1, t2), max(t1, t2)
    c1 = 1.0 - math.cos(math.pi / 2.0 - 0.366 * math.log(t_max / max(t_min, 0.109)))
    c2 = 1.0 - 0.105 * (1.0 - 1.0 / (1.0 + math.exp(100.0 * t_max - 5.0))) * (t_max - t_min) / (t_max - 0.0099) if t_max < 0.2 else 0.0
    c3 = c2 if t_max < 0.109 else c1
    c4 = c1 + 0.5 * (math.sqrt(c3) - c3) * (1.0 + math.cos(math.pi * t_min / 0.109))
    if t_max < 0.109:
        return c2
    if t_min > 0.109:
        return c1
    if t_max < 0.2:
        return min(c2, c4)
    return c4


def models(mechanism: str, dip: float) -> list:
    scenario = pygmm.Scenario(
        mag=SCENARIO["magnitude"], dist_rup=SCENARIO["distance_km"], dist_jb=SCENARIO["distance_km"], dist_x=-SCENARIO["distance_km"],
        v_s30=SCENARIO["vs30"], mechanism=mechanism, dip=dip, depth_tor=0.0,
    )  # fmt: skip
    classes = (pygmm.AbrahamsonSilvaKamai2014, pygmm.BooreStewartSeyhanAtkinson2014, pygmm.CampbellBozorgnia2014, pygmm.ChiouYoungs2014)
    return [model(scenario) for model in classes]


def moments(gmms: list, period: float | None) -> tuple[float, float]:
    """Average model at a period (None: PGA): mean ln median, √(mean σ²)."""
    if period is None:
        return np.mean([np.log(m.pga) for m in gmms]), math.sqrt(np.mean([m.ln_std_pga**2 for m in gmms]))
    mu = np.mean([m.interp_ln_spec_accels([period])[0] for m in gmms])
    return mu, math.sqrt(np.mean([m.interp_ln_stds([period])[0] ** 2 for m in gmms]))


@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.parametrize("measure, period, level", [("psa", 1.0, 0.6), ("psa", 0.15, 1.1), ("pga", None, 0.5)])
def test_single_period_conditioning_matches_baker_2011(measure: str, period: float | None, level: float) -> None:
    gmms = models("SS", 90.0)
    mu_star, sigma_star = moments(gmms, period)
    epsilon = (math.log(level) - mu_star) / sigma_star
    cs = conditional_spectrum(measure, period, level=level, periods=PERIODS, mechanism="strike_slip", **SCENARIO)
    assert cs.attrs["epsilon"] == pytest.approx(epsilon, rel=0.01)
    for t in PERIODS:
        mu, sigma = moments(gmms, t)
        rho = bj08(t, 0.01 if period is None else period)
        assert float(cs["median"].sel(period=t)) == pytest.approx(math.exp(mu + rho * epsilon * sigma), rel=0.01)
        assert float(cs["sigma_ln"].sel(period=t)) == pytest.approx(sigma * math.sqrt(max(1 - rho * rho, 0.0)), rel=0.01, abs=1e-6)


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_sa_avg_conditioning_matches_the_multivariate_normal() -> None:
    average = [0.3, 0.6, 1.2, 2.4]
    gmms = models("RS", 40.0)
    mus, sigmas = zip(*(moments(gmms, t) for t in average))
    n = len(average)
    variance = sum(bj08(a, b) * sa * sb for a, sa in zip(average, sigmas) for b, sb in zip(average, sigmas)) / n**2
    level = 0.4
    epsilon = (math.log(level) - sum(mus) / n) / math.sqrt(variance)
    cs = conditional_spectrum("sa_avg", average, level=level, periods=PERIODS, mechanism="reverse", **SCENARIO)
    assert cs.attrs["epsilon"] == pytest.approx(epsilon, rel=0.01)
    for t in PERIODS:
        mu, sigma = moments(gmms, t)
        rho = sum(bj08(t, a) * sa for a, sa in zip(average, sigmas)) / n / math.sqrt(variance)
        assert float(cs["median"].sel(period=t)) == pytest.approx(math.exp(mu + rho * epsilon * sigma), rel=0.01)
        assert float(cs["sigma_ln"].sel(period=t)) == pytest.approx(sigma * math.sqrt(1 - rho * rho), rel=0.01)


def test_at_the_conditioning_period_the_median_is_the_level_and_sigma_zero() -> None:
    cs = conditional_spectrum("psa", 2.0, level=0.35, periods=[0.1, 2.0, 5.0], mechanism="normal", **SCENARIO)
    assert float(cs["median"].sel(period=2.0)) == pytest.approx(0.35, rel=1e-12)
    assert float(cs["sigma_ln"].sel(period=2.0)) < 1e-7
    assert float(cs["sigma_ln"].sel(period=0.1)) > 0.3


@pytest.mark.parametrize(
    "change, field",
    [
        (dict(periods=[0.005, 1.0]), "periods"),
        (dict(periods=[1.0, 12.0]), "periods"),
        (dict(period=15.0), "period"),
        (dict(mechanism="oblique"), "mechanism"),
        (dict(magnitude=9.2), "magnitude"),
        (dict(vs30=90.0), "vs30"),
        (dict(distance_km=400.0), "distance_km"),
        (dict(measure="pgv"), "measure"),
        (dict(level=-0.1), "level"),
        (dict(damping=0.02), "damping"),
        (dict(measure="pga"), "period"),
    ],
)
def test_bad_input_is_one_line_naming_the_field(change: dict, field: str) -> None:
    arguments = dict(measure="psa", period=1.0, level=0.5, periods=[0.1, 1.0], mechanism="strike_slip", **SCENARIO) | change
    with pytest.raises(SiteError) as error:
        conditional_spectrum(**arguments)
    assert str(error.value).startswith(f"{field}:") and "\n" not in str(error.value)
