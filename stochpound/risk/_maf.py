"""Risk at a site: mean annual frequency of a limit state, the pounding risk curve and the risk-targeted separation.

The mean annual frequency (MAF) of exceeding a limit state with fragility F
at a site with hazard curve λ(x) is λ_LS = ∫ F(x) ``|dλ(x)|`` (Cornell &
Krawinkler 2000). Integrated by parts over the hazard's range [lo, hi],

    λ_LS = F(lo) λ(lo) + ∫_lo^hi λ(x) dF(x),

which counts the rate above a table's last intensity as if it were at that
intensity (a table says nothing beyond it; ask the table to extrapolate to
go further). For a lognormal F the integral is taken in z = ln(x/θ)/β,
∫ λ(θ e^{βz}) φ(z) dz, by composite Gauss–Legendre quadrature over
z ∈ [−16, 10] clipped to the hazard's range (the integrand of a power law
k0 x^(−k) peaks at z = −kβ, well inside for kβ < 6). For a power law the
result is k0 θ^(−k) exp(k²β²/2).

Since every gap's fragility comes from the same runs, λ_P(g) over the gap
grid is one curve, Tubaldi et al.'s (2012) pounding risk curve; the
risk-targeted separation g* solves λ_P(g*) = λ_target.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from stochpound.stats import interval, kernels
from stochpound.risk._fragility import ALWAYS, DECREASING, EMPTY, NEVER, SEPARATED, STATUS
from stochpound.risk._fragility_ensemble import BOOTSTRAP, limit_state_events, stripe_fragility
from stochpound.hazard import HazardCurve, probability_from_rate, rate_from_probability, return_period

TARGETS = (0.10, 0.02)
"""Default target probabilities of exceedance in ``years`` (50) of :func:`risk_targeted_separation`."""
_Z_RANGE = (-16.0, 10.0)
_PANELS, _NODES = 24, 8
_CHUNK = 4096
_EXTRAPOLATED_SHARE = 1e-4


def mean_annual_frequency(frag: object, hz: HazardCurve) -> float | np.ndarray | xr.DataArray:
    """λ = ∫ F(x) ``|dλ(x)|``: the mean annual frequency (1/yr) of exceeding a limit state with lognormal fragility ``frag``.

    Parameters
    ----------
    frag : Fragility or xarray.Dataset
        Anything with ``theta`` (IM units, the hazard's) and ``beta``
        (floats, arrays or DataArrays, broadcast): a
        :class:`~stochpound.risk._fragility.Fragility` or a fit Dataset
        of :func:`~stochpound.risk.stripe_fragility`. A step (β = 0)
        at θ gives λ(θ); θ = inf gives 0. A fit Dataset with ``status``,
        ``exceeded`` and ``runs`` gives its ``decreasing`` fits the rate of
        their flat fit (:func:`flat_fit_maf`) instead of NaN.
    hz : HazardCurve
        The site's hazard, in the same intensity measure and units.

    Returns
    -------
    float, numpy.ndarray or xarray.DataArray
        Annual rate (1/yr), shaped like θ and β.
    """
    theta, beta = frag.theta, frag.beta
    if isinstance(theta, xr.DataArray) or isinstance(beta, xr.DataArray):
        rate = xr.apply_ufunc(lambda t, b: lognormal_maf(t, b, hz), theta, beta)
        if isinstance(frag, xr.Dataset) and {"status", "exceeded", "runs"} <= set(frag.data_vars):
            stripes = [d for d in frag["exceeded"].dims if d not in frag["status"].dims]
            flat = xr.apply_ufunc(lambda k, n: flat_fit_maf(k, n, hz), frag["exceeded"], frag["runs"], input_core_dims=[stripes, stripes])
            rate = rate.where(frag["status"] != DECREASING, flat)
        return rate.assign_attrs(units="1/yr", long_name="mean annual frequency of exceedance")
    rate = lognormal_maf(theta, beta, hz)
    return rate.item() if rate.ndim == 0 else rate


def lognormal_maf(theta: ArrayLike, beta: ArrayLike, hz: HazardCurve) -> np.ndarray:
    """The numpy kernel of :func:`mean_annual_frequency` (θ, β broadcast; NaN where either is NaN)."""
    t, b = (np.asarray(value, dtype=float) for value in np.broadcast_arrays(np.asarray(theta, dtype=float), np.asarray(beta, dtype=float)))
    shape = t.shape
    t, b = t.ravel(), b.ravel()
    out = np.full(t.shape, np.nan)
    lo, hi = hz.support
    known = ~(np.isnan(t) | np.isnan(b))
    step = known & ((b == 0.0) | (t == 0.0) | np.isinf(t))
    on_step = step & (t <= hi)
    out[step] = 0.0
    if on_step.any():
        out[on_step] = hz(np.maximum(t[on_step], lo))
    regular = np.flatnonzero(known & ~step)
    for start in range(0, regular.size, _CHUNK):
        index = regular[start:start + _CHUNK]
        out[index] = _lognormal_integral(t[index], b[index], hz, lo, hi)
    return out.reshape(shape)


def flat_fit_maf(exceeded: ArrayLike, runs: ArrayLike, hz: HazardCurve) -> np.ndarray:
    """λ (1/yr) of a flat fit: F ≡ p̄, the fraction of all runs that exceeded, at every intensity.

    Where the probit's fitted slope is not positive (``decreasing``: no more
    exceedances at the higher stripes than at the lower, e.g. 19, 19 and 19
    of 20), the maximum-likelihood fit among fragilities that do not fall
    with intensity (slope ≥ 0) is flat at p̄ = Σ k_j / Σ n_j. Integrated
    with the hazard over its range [lo, hi], λ = p̄ λ(lo): like ``always``
    (F ≡ 1), a plateau set by the lowest intensity of the hazard's table,
    not by the structure, and an upper bound in that the runs say nothing
    below their lowest stripe.

    Parameters
    ----------
    exceeded, runs : array_like
        k_j and n_j per stripe (last axis).
    hz : HazardCurve
        The site's hazard.

    Returns
    -------
    numpy.ndarray
        p̄ λ(lo) over the leading axes (NaN without runs).
    """
    k, n = (np.asarray(value, dtype=float).sum(-1) for value in (exceeded, runs))
    with np.errstate(invalid="ignore", divide="ignore"):
        return _flat_rate(np.where(n > 0.0, k / n, np.nan), hz)


def _flat_rate(fraction: ArrayLike, hz: HazardCurve) -> ArrayLike:
    """λ of F ≡ ``fraction`` over the hazard's range: the fraction times the rate at its lowest intensity (1/yr)."""
    return fraction * float(hz(hz.support[0]))


