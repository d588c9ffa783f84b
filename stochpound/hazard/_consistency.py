"""Hazard consistency of stripes of motions: the hazard at another period recomputed from them.

Stripes conditioned on IM* at levels x_1 < … < x_m, each holding motions
(scaled to its level), represent the site if the distribution of any other
measure Sa(T') among a stripe's motions is the site's given IM* = x_j. Then
the total probability theorem gives the hazard of Sa(T') back (Lin, Haselton
& Baker 2013):

    λ(Sa(T') > y) ≈ Σ_j P(Sa(T') > y | IM* = x_j) Δλ_IM*(x_j),

with P the fraction of the stripe's motions whose Sa(T') exceeds y (the
motions as they ran, scaled), and Δλ(x_j) the rate of IM* in the bin of
x_j: the bins' edges are the geometric midpoints of consecutive levels, the
first bin starts half a step (in ln x) below x_1 and the last has no upper
end (it takes the whole tail, λ at its lower edge). Intensities below the
first edge are left out, so at small y the recomputed rate falls short of
the site's by about λ_IM*(first edge) times the fraction of those weaker
motions that would exceed y; compare where the stripes cover the rates of
interest. A selection consistent with the site's hazard reproduces the
site's own curve at T'; a suite scaled without regard to spectral shape does
not.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from stochpound.hazard._curve import HazardCurve


def stripe_rate_weights(levels: np.ndarray, hazard: HazardCurve, field: str = "levels") -> np.ndarray:
    """Δλ(x_j) of every stripe: the rate of IM* in the bin of its level (module docstring), 1/yr.

    Parameters
    ----------
    levels : array of float
        The stripes' levels of IM*, increasing (at least 2).
    hazard : HazardCurve
        The site's hazard of IM* (it must cover the bins' edges).
    field : str
        The name of ``levels`` in the error message.
    """
    levels = np.asarray(levels, dtype=float)
    if levels.ndim != 1 or levels.size < 2 or not np.all(np.diff(levels) > 0):
        raise ValueError(f"{field}: needs at least 2 increasing levels, got {levels.tolist()}")
    log_levels = np.log(levels)
    middle = (log_levels[1:] + log_levels[:-1]) / 2.0
    edges = np.exp(np.concatenate([[log_levels[0] - (middle[0] - log_levels[0])], middle]))
    rates = hazard(edges)
    return np.append(rates[:-1] - rates[1:], rates[-1])


def hazard_consistency(spectra: xr.DataArray, hazard: HazardCurve, other: HazardCurve, intensity_dim: str = "intensity",
                       record_dim: str = "record") -> xr.Dataset:
    """The hazard of another measure recomputed from stripes of motions, against the site's own curve (module docstring).

    Parameters
    ----------
    spectra : xarray.DataArray
        The other measure (e.g. Sa(T') in g) of every motion as it ran in
        every stripe, over ``intensity_dim`` (the levels of IM*, its
        coordinate) and ``record_dim``; NaN where a motion did not run in a stripe.
    hazard : HazardCurve
        The site's hazard of IM*, the stripes' measure (it must cover the bins' edges).
    other : HazardCurve
        The site's hazard of the other measure; the comparison is at its tabulated intensities.

    Returns
    -------
    xarray.Dataset
        Over ``im`` (the other curve's intensities): ``recomputed`` and
        ``site`` (annual rates, 1/yr) and their ``ratio`` (recomputed / site);
        ``rate_weight`` (``intensity_dim``): Δλ of every stripe.
    """
    levels = np.asarray(spectra[intensity_dim].values, dtype=float)
    weights = stripe_rate_weights(levels, hazard, "spectra")
    values = np.asarray(spectra.transpose(intensity_dim, record_dim).values, dtype=float)
    valid = np.isfinite(values)
    if not valid.any(axis=1).all():
        raise ValueError("spectra: a stripe without any motion")
    y = np.asarray(other.im, dtype=float)
    exceed = (values[:, :, None] > y[None, None, :]) & valid[:, :, None]
    fraction = exceed.sum(axis=1) / valid.sum(axis=1)[:, None]
    recomputed = weights @ fraction
    site = other(y)
    return xr.Dataset(
        {
            "recomputed": ("im", recomputed, {"units": "1/yr", "long_name": "rate of exceedance recomputed from the stripes"}),
            "site": ("im", site, {"units": "1/yr", "long_name": "the site's rate of exceedance"}),
            "ratio": ("im", recomputed / site, {"units": "1", "long_name": "recomputed / site"}),
            "rate_weight": (intensity_dim, weights, {"units": "1/yr", "long_name": "rate of the stripe's bin of the conditioning measure"}),
        },
        coords={"im": ("im", y, {"units": other.units}), intensity_dim: levels},
    )
