"""A stripes store's hazard consistency: the site's hazard at its other periods recomputed from the motions as they ran.

For a store whose hazard is a bundled site's curve (the bundled Fox Plaza
site has PGA and PSA at 16 periods from 0.03 to 5 s), every other curve of that site, or any
curve given (of PGA, PSA(T') or Sa_avg), is recomputed from the stripes (:func:`stochpound.analysis.hazard_consistency`:
λ(Sa(T') > y) ≈ Σ_j P(Sa(T') > y | IM* = x_j) Δλ(x_j), P the fraction of
the stripe's motions, scaled as they ran, above y) and set against the
site's own curve. Sa(T') of a motion is its stored 5 %-damped spectrum
(``motion_psa``, interpolated log–log at T' as for measure efficiency; Sa_avg
the geometric mean of those at its periods) or its PGA, times its scale factor
in the stripe.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import xarray as xr

from stochpound.motions import MODEL_DAMPING, Measure
from stochpound.hazard import HazardCurve, bundled_measure, bundled_site_curves, hazard_consistency, rate_from_probability
from stochpound.risk._efficiency import _interpolated
from stochpound.risk._maf import TARGETS
from stochpound.risk._inputs import StripeSpectraRuns, stripe_spectra_runs


def site_consistency(store: xr.Dataset, curves: Mapping[Measure, HazardCurve] | None = None,
                     hazard: HazardCurve | None = None) -> dict[str, xr.Dataset]:
    """Per other curve of the store's site, its hazard recomputed from the stripes against its own (module docstring).

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store.
    curves : mapping of Measure to HazardCurve, optional
        The curves to check (PGA, PSA at a period or Sa_avg over periods within the stored spectrum's, its intensities in g),
        by their measure; default: every other curve of the store's bundled site.
    hazard : HazardCurve, optional
        The hazard of the stripes' own measure (default: the store's); needed for a store that carries none (a site given to
        the risk as curves).

    Returns
    -------
    dict of str to xarray.Dataset
        Keyed by the measure's label (``"PGA"``, ``"PSA(2 s)"``), in the
        curves' order: :func:`~stochpound.risk.hazard_consistency`'s
        ``recomputed``, ``site`` (1/yr) and ``ratio`` over the curve's
        intensities ``im`` (g). Empty when the store has no stripes or no
        hazard, or, without ``curves``, its hazard is not a bundled curve of a
        site with curves at other periods.

    Raises
    ------
    ValueError
        Naming ``curves``: a measure the stored motions do not give (PGV, or a period outside the stored spectrum's).
    """
    runs = stripe_spectra_runs(store, hazard)
    if runs is None:
        return {}
    if curves is None:
        if runs.bundled is None:
            return {}
        curves = {bundled_measure(name): HazardCurve.bundled(name) for name in bundled_site_curves(runs.bundled) if name != runs.bundled}
    else:
        for measure in curves:
            _check_stored(measure, runs.spectrum_periods)
    return {measure.label: hazard_consistency((_unscaled(runs, measure) / runs.g * runs.scale_factor).transpose("intensity", "record"),
                                              runs.hazard, curve)
            for measure, curve in curves.items()}


def _unscaled(runs: StripeSpectraRuns, measure: Measure) -> xr.DataArray:
    """Each motion's ``measure`` at scale 1 (m/s²): its PGA, or its PSA interpolated log–log at the measure's period(s) (Sa_avg:
    their geometric mean)."""
    if measure.kind == "pga":
        return runs.pga
    psa = _interpolated(runs.psa, runs.spectrum_periods, list(np.atleast_1d(measure.spectral_period)))
    return psa.isel(period=0, drop=True) if measure.kind == "psa" else np.exp(np.log(psa).mean("period"))


def _check_stored(measure: Measure, spectrum_periods: np.ndarray) -> None:
    """ValueError naming ``curves`` unless the stored motions give ``measure`` (PGA, or spectral periods within the stored ones)."""
    if measure.kind == "pgv":
        raise ValueError(f"curves: {measure.label} is not recomputed from the stored motions (PGA, PSA and Sa_avg are)")
    if measure.damping not in (None, MODEL_DAMPING):
        raise ValueError(f"curves: {measure.description} needs the spectrum at its damping; the store holds it at {MODEL_DAMPING:g}")
    periods = np.atleast_1d(measure.spectral_period) if measure.is_spectral else None
    if periods is not None and not (spectrum_periods[0] * (1 - 1e-9) <= periods.min() and periods.max() <= spectrum_periods[-1] * (1 + 1e-9)):
        raise ValueError(f"curves: {measure.label} needs the spectrum at {min(periods):g}-{max(periods):g} s; the store holds "
                         f"{spectrum_periods[0]:g}-{spectrum_periods[-1]:g} s")


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