def fit_maf(theta: ArrayLike, beta: ArrayLike, status: ArrayLike, exceeded: ArrayLike, runs: ArrayLike, hz: HazardCurve) -> np.ndarray:
    """λ (1/yr) of stripe fits: :func:`lognormal_maf` of θ, β, and :func:`flat_fit_maf` of the counts where the fit is ``decreasing``."""
    return np.where(np.asarray(status) == DECREASING, flat_fit_maf(exceeded, runs, hz), lognormal_maf(theta, beta, hz))


def risk_curve(fragility: xr.Dataset, hz: HazardCurve, years: float = 50.0, confidence: float = 0.95) -> xr.Dataset:
    """λ(g) for every fit of ``fragility`` (e.g. every gap: the pounding risk curve), with its bootstrap band.

    Parameters
    ----------
    fragility : xarray.Dataset
        From :func:`~stochpound.risk.stripe_fragility`
        or :func:`~stochpound.risk.ida_fragility`;
        with ``theta_bootstrap``/``beta_bootstrap`` the band is the
        percentiles of λ over the resamples of the motions (the whole chain refitted).
    hz : HazardCurve
        The site's hazard in the fragility's intensity measure.
    years : float
        The exposure time of ``probability``.
    confidence : float
        Level of the band, in (0, 1).

    Returns
    -------
    xarray.Dataset
        ``maf`` (1/yr), ``probability`` (of at least one exceedance in
        ``years``, Poisson), ``return_period`` (yr), and with a bootstrap
        ``maf_lower``, ``maf_upper`` and ``maf_bootstrap`` (or the
        fragility's attribute ``no_interval``: why there is no interval).
    """
    kernels.check_confidence(confidence)
    maf = mean_annual_frequency(fragility, hz)
    result = xr.Dataset(
        {
            "maf": maf.assign_attrs(units="1/yr", long_name="mean annual frequency of exceedance"),
            "probability": xr.apply_ufunc(probability_from_rate, maf, kwargs={"years": years}).assign_attrs(
                units="1", long_name=f"probability of at least one exceedance in {years:g} years (Poisson)"),
            "return_period": xr.apply_ufunc(return_period, maf).assign_attrs(units="yr", long_name="mean return period"),
        },
        attrs={"years": years, "hazard": repr(hz), "hazard_source": hz.source, **no_interval_attrs(fragility)},
    )
    if "theta_bootstrap" in fragility:
        sampled, left_out = (_resampled_maf(fragility, part, hz) for part in ("bootstrap", "jackknife"))
        lower, upper = _interval(sampled, maf, left_out, confidence)
        attrs = {"units": "1/yr", "confidence": confidence, "method": fragility["theta_lower"].attrs.get("method", "")}
        result = result.assign(
            maf_lower=lower.assign_attrs(long_name="lower bound of the MAF", **attrs),
            maf_upper=upper.assign_attrs(long_name="upper bound of the MAF", **attrs),
            maf_bootstrap=sampled.assign_attrs(units="1/yr", long_name="MAF of each resample of the motions"),
            maf_jackknife=left_out.assign_attrs(units="1/yr", long_name="MAF without each motion or cluster of motions"),
        )
    result.attrs["hazard_extrapolated"] = int(hz.extrapolated)
    return rate_intervals(result, years)


