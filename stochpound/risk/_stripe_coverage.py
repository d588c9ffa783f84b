"""How much of the pounding rate at g* comes from shaking the stripes did not run: below the lowest stripe and above the top one.

The MAF λ_P = ∫ F(x) ``|dλ(x)|`` counts every intensity of the hazard's
range, but the stripes only observe F between the lowest level x_1 and the
top one x_n; outside, the fitted lognormal is extrapolated. At g* of each
configuration and target, with F the lognormal fitted there (θ and β
interpolated between the grid's gaps, linearly in ln g):

* ``below``: the share of λ_P owed to shaking weaker than x_1,
  ∫ F |dλ| from the hazard's lower end to x_1, over λ_P;
* ``above``: the share owed to the fitted fragility's rise beyond x_n,
  1 − λ⁻/λ_P, λ⁻ = ∫ F |dλ| up to x_n + F(x_n) λ(x_n): the rate above
  x_n counted at the top stripe's F, not at the extrapolated rise.

Both partial integrals are sums over 4000 log-spaced intensities (a power
law from where F is 10⁻¹⁵ of its median, 8 β below θ).

A large ``below`` share (a measure far from the structure's periods, whose
frequent, weak shaking still pounds) means g* rests on an extrapolation:
stripes at more frequent intensities replace it by runs.

λ⁻ itself, at every gap of the grid (:func:`top_capped_maf`), is a lower
bound of λ_P that rests on the runs alone (F does not fall with intensity,
so beyond x_n it is at least F(x_n)): the gap where λ⁻ meets a target is a
lower bound of g*, the answer for a target rarer than the stripes reach.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from stochpound.hazard import HazardCurve
from stochpound.risk._fragility import ALWAYS, FIT, SEPARATED, lognormal_cdf
from stochpound.risk._maf import mean_annual_frequency

_POINTS = 4000


def fragility_at_separation(fragility: xr.Dataset, separation: xr.DataArray) -> xr.Dataset:
    """θ (IM units) and β of the fitted fragility at each g* (m), interpolated between the grid's gaps linearly in ln g.

    Parameters
    ----------
    fragility : xarray.Dataset
        ``theta`` and ``beta`` over ``gap`` (m, ascending) and the configurations.
    separation : xarray.DataArray
        g* (m) over the configurations and, e.g., ``target``.

    Returns
    -------
    xarray.Dataset
        ``theta`` (ln θ interpolated) and ``beta`` over the dimensions of
        ``separation``; NaN where g* is not finite or lies outside the gap grid.
    """

    def interpolate(values: np.ndarray, gaps: np.ndarray, at: np.ndarray, log: bool) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            inside = np.isfinite(at) & (at >= gaps[0]) & (at <= gaps[-1])
            where = np.log(np.where(inside, at, gaps[0]))
            table = np.log(values) if log else values
            out = np.interp(where, np.log(gaps), table)
        return np.where(inside, np.exp(out) if log else out, np.nan)

    gaps = np.asarray(fragility["gap"].values, dtype=float)
    parts = {}
    for name, log in (("theta", True), ("beta", False)):
        parts[name] = xr.apply_ufunc(lambda values, at, log=log: interpolate(values, gaps, at, log), fragility[name], separation,
                                     input_core_dims=[["gap"], []], vectorize=True)
    return xr.Dataset(parts)


def maf_outside_stripes(fragility: xr.Dataset, separation: xr.DataArray, hz: HazardCurve) -> xr.Dataset:
    """The shares of λ_P at g* from below the lowest stripe (``below``) and beyond the top one (``above``), module docstring.

    Parameters
    ----------
    fragility : xarray.Dataset
        A stripes fit over ``gap`` (:func:`~stochpound.risk.pounding_fragility`), with its ``intensity`` coordinate.
    separation : xarray.DataArray
        g* (m) per configuration and target (:func:`~stochpound.risk.risk_targeted_separation`'s ``separation``).
    hz : HazardCurve
        The site's hazard the fit was integrated with.

    Returns
    -------
    xarray.Dataset
        ``below`` and ``above`` (fractions of λ_P at g*), ``theta`` and ``beta``
        of the fit at g*, over the dimensions of ``separation``; NaN where g* is not finite.
    """
    levels = np.asarray(fragility["intensity"].values, dtype=float)
    at = fragility_at_separation(fragility, separation)
    total = mean_annual_frequency(at, hz)
    below, middle = (xr.apply_ufunc(lambda t, b, upper=upper: _rate_between(t, b, hz, upper), at["theta"], at["beta"], vectorize=True)
                     for upper in (float(levels.min()), float(levels.max())))
    top = float(min(levels.max(), hz.support[1]))
    at_top = xr.apply_ufunc(lambda t, b: lognormal_cdf(top, t, b), at["theta"], at["beta"]) * float(hz(top))
    with np.errstate(divide="ignore", invalid="ignore"):
        shares = {"below": below / total, "above": 1.0 - (middle + at_top) / total}
    return xr.Dataset({"below": shares["below"].assign_attrs(units="1", long_name="share of the MAF at g* from below the lowest stripe"),
                       "above": shares["above"].assign_attrs(units="1", long_name="share of the MAF at g* from the fragility's rise beyond the top stripe"),
                       "theta": at["theta"], "beta": at["beta"]})


def top_capped_maf(fragility: xr.Dataset, hz: HazardCurve) -> xr.DataArray:
    """λ⁻ (1/yr) of every fit: its MAF with the fragility beyond the top stripe held at its value there (module docstring).

    λ⁻ = ∫ F |dλ| up to the top stripe's level x_n + F(x_n) λ(x_n) for a
    lognormal fit. A ``separated`` step whose top stripe's runs did not all
    exceed (none below it, k of n at it: the likelihood's step at x_n says
    F = 1 beyond, the runs say k/n) gives the fraction that exceeded at x_n,
    k/n λ(x_n). Any other step or flat fit keeps its MAF
    (:func:`~stochpound.risk.mean_annual_frequency`): it does not rise beyond the runs.

    Parameters
    ----------
    fragility : xarray.Dataset
        A stripes fit (:func:`~stochpound.risk.pounding_fragility`), with its ``intensity`` coordinate.
    hz : HazardCurve
        The site's hazard the fit is integrated with.

    Returns
    -------
    xarray.DataArray
        λ⁻ over the fit's dimensions (e.g. ``gap`` and the configurations), ≤ the MAF.
    """
    top = float(min(np.max(fragility["intensity"].values), hz.support[1]))
    middle = xr.apply_ufunc(lambda t, b: _rate_between(t, b, hz, top), fragility["theta"], fragility["beta"], vectorize=True)
    at_top = xr.apply_ufunc(lambda t, b: lognormal_cdf(top, t, b), fragility["theta"], fragility["beta"]) * float(hz(top))
    exceeded, runs = (fragility[name].sel(intensity=fragility["intensity"].max(), drop=True) for name in ("exceeded", "runs"))
    fraction = exceeded / runs.where(runs > 0)
    step = mean_annual_frequency(fragility, hz).where((fragility["status"] != SEPARATED) | ~(fraction < 1.0), fraction * float(hz(top)))
    return step.where(fragility["status"] != FIT, middle + at_top)


def _rate_between(theta: float, beta: float, hz: HazardCurve, upper: float) -> float:
    """∫ F |dλ| from the hazard's lower end (a power law: where F is 10⁻¹⁵ of its median) to ``upper``, 1/yr (NaN for a NaN fit)."""
    if not (np.isfinite(theta) and np.isfinite(beta)) or theta <= 0.0:
        return np.nan
    low, high = hz.support
    start = low if low > 0.0 else theta * np.exp(-8.0 * max(beta, 1e-3))
    end = min(upper, high)
    if end <= start:
        return 0.0
    x = np.geomspace(start, end, _POINTS)
    rate = hz(x)
    middle = np.sqrt(x[1:] * x[:-1])
    return float(np.sum(lognormal_cdf(middle, theta, beta) * (rate[:-1] - rate[1:])))


def at_lowest_stripe(fragility: xr.Dataset, lowest: float | None = None) -> xr.DataArray:
    """Where a stripes fit is a step at or below its lowest stripe (``always``, or ``separated`` with θ at the lowest level):
    its rate then rests on what lies below the runs, where nothing is known, and is a bound, not a rate. ``lowest``: the
    lowest stripe's level (IM units), default the fit's lowest ``intensity``."""
    lowest = float(np.min(fragility["intensity"].values)) if lowest is None else lowest
    return (fragility["status"] == ALWAYS) | ((fragility["status"] == SEPARATED) & (fragility["theta"] <= lowest * (1.0 + 1e-9)))


def stripes_only_maf(fragility: xr.Dataset, hz: HazardCurve) -> xr.DataArray:
    """λ⁻ (1/yr) from the stripes' fractions alone, nothing below the lowest stripe: Σ_j p_j (λ(x_j) − λ(x_{j+1})).

    p_j = k_j/n_j is stripe j's fraction that exceeded, held from its level x_j up to the next one (λ(x_{n+1}) = 0 above the
    top stripe). A fragility that does not fall with intensity and is at least p_j at x_j exceeds this everywhere, so it is
    the lower bound the runs give of a rate whose fit is a step at the lowest stripe (:func:`at_lowest_stripe`).

    Parameters
    ----------
    fragility : xarray.Dataset
        A stripes fit with its per-stripe ``exceeded`` and ``runs`` over ``intensity``.
    hz : HazardCurve
        The site's hazard.

    Returns
    -------
    xarray.DataArray
        λ⁻ over the fit's dimensions other than ``intensity``.
    """
    levels = np.asarray(fragility["intensity"].values, dtype=float)
    order = np.argsort(levels)
    rates = np.asarray(hz(np.minimum(levels[order], hz.support[1])), dtype=float)
    bins = xr.DataArray(rates - np.append(rates[1:], 0.0), dims="intensity", coords={"intensity": levels[order]})
    return (_fractions(fragility, levels[order]) * bins).sum("intensity", min_count=1).assign_attrs(
        units="1/yr", long_name="mean annual frequency from the stripes' fractions alone (nothing below the lowest stripe)")


def stripes_upper_maf(fragility: xr.Dataset, hz: HazardCurve) -> xr.DataArray:
    """λ⁺ (1/yr) from the stripes' fractions alone: p_1 (λ(lo) − λ(x_1)) + Σ_{j≥2} p_j (λ(x_{j−1}) − λ(x_j)) + λ(x_n).

    The upper counterpart of :func:`stripes_only_maf`: a fragility that does not fall with intensity and is at most p_j at
    x_j is at most p_j on (x_{j−1}, x_j] (at most p_1 from the hazard's lower end lo up to the lowest stripe) and at most 1
    beyond the top stripe x_n, so its λ (the chain's, :func:`~stochpound.risk.mean_annual_frequency`) is at most λ⁺.
    Together, [λ⁻, λ⁺] is what the runs bound a rate to where their fit does not pin it (the fractions' own sampling aside);
    λ⁺ is inf where the lowest stripe has exceedances and the hazard has no lower end.

    Parameters
    ----------
    fragility : xarray.Dataset
        A stripes fit with its per-stripe ``exceeded`` and ``runs`` over ``intensity``.
    hz : HazardCurve
        The site's hazard.

    Returns
    -------
    xarray.DataArray
        λ⁺ over the fit's dimensions other than ``intensity``.
    """
    levels = np.sort(np.asarray(fragility["intensity"].values, dtype=float))
    rates = np.asarray(hz(np.clip(levels, hz.support[0], hz.support[1])), dtype=float)
    below = np.append(float(hz(hz.support[0])), rates[:-1])  # λ at the lower end of each stripe's bin (x_{j-1}, x_j]
    bins = xr.DataArray(below - rates, dims="intensity", coords={"intensity": levels})
    fraction = _fractions(fragility, levels)
    with np.errstate(invalid="ignore"):  # a bin of no exceedance adds nothing, even below a hazard without a lower end (λ(lo) = inf)
        parts = (fraction * bins).where(fraction != 0.0, 0.0).where(fraction.notnull())
    return (parts.sum("intensity", min_count=1) + rates[-1]).assign_attrs(
        units="1/yr", long_name="mean annual frequency bound from the stripes' fractions alone (at most 1 beyond the top stripe)")


UNIDENTIFIED_BETA = 0.8
"""β from which a lognormal fit is not identified by the stripes: its 16–84 % range spans e^{2β} ≈ 5 times in intensity,
wider than record-to-record dispersion (0.3–0.6 for storey drifts, FEMA P-58) and than a stripe set usually spans."""


def _fractions(fragility: xr.Dataset, levels: np.ndarray) -> xr.DataArray:
    """Each stripe's fraction of runs that exceeded, k_j/n_j (NaN where none ran), at ``levels`` in that order."""
    return (fragility["exceeded"] / fragility["runs"].where(fragility["runs"] > 0)).sel(intensity=levels)


def identified(fragility: xr.Dataset) -> xr.DataArray:
    """Where a stripes fit is a lognormal its runs identify (bool): neither a step nor flat, and :func:`unidentified` finds
    nothing against it."""
    return (fragility["status"] == FIT) & (unidentified(fragility) == "")


def unidentified(fragility: xr.Dataset) -> xr.DataArray:
    """Why a lognormal stripes fit is not identified by its runs, in words ("" where it is, or where the fit is a step):
    ``θ beyond the top stripe`` (its median lies where no run went) or ``β ≥ 0.8`` (``UNIDENTIFIED_BETA``)."""
    top = float(np.max(fragility["intensity"].values))

    def why(status: float, theta: float, beta: float) -> str:
        if status != FIT:
            return ""
        reasons = ([f"θ = {theta:.3g} beyond the top stripe {top:.3g}"] if theta > top else []) + (
            [f"β = {beta:.2g} ≥ {UNIDENTIFIED_BETA:g}"] if beta >= UNIDENTIFIED_BETA else [])
        return "; ".join(reasons)

    return xr.apply_ufunc(np.vectorize(why, otypes=[object]), fragility["status"], fragility["theta"], fragility["beta"])
