"""The shares of the pounding rate at g* from shaking the stripes did not run (stochpound.risk.maf_outside_stripes)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from scipy import integrate, stats

from stochpound.motions import Measure
from stochpound.risk import HazardCurve, maf_outside_stripes, mean_annual_frequency
from stochpound.store import Intensity

K0, K = 2.0e-4, 2.4
LEVELS = np.array([0.2, 0.4, 0.8])
GAPS = np.array([0.01, 0.02, 0.04, 0.08])
_SETTING = Intensity(Measure("pga"), "g", tuple(LEVELS), "stripes", "stripes", "")


def _fit(theta: np.ndarray, beta: np.ndarray) -> xr.Dataset:
    return xr.Dataset({"theta": ("gap", theta), "beta": ("gap", beta)}, coords={"gap": GAPS, "intensity": ("intensity", LEVELS)})


def _partial(theta: float, beta: float, upper: float) -> float:
    """∫_0^upper F |dλ| for λ = K0 x^-K, by adaptive quadrature in ln x (independent of the module's sums)."""
    def integrand(u: float) -> float:
        return stats.norm.cdf((u - np.log(theta)) / beta) * K * K0 * np.exp(-K * u)
    return integrate.quad(integrand, np.log(theta) - 12 * beta, np.log(upper), limit=200)[0]


def test_the_shares_match_a_quadrature_of_the_integral_below_and_above_the_stripes() -> None:
    hz = HazardCurve.power_law(K0, K)
    fit = _fit(0.5 * GAPS / 0.02, np.full(GAPS.size, 0.6))  # θ = 0.5 g at 0.02 m, growing with the gap
    separation = xr.DataArray([0.02, 0.04], dims="target", coords={"target": [0.1, 0.02]})
    shares = maf_outside_stripes(fit, separation, hz)
    for theta, beta, below, above in zip(shares["theta"].values, shares["beta"].values, shares["below"].values, shares["above"].values):
        total = K0 * theta ** (-K) * np.exp(0.5 * K**2 * beta**2)
        assert below == pytest.approx(_partial(theta, beta, LEVELS[0]) / total, rel=2e-3)
        kept = _partial(theta, beta, LEVELS[-1]) + stats.norm.cdf(np.log(LEVELS[-1] / theta) / beta) * K0 * LEVELS[-1] ** (-K)
        assert above == pytest.approx(1.0 - kept / total, abs=2e-4)
        assert 0.0 < below < 1.0 and 0.0 < above < 1.0


def test_the_fit_at_g_star_is_interpolated_in_ln_g_and_the_total_is_the_chains_maf() -> None:
    hz = HazardCurve.bundled("fox_plaza_los_angeles_sa1p0s")
    fit = _fit(np.array([0.2, 0.4, 0.8, 1.6]), np.array([0.4, 0.5, 0.6, 0.7]))
    shares = maf_outside_stripes(fit, xr.DataArray(np.sqrt(0.02 * 0.04)), hz)  # halfway between two gaps in ln g
    assert float(shares["theta"]) == pytest.approx(np.sqrt(0.4 * 0.8)) and float(shares["beta"]) == pytest.approx(0.55)
    total = float(mean_annual_frequency(xr.Dataset({"theta": shares["theta"], "beta": shares["beta"]}), hz))
    lo = hz.support[0]
    x = np.geomspace(lo, LEVELS[0], 20001)
    below = np.sum(stats.norm.cdf(np.log(np.sqrt(x[1:] * x[:-1]) / float(shares["theta"])) / 0.55) * -np.diff(hz(x)))
    assert float(shares["below"]) == pytest.approx(below / total, rel=1e-3)


def test_stripes_that_cover_the_whole_table_leave_nothing_outside() -> None:
    hz = HazardCurve.bundled("fox_plaza_los_angeles_sa1p0s")
    fit = _fit(np.array([0.2, 0.4, 0.8, 1.6]), np.full(4, 0.5)).assign_coords(intensity=("intensity", [hz.support[0], 1.0, hz.support[1]]))
    shares = maf_outside_stripes(fit, xr.DataArray([0.015, 0.05], dims="target"), hz)
    np.testing.assert_allclose(shares["below"], 0.0, atol=1e-12)
    np.testing.assert_allclose(shares["above"], 0.0, atol=1e-4)  # the sums against the chain's Gauss-Legendre quadrature of the total


def test_a_g_star_off_the_grid_gives_nan_not_a_number_made_up() -> None:
    hz = HazardCurve.power_law(K0, K)
    shares = maf_outside_stripes(_fit(GAPS * 10, np.full(GAPS.size, 0.5)), xr.DataArray([np.inf, 0.5, 0.02], dims="target"), hz)
    assert np.isnan(shares["below"].values[:2]).all() and np.isfinite(shares["below"].values[2])


@pytest.mark.parametrize(("lowest", "notable"), [(0.2, True), (0.005, False)])
def test_the_report_states_the_shares_it_computes_and_says_when_the_answer_rests_on_the_extrapolation(lowest: float, notable: bool) -> None:
    """The Risk section's sentence carries the worst configuration's shares per target, and the warning only from 10 % up."""
    from stochpound.report.sections._risk import OUTSIDE_STRIPES_NOTABLE, _outside_stripes_text
    from stochpound.risk import StoreRisk

    hz = HazardCurve.power_law(K0, K)
    fit = _fit(np.array([0.1, 0.2, 0.4, 0.8]), np.full(4, 0.9)).assign_coords(intensity=("intensity", [lowest, 0.4, 0.8]))
    separation = xr.Dataset({"separation": ("target", [0.02, 0.04])}, coords={"target": [0.1, 0.02]})
    risk = StoreRisk(fit, xr.Dataset(), separation, None, "", hz, 20, "stripes", setting=_SETTING)
    shares = maf_outside_stripes(fit, separation["separation"], hz)
    text = _outside_stripes_text(risk)
    worst = float(shares["below"].max())
    assert (worst >= OUTSIDE_STRIPES_NOTABLE) is notable
    assert f"{100 * float(shares['below'].sel(target=0.1)):.0f} % for 10 % in 50 yr" in text or "under 1 % for 10 % in 50 yr" in text
    assert ("rests on the fitted fragility's extrapolation" in text) is notable
    assert f"({lowest:.3g} g, once in {1.0 / float(hz(lowest)):.3g} yr)" in text


@pytest.mark.parametrize(("lowest", "notable"), [(0.2, True), (0.005, False)])
def test_the_design_summary_lists_the_shaking_below_the_stripes_among_what_the_answer_rests_on_when_it_matters(lowest: float, notable: bool) -> None:
    from stochpound.report.sections._risk import _outside_stripes_assumption
    from stochpound.risk import StoreRisk

    hz = HazardCurve.power_law(K0, K)
    fit = _fit(np.array([0.1, 0.2, 0.4, 0.8]), np.full(4, 0.9)).assign_coords(intensity=("intensity", [lowest, 0.4, 0.8]))
    separation = xr.Dataset({"separation": ("target", [0.02, 0.04])}, coords={"target": [0.1, 0.02]})
    entry = _outside_stripes_assumption(StoreRisk(fit, xr.Dataset(), separation, None, "", hz, 20, "stripes", setting=_SETTING))
    assert bool(entry) is notable
    if notable:
        share = float(maf_outside_stripes(fit, separation["separation"], hz)["below"].sel(target=0.1))
        assert entry["shaking below the stripes"].startswith(f"{100 * share:.0f} % for 10 % in 50 yr")