def _resampled_maf(fragility: xr.Dataset, part: str, hz: HazardCurve) -> xr.DataArray:
    """λ of every ``part`` (``bootstrap`` or ``jackknife``) resample of a fit Dataset, a decreasing resample's by its flat fit."""
    rate = mean_annual_frequency(xr.Dataset({"theta": fragility[f"theta_{part}"], "beta": fragility[f"beta_{part}"]}), hz)
    if f"flat_{part}" in fragility:
        flat = fragility[f"flat_{part}"]
        rate = rate.where(flat.isnull(), _flat_rate(flat, hz))
    return rate


def degenerate_text(status: ArrayLike, hz: HazardCurve, what: str = "gaps") -> str:
    """What the degenerate fits among ``status`` are and what each does to the MAF ("" when every fit is a lognormal).

    A degenerate fit is a step (β = 0), not a lognormal (its ``status``:
    ``always``, ``never``, ``separated``; a ``decreasing`` fit is flat at
    the fraction of runs that exceeded, :func:`flat_fit_maf`; an ``empty``
    one has no λ); integrated with the
    hazard it gives λ(θ): for ``always`` (every run exceeded, θ = 0) the
    hazard's rate at the lowest intensity of its table, a plateau set by
    the table, not by the structure; for ``never`` 0; for ``separated``
    the hazard's rate at the step.

    Parameters
    ----------
    status : array_like of int
        Fit statuses (indices into ``STATUS``), e.g. one per gap and configuration.
    hz : HazardCurve
        The hazard the fits were integrated with.
    what : str
        What one fit is of, in words (plural), e.g. ``"gaps"``.

    Returns
    -------
    str
        One sentence per kind of degenerate fit found, with its count.
    """
    status = np.asarray(status).ravel()
    lo = hz.support[0]
    effect = {
        ALWAYS: f"every run exceeded at every stripe, F ≡ 1, so λ is the hazard's rate at the lowest intensity of its table "
                f"({lo:.3g} {hz.units}): {float(hz(lo)):.3g} /yr, a plateau set by the hazard table, not a fitted risk",
        NEVER: "no run exceeded, F ≡ 0, so λ = 0: no risk is resolved, only that none of the runs exceeded",
        SEPARATED: "the runs separate at one intensity (none exceeded below it, all above), so F is a step there and λ is the "
                   "hazard's rate at that intensity",
        DECREASING: f"the fitted slope is not positive: no more runs exceeded at the higher stripes than at the lower, so the fit is "
                    f"flat at the fraction p̄ of all runs that exceeded (the maximum-likelihood fit that does not fall with intensity) and "
                    f"λ = p̄ × the hazard's rate at the lowest intensity of its table ({lo:.3g} {hz.units}), p̄ × {float(hz(lo)):.3g} /yr: "
                    f"a plateau set by the hazard table, an upper bound rather than a fitted risk",
        EMPTY: "no runs: no fragility and no λ (NaN)",
    }
    kind = {DECREASING: "a flat fit", EMPTY: "no fit"}
    parts = [f"{int((status == code).sum())} of {status.size} {what}: {kind.get(code, 'a step')} '{STATUS[code]}' ({text})"
             for code, text in effect.items() if (status == code).any()]
    return ("Degenerate fits, not lognormals: " + "; ".join(parts) + ".") if parts else ""


