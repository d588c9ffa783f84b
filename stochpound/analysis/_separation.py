"""How wide must the gap be: pounding probability for every gap, and the separation a target probability needs.

Before its first impact, a run with gap g and the same run without contacts
(every gap ``inf``) are identical. So a run pounds at gap g exactly when the
contact-free run's closure y_left − y_right reaches g, i.e. when its peak
closure D ≥ g (``peak_contact_closure`` of :func:`stochpound.simulate`).
With several contacts sharing one gap, D is the largest peak closure over
them; contacts with their own gaps g_c pound when max_c (D_c − g_c) ≥ 0.
One contact-free ensemble therefore gives P(pounding | g) = P(D ≥ g) for
every g at once, realization by realization (docs/separation.md).

Every function takes the peak closures as an :class:`xarray.DataArray` with
the ensemble dimension ``dim`` (and ``contact``), reduces ``dim`` with one
numpy kernel wrapped in :func:`xarray.apply_ufunc` (lazy on dask-backed
data) and carries every other dimension along (e.g. an experiment's grid).
NaN peak closures (missing runs) are left out of the counts.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np
import xarray as xr

from stochpound.store import VariableAttributes

TARGET_PROBABILITIES = (0.5, 0.16, 0.05, 0.01)
"""Default target pounding probabilities of :func:`required_separation`."""


def pounding_curve(
    peak_closure: xr.DataArray,
    gaps: Sequence[float] | np.ndarray,
    dim: str = "realization",
    confidence: float = 0.95,
    contact_dim: str | None = "contact",
    gap_offsets: xr.DataArray | None = None,
) -> xr.Dataset:
    """P(pounding | g) = P(D ≥ g) for every gap g, with Clopper–Pearson intervals.

    Parameters
    ----------
    peak_closure : xarray.DataArray
        Peak closure D_c of each contact-free run (m), dims ``dim`` and
        ``contact_dim`` (if present) and any others, which are carried along.
    gaps : sequence of float
        The gaps g (m) at which to evaluate the curve (1-D, not NaN).
    dim : str
        The ensemble dimension reduced.
    confidence : float
        Level of the two-sided exact binomial (Clopper–Pearson) interval, in (0, 1).
    contact_dim : str or None
        The contacts' dimension: a run pounds when any contact does, i.e.
        when max_c (D_c − offset_c) ≥ g. ``None``: no maximum is taken.
    gap_offsets : xarray.DataArray, optional
        Contacts with their own gaps: contact c's gap is g + offset_c (m);
        may vary along other dimensions too (e.g. per realization), and
        ``inf`` makes a contact never close. Default: every contact has gap g.

    Returns
    -------
    xarray.Dataset
        On a new dimension ``gap`` (coordinate in m): ``probability`` (the
        fraction of realizations with D ≥ g), ``lower`` and ``upper`` (its
        interval); ``realizations``, the number of runs counted (not NaN).
        A ``realizations`` of 0 gives NaN.
    """
    gap_values = np.asarray(gaps, dtype=float)
    if gap_values.ndim != 1 or np.isnan(gap_values).any():
        raise ValueError(f"gaps: must be a 1-D sequence of gaps in m (not NaN), got {gaps!r}")
    demand = _demand(peak_closure, dim, contact_dim, gap_offsets)
    _check_confidence(confidence)
    probability, lower, upper, count = xr.apply_ufunc(
        _exceedance_kernel, demand,
        kwargs={"gaps": gap_values, "confidence": confidence},
        input_core_dims=[[dim]], output_core_dims=[["gap"], ["gap"], ["gap"], []],
        dask="parallelized", output_dtypes=[float, float, float, int],
        dask_gufunc_kwargs={"output_sizes": {"gap": len(gap_values)}, "allow_rechunk": True},
    )
    attrs = {"units": "1", "confidence": confidence}
    result = xr.Dataset(
        {
            "probability": probability.assign_attrs(long_name="probability of pounding P(D >= gap)", **attrs),
            "lower": lower.assign_attrs(long_name="lower Clopper-Pearson bound", **attrs),
            "upper": upper.assign_attrs(long_name="upper Clopper-Pearson bound", **attrs),
            "realizations": count.assign_attrs(units="1", long_name="number of realizations counted"),
        }
    )
    return result.assign_coords(gap=("gap", gap_values, {"units": "m", "long_name": "gap (common to every contact, plus its offset)"}))


def required_separation(
    peak_closure: xr.DataArray,
    probabilities: Sequence[float] = TARGET_PROBABILITIES,
    dim: str = "realization",
    confidence: float = 0.95,
    contact_dim: str | None = "contact",
    gap_offsets: xr.DataArray | None = None,
) -> xr.Dataset:
    """The gap needed for each target pounding probability p: the (1 − p) quantile of D, with its interval.

    The point estimate is the sample's inverse-CDF quantile (numpy's
    ``inverted_cdf``): the k-th smallest D with k = ⌈n (1 − p)⌉, so any gap
    wider than it was reached in at most a fraction p of the realizations.
    The interval is distribution-free, from order statistics: the
    two-sided interval of :meth:`scipy.stats.quantile_test`'s
    ``confidence_interval`` (bounds D_(l), D_(u) with l, u from the
    Binomial(n, 1 − p) quantiles at (1 − confidence) / 2).

    Parameters
    ----------
    peak_closure, dim, confidence, contact_dim, gap_offsets
        As in :func:`pounding_curve` (with ``gap_offsets``, the result is the
        common part g of the contacts' gaps g + offset_c).
    probabilities : sequence of float
        Target probabilities of pounding p, each in (0, 1).

    Returns
    -------
    xarray.Dataset
        On a new dimension ``probability`` (the targets p): ``separation``,
        ``lower`` and ``upper`` (m), and ``realizations`` (runs counted).
        A bound is NaN when the sample is too small to give it at this
        confidence: the lower bound needs p^n < (1 − confidence)/2, the upper
        bound (1 − p)^n ≤ (1 − confidence)/2 (e.g. n ≥ 72 realizations for
        p = 0.05 and n ≥ 368 for p = 0.01 at 95 %).
    """
    targets = np.asarray(probabilities, dtype=float)
    if targets.ndim != 1 or not np.all((targets > 0.0) & (targets < 1.0)):
        raise ValueError(f"probabilities: must be a 1-D sequence of probabilities in (0, 1), got {probabilities!r}")
    demand = _demand(peak_closure, dim, contact_dim, gap_offsets)
    _check_confidence(confidence)
    separation, lower, upper, count = xr.apply_ufunc(
        _quantile_kernel, demand,
        kwargs={"levels": 1.0 - targets, "confidence": confidence},
        input_core_dims=[[dim]], output_core_dims=[["probability"], ["probability"], ["probability"], []],
        dask="parallelized", output_dtypes=[float, float, float, int],
        dask_gufunc_kwargs={"output_sizes": {"probability": len(targets)}, "allow_rechunk": True},
    )
    units = VariableAttributes.of(peak_closure, units="m").units
    result = xr.Dataset(
        {
            "separation": separation.assign_attrs(units=units, long_name="gap reached with the target probability: the (1 - p) quantile of D"),
            "lower": lower.assign_attrs(units=units, long_name="lower order-statistic bound (NaN: sample too small)", confidence=confidence),
            "upper": upper.assign_attrs(units=units, long_name="upper order-statistic bound (NaN: sample too small)", confidence=confidence),
            "realizations": count.assign_attrs(units="1", long_name="number of realizations counted"),
        }
    )
    return result.assign_coords(probability=("probability", targets, {"units": "1", "long_name": "target probability of pounding"}))


def rule_exceedance(
    peak_closure: xr.DataArray,
    rule_gap: xr.DataArray,
    dim: str = "realization",
    confidence: float = 0.95,
    contact_dim: str | None = "contact",
) -> xr.Dataset:
    """Probability that a gap given per run (e.g. a separation rule's) is reached, with its Clopper–Pearson interval.

    A run pounds at gaps g_c when max_c (D_c − g_c) ≥ 0: the result is
    P(D ≥ rule's gap), the probability that buildings separated by the
    rule's gap pound (equal to P(D > rule's gap) for a continuous D).

    Parameters
    ----------
    peak_closure : xarray.DataArray
        As in :func:`pounding_curve`.
    rule_gap : xarray.DataArray
        Each contact's gap (m), which may vary per realization and along
        other dimensions, e.g. ``rule`` from :func:`~stochpound.analysis.separation_rules`.
        A NaN gap leaves its run out.
    dim, confidence, contact_dim
        As in :func:`pounding_curve`.

    Returns
    -------
    xarray.Dataset
        ``probability``, ``lower``, ``upper`` and ``realizations`` as in
        :func:`pounding_curve`, without the ``gap`` dimension.
    """
    curve = pounding_curve(peak_closure, [0.0], dim, confidence, contact_dim, gap_offsets=rule_gap)
    curve["probability"].attrs["long_name"] = "probability of pounding at the given gaps"
    return curve.isel(gap=0, drop=True)


# ---------------------------------------------------------------- helpers


def _demand(peak_closure: xr.DataArray, dim: str, contact_dim: str | None, gap_offsets: xr.DataArray | None) -> xr.DataArray:
    """max_c (D_c − offset_c) per run (m): the run pounds at gap g iff it is ≥ g; NaN if any contact's is."""
    if dim not in peak_closure.dims:
        raise ValueError(f"dim: {dim!r} is not a dimension of peak_closure (its dimensions: {', '.join(map(str, peak_closure.dims))})")
    if peak_closure.sizes[dim] == 0:
        raise ValueError(f"peak_closure: no realizations along {dim!r}")
    demand = peak_closure if gap_offsets is None else peak_closure - gap_offsets
    if contact_dim is not None and contact_dim in demand.dims:
        demand = demand.max(contact_dim, skipna=False)
    if "gap" in demand.coords and "gap" not in demand.dims:  # a store's contact-free selection (gap = inf) labels its runs
        demand = demand.drop_vars("gap")
    return demand


def _check_confidence(confidence: float) -> None:
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence: must be in (0, 1), got {confidence}")


def _exceedance_kernel(samples: np.ndarray, gaps: np.ndarray, confidence: float) -> tuple[np.ndarray, ...]:
    """Fraction of non-NaN ``samples`` (last axis) ≥ each of ``gaps``, its Clopper–Pearson bounds, and the count."""
    trials = np.count_nonzero(~np.isnan(samples), axis=-1)
    successes = np.count_nonzero(samples[..., None, :] >= gaps[:, None], axis=-1)
    n = np.broadcast_to(trials[..., None], successes.shape)
    with np.errstate(invalid="ignore", divide="ignore"):
        probability = successes / n
    lower, upper = _clopper_pearson(successes, n, confidence)
    return probability, lower, upper, trials


def _clopper_pearson(successes: np.ndarray, trials: np.ndarray, confidence: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact two-sided binomial interval of the proportion successes/trials (NaN for no trials)."""
    from scipy import stats

    tail = (1.0 - confidence) / 2.0
    with np.errstate(invalid="ignore"):
        lower = np.where(successes > 0, stats.beta.ppf(tail, successes, trials - successes + 1), 0.0)
        upper = np.where(successes < trials, stats.beta.isf(tail, successes + 1, trials - successes), 1.0)
    empty = trials == 0
    return np.where(empty, np.nan, lower), np.where(empty, np.nan, upper)


def _quantile_kernel(samples: np.ndarray, levels: np.ndarray, confidence: float) -> tuple[np.ndarray, ...]:
    """Inverse-CDF quantiles at ``levels`` of non-NaN ``samples`` (last axis), their order-statistic bounds, and the count."""
    from scipy import stats

    trials = np.count_nonzero(~np.isnan(samples), axis=-1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN rows give NaN
        estimate = np.moveaxis(np.nanquantile(samples, levels, axis=-1, method="inverted_cdf"), 0, -1)
    ordered = np.sort(samples, axis=-1)  # NaN last
    n = trials[..., None]
    tail = (1.0 - confidence) / 2.0
    lower = _order_statistic(ordered, stats.binom.ppf(tail, n, levels) - 1, n)
    upper = _order_statistic(ordered, stats.binom.isf(tail, n, levels), n)
    return estimate, lower, upper, trials


def _order_statistic(ordered: np.ndarray, index: np.ndarray, n: np.ndarray) -> np.ndarray:
    """ordered[..., index] (0-based) where 0 ≤ index < n, NaN elsewhere."""
    inside = (index >= 0) & (index < n)
    safe = np.where(inside, index, 0).astype(int)
    return np.where(inside, np.take_along_axis(ordered, safe, axis=-1), np.nan)
