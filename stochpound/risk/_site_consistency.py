"""A stripes store's hazard consistency: the site's hazard at its other periods recomputed from the motions as they ran.

For a store whose hazard is a bundled site's curve (the bundled Fox Plaza
site has PGA and PSA at 16 periods from 0.03 to 5 s), every other curve of that site is
recomputed from the stripes (:func:`stochpound.analysis.hazard_consistency`:
λ(Sa(T') > y) ≈ Σ_j P(Sa(T') > y | IM* = x_j) Δλ(x_j), P the fraction of
the stripe's motions, scaled as they ran, above y) and set against the
site's own curve. Sa(T') of a motion is its stored 5 %-damped spectrum
(``motion_psa``, interpolated log–log at T' as for measure efficiency) or its
PGA, times its scale factor in the stripe.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from stochpound.hazard import HazardCurve, bundled_measure, bundled_site_curves, hazard_consistency, rate_from_probability
from stochpound.risk._efficiency import _interpolated
from stochpound.risk._maf import TARGETS
from stochpound.risk._inputs import stripe_spectra_runs


def site_consistency(store: xr.Dataset) -> dict[str, xr.Dataset]:
    """Per other curve of the store's bundled site, its hazard recomputed from the stripes against its own (module docstring).

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store.

    Returns
    -------
    dict of str to xarray.Dataset
        Keyed by the other measure (``"PGA"``, ``"PSA(2 s)"``), in the bundled
        curves' order: :func:`~stochpound.risk.hazard_consistency`'s
        ``recomputed``, ``site`` (1/yr) and ``ratio`` over the curve's
        intensities ``im`` (g). Empty when the store has no stripes or its
        hazard is not a bundled curve of a site with curves at other periods.
    """
    runs = stripe_spectra_runs(store)
    if runs is None:
        return {}
    others = [name for name in bundled_site_curves(runs.bundled) if name != runs.bundled]
    results = {}
    for name in others:
        measure = bundled_measure(name)
        if measure.kind == "pga":
            unscaled = runs.pga
        else:
            unscaled = _interpolated(runs.psa, runs.spectrum_periods, [measure.period]).isel(period=0, drop=True)
        spectra = (unscaled / runs.g * runs.scale_factor).transpose("intensity", "record")
        results[measure.label] = hazard_consistency(spectra, runs.hazard, HazardCurve.bundled(name))
    return results


def consistency_at_targets(result: xr.Dataset, years: float = 50.0) -> np.ndarray:
    """The ratio recomputed / site (log–log interpolated in the site's rate) at the rates of ``TARGETS`` (10 % and 2 %) in ``years``.

    Parameters
    ----------
    result : xarray.Dataset
        One measure of :func:`site_consistency` (``site`` in 1/yr and ``ratio`` over ``im``).
    years : float
        The targets' time span, years.

    Returns
    -------
    numpy.ndarray
        One ratio per target; NaN where the site's curve does not reach the target's rate.
    """
    rates = rate_from_probability(np.asarray(TARGETS), years)
    site, ratio = result["site"].values, result["ratio"].values
    keep = (site > 0) & np.isfinite(ratio) & (ratio > 0)
    order = np.argsort(np.log(site[keep]))
    log_site, log_ratio = np.log(site[keep])[order], np.log(ratio[keep])[order]
    inside = (np.log(rates) >= log_site[0]) & (np.log(rates) <= log_site[-1]) if log_site.size else np.zeros(rates.size, bool)
    return np.where(inside, np.exp(np.interp(np.log(rates), log_site, log_ratio)) if log_site.size else np.nan, np.nan)