def rate_intervals(result: xr.Dataset, years: float) -> xr.Dataset:
    """``result`` with the intervals of its return period and probability, from those of its MAF (absent without them).

    Both are monotone in the MAF λ, so the interval of λ maps onto theirs
    exactly: the return period 1/λ is in [1/λ_upper, 1/λ_lower] (yr) and
    the probability 1 − exp(−λ t) in [its value at λ_lower, at λ_upper],
    at the same confidence, from the same resamples.

    Parameters
    ----------
    result : xarray.Dataset
        With ``maf``, ``maf_lower`` and ``maf_upper`` (1/yr).
    years : float
        The exposure time t of the probability (yr).

    Returns
    -------
    xarray.Dataset
        With ``return_period_lower``/``return_period_upper`` (yr) and
        ``probability_lower``/``probability_upper``.
    """
    if "maf_lower" not in result or "maf_upper" not in result:
        return result
    attrs = {key: value for key, value in result["maf_lower"].attrs.items() if key in ("confidence", "method", "seed")}
    periods = {bound: xr.apply_ufunc(return_period, result[f"maf_{other}"]) for bound, other in (("lower", "upper"), ("upper", "lower"))}
    chances = {bound: xr.apply_ufunc(probability_from_rate, result[f"maf_{bound}"], kwargs={"years": years}) for bound in ("lower", "upper")}
    return result.assign(
        **{f"return_period_{bound}": value.assign_attrs(units="yr", long_name=f"{bound} bound of the mean return period", **attrs)
           for bound, value in periods.items()},
        **{f"probability_{bound}": value.assign_attrs(units="1", long_name=f"{bound} bound of the probability in {years:g} years", **attrs)
           for bound, value in chances.items()},
    )


def risk_targeted_separation(curve: xr.Dataset, targets: Sequence[float] = TARGETS, years: float = 50.0, dim: str = "gap",
                             confidence: float = 0.95) -> xr.Dataset:
    """The gap g* with λ_P(g*) = λ_target for each target probability in ``years``, with its bootstrap interval.

    λ_P(g) is made non-increasing along the gap grid by isotonic
    regression of ln λ_P on the gap (pool-adjacent-violators,
    ``non_increasing``): a wider gap cannot pound more often, so a
    rise is estimation noise, and pooling it with its neighbours keeps the
    upward fluctuations as well as the downward ones (a running minimum
    would keep only the downward ones: biased low, non-conservative). Each
    gap weighs in the fit by the share of ln g it stands for
    (``gap_weights``: equal on an evenly log-spaced grid), so a grid refined
    near g* fits the same curve as a uniformly finer one would there. g* is
    interpolated between the two grid gaps that bracket the target,
    linearly in ln λ against ln g (exact where λ_P is a power law of g, as
    for a linear pair under a power-law hazard; against g from a zero gap).

    Parameters
    ----------
    curve : xarray.Dataset
        From :func:`risk_curve`, with dimension ``dim`` (ascending gaps, m).
    targets : sequence of float
        Probabilities of pounding in ``years`` (each in (0, 1)): rate −ln(1 − p)/years.
    years : float
        Their exposure time.
    dim : str
        The gap dimension.
    confidence : float
        Level of the interval (percentiles of g* over the bootstrap resamples).

    Returns
    -------
    xarray.Dataset
        Over ``target`` (the probabilities) and the curve's other
        dimensions: ``separation`` (m; ``inf`` when even the widest gap of
        the grid is too risky, the grid's first gap when that one already
        meets the target), ``target_rate`` (1/yr) and, with a bootstrap,
        ``lower`` and ``upper`` (or the curve's attribute ``no_interval``).
    """
    kernels.check_confidence(confidence)
    if dim not in curve.dims:
        raise ValueError(f"dim: {dim!r} is not a dimension of the risk curve (its dimensions: {', '.join(map(str, curve.dims))})")
    gaps = np.asarray(curve[dim].values, dtype=float)
    if gaps.size < 2 or not np.all(np.diff(gaps) > 0.0):
        raise ValueError(f"{dim}: the gap grid must hold at least two strictly increasing gaps")
    rates = rate_from_probability(np.asarray(targets, dtype=float), years)
    rates = np.atleast_1d(rates)

    def solve(maf: xr.DataArray) -> xr.DataArray:
        return xr.apply_ufunc(_separation_kernel, maf, kwargs={"gaps": gaps, "rates": rates},
                              input_core_dims=[[dim]], output_core_dims=[["target"]])

    separation = solve(curve["maf"])
    result = xr.Dataset({"separation": separation.assign_attrs(units="m", long_name="risk-targeted separation g*")})
    if "maf_bootstrap" in curve:
        lower, upper = _interval(solve(curve["maf_bootstrap"]), separation, solve(curve["maf_jackknife"]), confidence)
        attrs = {"units": "m", "confidence": confidence, "method": curve["maf_lower"].attrs.get("method", "")}
        result = result.assign(lower=lower.assign_attrs(long_name="lower bound of g*", **attrs),
                               upper=upper.assign_attrs(long_name="upper bound of g*", **attrs))
    return result.assign_coords(
        target=("target", np.atleast_1d(np.asarray(targets, dtype=float)), {"units": "1", "long_name": f"target probability of pounding in {years:g} years"}),
        target_rate=("target", rates, {"units": "1/yr", "long_name": "target mean annual frequency"}),
    ).assign_attrs(years=years, **no_interval_attrs(curve))


