"""hazard_consistency against the closed form of a power-law hazard and lognormal conditional spectra."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from scipy.stats import norm

from stochpound.analysis import HazardCurve, hazard_consistency


def test_the_recomputed_hazard_matches_the_closed_form() -> None:
    """λ(x) = k0 x^-k and Sa' = c x e^(β z): λ'(y) = k0 (y/c)^-k exp(k² β² / 2) exactly."""
    k0, k, c, beta = 1e-4, 2.5, 0.6, 0.45
    levels = np.geomspace(0.005, 30.0, 160)
    z = norm.ppf((np.arange(400) + 0.5) / 400)  # the motions: quantiles of a standard normal
    spectra = xr.DataArray(c * levels[:, None] * np.exp(beta * z[None, :]), dims=("intensity", "record"), coords={"intensity": levels})
    y = np.geomspace(0.1, 1.5, 9)
    exact = k0 * (y / c) ** -k * np.exp(k * k * beta * beta / 2)
    result = hazard_consistency(spectra, HazardCurve.power_law(k0, k), HazardCurve(y, exact))
    np.testing.assert_allclose(result["recomputed"].values, exact, rtol=0.03)
    np.testing.assert_allclose(result["ratio"].values, 1.0, atol=0.03)
    # a shape that is not the site's: the recomputed curve misses it by the factor exp(k ln 1.5)
    biased = hazard_consistency(spectra * 1.5, HazardCurve.power_law(k0, k), HazardCurve(y, exact))
    np.testing.assert_allclose(biased["ratio"].values, 1.5**k, rtol=0.05)


def test_motions_missing_from_a_stripe_are_left_out() -> None:
    levels = np.array([0.1, 0.2, 0.4])
    values = np.array([[0.05, 0.2, np.nan], [0.1, np.nan, 0.4], [0.2, 0.8, np.nan]])
    spectra = xr.DataArray(values, dims=("intensity", "record"), coords={"intensity": levels})
    hz = HazardCurve.power_law(1e-3, 2.0)
    result = hazard_consistency(spectra, hz, HazardCurve([0.15, 0.3], [1e-2, 1e-3]))
    edges = np.array([0.1 / np.sqrt(2), 0.1 * np.sqrt(2), 0.2 * np.sqrt(2)])
    weights = np.append(hz(edges)[:-1] - hz(edges)[1:], hz(edges)[-1])
    np.testing.assert_allclose(result["rate_weight"].values, weights, rtol=1e-12)
    expected = [weights[0] * 0.5 + weights[1] * 0.5 + weights[2] * 1.0, weights[0] * 0.0 + weights[1] * 0.5 + weights[2] * 0.5]
    np.testing.assert_allclose(result["recomputed"].values, expected, rtol=1e-12)
    with pytest.raises(ValueError, match="^spectra:"):
        hazard_consistency(spectra.isel(intensity=[0]), hz, hz)