def rate_at_separation(curve: xr.Dataset, separation: xr.DataArray, dim: str = "gap") -> xr.DataArray:
    """λ_P (1/yr) at given gaps: the inverse of :func:`risk_targeted_separation` on the same curve.

    The curve's ``maf`` is made non-increasing as g* reads it (isotonic in ln λ, each gap weighted by the share of ln g it
    stands for) and interpolated between the two grid gaps that bracket each gap, linearly in ln λ against ln g (in λ where
    the wider gap's λ is 0, against g from a zero gap): at g* of a target inside the grid it gives back the target's rate.

    Parameters
    ----------
    curve : xarray.Dataset
        From :func:`risk_curve`, with ``maf`` over ``dim`` (ascending gaps, m).
    separation : xarray.DataArray
        The gaps (m) to read λ_P at, over some of the curve's other dimensions and, e.g., ``target``.

    Returns
    -------
    xarray.DataArray
        λ_P (1/yr) over the dimensions of both; NaN where the gap is not finite or lies outside the grid.
    """
    envelope = separation_envelope(curve["maf"], dim)  # once per curve
    rate = xr.apply_ufunc(_rate_kernel, envelope, separation, kwargs={"gaps": np.asarray(curve[dim].values, dtype=float)},
                          input_core_dims=[[dim], []], vectorize=True)
    return rate.assign_attrs(units="1/yr", long_name="mean annual frequency of pounding at the gap")


def separation_envelope(maf: xr.DataArray, dim: str = "gap") -> xr.DataArray:
    """λ_P(g) made non-increasing as g* reads it (:func:`risk_targeted_separation`): the isotonic fit of ln λ along ``dim``, each gap
    weighted by the share of ln g it stands for (``gap_weights``); NaN along a curve that has no rate (1/yr).

    Parameters
    ----------
    maf : xarray.DataArray
        λ_P (1/yr) over ``dim`` (ascending gaps, m) and any other dimensions.
    dim : str
        The gap dimension.
    """
    weights = gap_weights(np.asarray(maf[dim].values, dtype=float))
    envelope = xr.apply_ufunc(non_increasing, maf, kwargs={"weights": weights}, input_core_dims=[[dim]], output_core_dims=[[dim]])
    return envelope.transpose(*maf.dims).where(maf.notnull().any(dim))


def target_text(probability: float, years: float) -> str:
    """A target in words: ``10 % in 50 yr`` (a probability of pounding in ``years``)."""
    return f"{100 * probability:g} % in {years:g} yr"


def no_interval_attrs(data: xr.Dataset) -> dict[str, str]:
    """``data``'s ``no_interval`` attribute (why its motions gave no interval: :func:`~stochpound.risk.stripe_fragility`), to pass on."""
    return {"no_interval": data.attrs["no_interval"]} if "no_interval" in data.attrs else {}


def demand_hazard_curve(demand: xr.DataArray, levels: Sequence[float] | np.ndarray, hz: HazardCurve, dim: str = "level",
                        intensity_dim: str = "intensity", record_dim: str = "record", confidence: float = 0.95,
                        bootstrap: int = BOOTSTRAP, seed: int = 0) -> xr.Dataset:
    """The annual rate at which a demand exceeds each of ``levels`` (e.g. drift, floor acceleration, isolator displacement).

    The fragility of "demand ≥ level" is fitted to the stripes of
    ``demand`` for every level (:func:`~stochpound.risk.stripe_fragility`)
    and integrated with the hazard (:func:`risk_curve`).

    Parameters
    ----------
    demand : xarray.DataArray
        One value per run, dims ``intensity_dim`` (levels in the hazard's IM units) and ``record_dim``.
    levels : sequence of float
        Demand levels, in the units of ``demand``.

    Returns
    -------
    xarray.Dataset
        :func:`risk_curve` over ``dim`` (the demand levels).
    """
    fragility = stripe_fragility(limit_state_events(demand, levels, dim), intensity_dim, record_dim, confidence, bootstrap, seed)
    return risk_curve(fragility, hz, confidence=confidence)


# ---------------------------------------------------------------- kernels


def _interval(sampled: xr.DataArray, estimate: xr.DataArray, left_out: xr.DataArray, confidence: float) -> tuple[xr.DataArray, xr.DataArray]:
    """BCa bounds of ``estimate`` from its resamples (dim ``bootstrap``) and jackknife values (dim ``jackknife``)."""
    return xr.apply_ufunc(lambda s, e, j: interval(s, e, j, confidence), sampled, estimate, left_out,
                          input_core_dims=[["bootstrap"], [], ["jackknife"]], output_core_dims=[[], []])


def _lognormal_integral(theta: np.ndarray, beta: np.ndarray, hz: HazardCurve, lo: float, hi: float) -> np.ndarray:
    """F(lo) λ(lo) + ∫ λ(θ e^{βz}) φ(z) dz over z in the hazard's range (composite Gauss–Legendre), per element."""
    from scipy import special

    log_theta = np.log(theta)
    with np.errstate(divide="ignore"):
        z_lo = (np.log(lo) - log_theta) / beta
        z_hi = (np.log(hi) - log_theta) / beta
    a = np.clip(z_lo, *_Z_RANGE)
    b = np.clip(z_hi, *_Z_RANGE)
    nodes, weights = special.roots_legendre(_NODES)
    panel = (np.arange(_PANELS)[:, None] + 0.5 * (nodes[None, :] + 1.0)).ravel() / _PANELS
    width = np.maximum(b - a, 0.0)
    z = a[:, None] + width[:, None] * panel[None, :]
    w = np.tile(weights, _PANELS)[None, :] * 0.5 * width[:, None] / _PANELS
    log_x = log_theta[:, None] + beta[:, None] * z
    if not hz.extrapolate:
        log_x = np.clip(log_x, np.log(lo), np.log(hi))
    terms = w * np.exp(hz.log_rate(log_x) - 0.5 * z**2) / np.sqrt(2.0 * np.pi)
    integral = terms.sum(-1)
    if hz.extrapolate and hz.power is None:
        outside = (log_x < np.log(hz.im[0])) | (log_x > np.log(hz.im[-1]))
        if np.any(np.where(outside, terms, 0.0).sum(-1) > _EXTRAPOLATED_SHARE * integral):
            hz.extrapolated = True
    if lo > 0.0:
        integral = integral + special.ndtr(z_lo) * float(hz(lo))
    return integral


def non_increasing(maf: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """The closest non-increasing curve to a rate curve along its last axis, in ln λ (isotonic regression).

    Each curve (the last axis, ascending gaps) is replaced by the
    least-squares non-increasing fit of ln λ, computed by the
    pool-adjacent-violators algorithm (:func:`scipy.optimize.isotonic_regression`):
    a run of values that rises is replaced by the mean of its logarithms
    (their geometric mean). A zero rate enters as the smallest positive
    double. NaN values are left out of the fit and take the fitted value of
    the gap before them (``inf`` before the first finite one).

    Parameters
    ----------
    maf : numpy.ndarray
        Mean annual frequencies (1/yr), ≥ 0 or NaN, the gaps on the last axis.
    weights : numpy.ndarray, optional
        The weight of each gap in the fit (along the last axis, > 0), e.g. the share of ln g it stands for
        (:func:`gap_weights`); default equal weights.

    Returns
    -------
    numpy.ndarray
        The non-increasing rates, same shape.
    """
    from scipy import optimize

    maf = np.asarray(maf, dtype=float)
    rows = maf.reshape(-1, maf.shape[-1])
    fitted = np.full_like(rows, np.inf)
    tiny = np.log(np.finfo(float).tiny)
    for row, out in zip(rows, fitted, strict=True):
        known = ~np.isnan(row)
        if known.sum() > 1:
            with np.errstate(divide="ignore"):
                logs = np.maximum(np.log(row[known]), tiny)
            fitted_logs = optimize.isotonic_regression(logs, weights=None if weights is None else weights[known], increasing=False).x
            out[known] = np.where(fitted_logs > tiny + 1.0, np.exp(fitted_logs), 0.0)  # a pool of zeros alone (its mean ln tiny, to rounding) is 0 again
        elif known.any():
            out[known] = row[known]
        out[:] = np.fmin.accumulate(out)  # NaN positions take the value before them
    return fitted.reshape(maf.shape)


def gap_weights(gaps: np.ndarray) -> np.ndarray:
    """The share of the gap axis each gap of a grid stands for: half the distance (in ln g; in g from a zero gap) to its two
    neighbours, the whole distance to its one neighbour at an end. Equal on an evenly spaced grid; a grid refined in places
    (``stochpound.risk._gap_grid``) does not give its refined stretches more weight in the isotonic fit than the stretches they replace."""
    position = np.log(gaps) if gaps[0] > 0.0 else np.asarray(gaps, dtype=float)
    step = np.diff(position)
    return np.concatenate([step[:1], 0.5 * (step[:-1] + step[1:]), step[-1:]])


def _separation_kernel(maf: np.ndarray, gaps: np.ndarray, rates: np.ndarray) -> np.ndarray:
    """g* per target rate along the last axis of ``maf`` (isotonic λ weighted by :func:`gap_weights`, interpolation of ln λ in ln g)."""
    envelope = non_increasing(maf, gap_weights(gaps))
    below = envelope[..., None, :] <= rates[:, None]  # (..., target, gap)
    found = below.any(-1)
    index = np.argmax(below, axis=-1)
    previous = np.maximum(index - 1, 0)
    lam_hi = np.take_along_axis(envelope[..., None, :], previous[..., None], -1)[..., 0]
    lam_lo = np.take_along_axis(envelope[..., None, :], index[..., None], -1)[..., 0]
    g_hi, g_lo = gaps[previous], gaps[index]
    target = np.broadcast_to(rates, index.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        in_log = (np.log(lam_hi) - np.log(target)) / (np.log(lam_hi) - np.log(lam_lo))
        linear = (lam_hi - target) / (lam_hi - lam_lo)
        fraction = np.where(lam_lo > 0.0, in_log, linear)
        fraction = np.where(np.isfinite(lam_hi), fraction, 1.0)
    fraction = np.clip(fraction, 0.0, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        in_log_gap = np.exp(np.log(g_hi) + fraction * (np.log(g_lo) - np.log(g_hi)))
    separation = np.where(g_hi > 0.0, in_log_gap, g_hi + fraction * (g_lo - g_hi))
    separation = np.where(~found, np.inf, np.where(index == 0, gaps[0], separation))
    return np.where(np.isnan(maf).all(-1)[..., None], np.nan, separation)


def _rate_kernel(envelope: np.ndarray, at: float, gaps: np.ndarray) -> float:
    """λ_P at the gap ``at`` of one non-increasing curve (``envelope`` over ``gaps``): the interpolation :func:`_separation_kernel`
    inverts."""
    if not (np.isfinite(at) and gaps[0] <= at <= gaps[-1]) or np.isnan(envelope).all():
        return np.nan
    upper = int(np.clip(np.searchsorted(gaps, at, side="right"), 1, gaps.size - 1))
    g_narrow, g_wide = gaps[upper - 1], gaps[upper]
    lam_narrow, lam_wide = envelope[upper - 1], envelope[upper]
    fraction = np.log(at / g_narrow) / np.log(g_wide / g_narrow) if g_narrow > 0.0 else (at - g_narrow) / (g_wide - g_narrow)
    if not np.isfinite(lam_narrow):
        return float(lam_wide) if fraction == 1.0 else np.inf
    if lam_wide > 0.0:
        return float(np.exp(np.log(lam_narrow) + fraction * np.log(lam_wide / lam_narrow)))
    return float(lam_narrow + fraction * (lam_wide - lam_narrow))
