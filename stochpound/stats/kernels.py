"""The numpy kernels: the one implementation of every statistic of the toolkit.

The xarray functions of :mod:`stochpound.analysis` wrap these kernels with
:func:`xarray.apply_ufunc` (lazily on dask); the experiment store's per-case
summaries (``stochpound.experiment._summary``) and
:func:`stochpound.simulate_ensemble` call them, directly or through those
wrappers. Nothing else computes these quantities.

Conventions:

* a kernel reduces its array's *trailing* axis (or the axes it is given),
  as :func:`xarray.apply_ufunc` hands the core dimensions last;
* NaN marks a missing value (a case not run, padding above a building's top
  floor, after a motion's end or after a realization's last impact) and is
  ignored; a reduction over nothing but NaN gives NaN;
* moments are population moments (ddof = 0, the reference study's Table 3.2
  convention); intervals use the sample standard deviation (ddof = 1);
* confidence levels are in (0, 1), e.g. 0.95.
"""

from __future__ import annotations

import warnings
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from stochpound.stats._bootstrap import bootstrap_weights

Axis = int | tuple[int, ...]

BOOTSTRAP_RESAMPLES = 9999
"""Resamples of :func:`bootstrap_mean_interval` (scipy's default): the Monte Carlo error of its 2.5 % and 97.5 %
bounds is then about 2 % of the interval's width."""
BOOTSTRAP_SEED = 20240528
"""Seed of the resampling of :func:`bootstrap_mean_interval` (with the sample size): the same data always give the same interval."""


class Moments(NamedTuple):
    """Population moments along an axis (units: those of the sample; variance squared)."""

    mean: np.ndarray
    variance: np.ndarray
    std: np.ndarray
    skewness: np.ndarray
    excess: np.ndarray


class ImpactCounts(NamedTuple):
    """Counts and extremes of the impacts of one table (0 extremes when there is no impact)."""

    impacts: np.ndarray
    impacts_in_phase: np.ndarray
    impacts_out_of_phase: np.ndarray
    peak_impact_force: np.ndarray
    longest_impact: np.ndarray
    total_impulse: np.ndarray


class Interval(NamedTuple):
    """An estimate with its two-sided confidence interval and the sample size behind it."""

    estimate: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    count: np.ndarray


def check_confidence(confidence: float) -> None:
    """Raise ``ValueError`` naming ``confidence`` unless it is in (0, 1)."""
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence: must be in (0, 1), got {confidence}")


def moments(values: np.ndarray, axis: Axis = -1) -> Moments:
    """Mean, variance, std, skewness m3/m2^1.5 and excess m4/m2² − 3 along ``axis``.

    Parameters
    ----------
    values : numpy.ndarray
        The sample(s); NaN is ignored.
    axis : int or tuple of int
        The axis (or axes) to reduce.

    Returns
    -------
    Moments
        Population moments (ddof = 0). A constant sample has std 0 and NaN
        skewness and excess; an all-NaN one is NaN throughout.
    """
    x = np.asarray(values, dtype=np.float64)
    missing = np.isnan(x)
    count = np.sum(~missing, axis=axis)
    if missing.any():
        x = np.where(missing, 0.0, x)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.sum(x, axis=axis) / count
        centred = x - np.expand_dims(mean, axis)
        if missing.any():
            centred = np.where(missing, 0.0, centred)
        square = centred * centred
        m2 = np.sum(square, axis=axis) / count
        m3 = np.sum(square * centred, axis=axis) / count
        m4 = np.sum(square * square, axis=axis) / count
        flat = m2 == 0.0
        skewness = np.where(flat, np.nan, m3 / m2**1.5)
        excess = np.where(flat, np.nan, m4 / m2**2 - 3.0)
    return Moments(mean, m2, np.sqrt(m2), skewness, excess)


def pearson(response: np.ndarray, reference: np.ndarray, axis: int = -1) -> np.ndarray:
    """Pearson correlation coefficient of two samples along ``axis`` (pairs with a NaN are dropped).

    Parameters
    ----------
    response, reference : numpy.ndarray
        Broadcastable arrays (e.g. a grid of responses against one reference).
    axis : int
        The axis along which the samples run (e.g. time).

    Returns
    -------
    numpy.ndarray
        In [−1, 1]; NaN when either sample is constant or empty.
    """
    a, b = np.broadcast_arrays(np.asarray(response, dtype=np.float64), np.asarray(reference, dtype=np.float64))
    valid = ~(np.isnan(a) | np.isnan(b))
    count = np.sum(valid, axis=axis, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        da = np.where(valid, a - np.sum(np.where(valid, a, 0.0), axis=axis, keepdims=True) / count, 0.0)
        db = np.where(valid, b - np.sum(np.where(valid, b, 0.0), axis=axis, keepdims=True) / count, 0.0)
        return np.sum(da * db, axis=axis) / np.sqrt(np.sum(da * da, axis=axis) * np.sum(db * db, axis=axis))


def abs_peak(values: np.ndarray, axis: Axis = -1) -> np.ndarray:
    """The largest absolute value along ``axis``, ignoring NaN (NaN where every value is NaN)."""
    magnitude = np.abs(np.asarray(values, dtype=np.float64))
    peak = np.max(np.where(np.isnan(magnitude), -np.inf, magnitude), axis=axis)
    return np.where(np.isneginf(peak), np.nan, peak)


def wall_penetration(peak_closure: np.ndarray, gap: np.ndarray) -> np.ndarray:
    """The largest penetration of a wall over the run and over the walls, m (the walls along the trailing axis).

    A wall's penetration is its level's displacement toward it beyond its
    at-rest gap; its largest over the run is the wall's located peak closure
    minus its gap (``peak_wall_closure`` − ``wall_gap`` of
    :func:`stochpound.simulate`), and 0 for a wall never reached (an ``inf``
    gap included). NaN without walls (an empty trailing axis).
    """
    closure, at_rest = np.asarray(peak_closure, dtype=np.float64), np.asarray(gap, dtype=np.float64)
    if closure.shape[-1] == 0:
        return np.full(closure.shape[:-1], np.nan)
    return np.maximum(np.max(closure - at_rest, axis=-1), 0.0)


def largest_wall_closure(peak_closure: np.ndarray) -> np.ndarray:
    """The largest peak closure toward a wall over the walls (trailing axis), m: the clearance the run needed.

    A wall's closure is its level's displacement toward it (``peak_wall_closure``
    of :func:`stochpound.simulate`, located on the solution, whatever its gap,
    ``inf`` included); a run with every wall at clearance c reaches one exactly
    when this value is at least c (before the first impact the run equals the
    run whose walls are never reached). NaN without walls (an empty trailing axis).
    """
    closure = np.asarray(peak_closure, dtype=np.float64)
    if closure.shape[-1] == 0:
        return np.full(closure.shape[:-1], np.nan)
    return np.max(closure, axis=-1)


def energy_residual_ratio(residual: np.ndarray, energy_input: np.ndarray) -> np.ndarray:
    """The largest absolute energy residual over the largest absolute energy input along the trailing axis (J/J): the energy balance's error."""
    return abs_peak(residual) / abs_peak(energy_input)


def final_value(values: np.ndarray) -> np.ndarray:
    """The last value along the trailing axis that is not NaN (NaN where every value is NaN)."""
    x = np.asarray(values, dtype=np.float64)
    present = ~np.isnan(x)
    last = x.shape[-1] - 1 - np.argmax(present[..., ::-1], axis=-1)
    value = np.take_along_axis(x, np.expand_dims(last, -1), axis=-1)[..., 0] if x.shape[-1] else np.full(x.shape[:-1], np.nan)
    return np.where(present.any(axis=-1), value, np.nan)


def impact_counts(in_phase: np.ndarray, peak_force: np.ndarray, duration: np.ndarray, impulse: np.ndarray, valid: np.ndarray) -> ImpactCounts:
    """Counts and extremes of the impacts listed along the trailing axis.

    Parameters
    ----------
    in_phase : numpy.ndarray
        Whether both floors moved the same way at onset (bool, or float with
        NaN padding).
    peak_force, duration, impulse : numpy.ndarray
        Largest force (N), duration (s) and impulse (N·s) of each impact.
    valid : numpy.ndarray of bool
        Which rows are impacts (False for padding).

    Returns
    -------
    ImpactCounts
        Extremes are 0 when there is no impact. The impulse is summed in
        table order (a cumulative sum), so trailing padding cannot change its
        last bit.
    """
    valid = np.asarray(valid, dtype=bool)
    count = np.sum(valid, axis=-1)
    phase = np.sum(valid & (np.nan_to_num(np.asarray(in_phase, dtype=np.float64)) != 0.0), axis=-1)

    def largest(values: np.ndarray) -> np.ndarray:
        if valid.shape[-1] == 0:
            return np.zeros(valid.shape[:-1])
        return np.max(np.where(valid, np.asarray(values, dtype=np.float64), 0.0), axis=-1)

    impulses = np.where(valid, np.asarray(impulse, dtype=np.float64), 0.0)
    total = np.cumsum(impulses, axis=-1)[..., -1] if valid.shape[-1] else np.zeros(valid.shape[:-1])
    return ImpactCounts(count, phase, count - phase, largest(peak_force), largest(duration), total)


def clopper_pearson(successes: np.ndarray, trials: np.ndarray, confidence: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
    """The exact (Clopper–Pearson) confidence interval of a binomial proportion.

    Parameters
    ----------
    successes, trials : numpy.ndarray
        k and n (broadcastable; n = 0 gives NaN).
    confidence : float
        Two-sided level in (0, 1).

    Returns
    -------
    lower, upper : numpy.ndarray
        The bounds in [0, 1]; equal to scipy's
        ``binomtest(k, n).proportion_ci(confidence, method="exact")``.
    """
    from scipy import stats

    check_confidence(confidence)
    k, n = np.broadcast_arrays(np.asarray(successes, dtype=np.float64), np.asarray(trials, dtype=np.float64))
    alpha = 1.0 - confidence
    with np.errstate(invalid="ignore"):
        lower = np.where(k > 0, stats.beta.ppf(alpha / 2, k, n - k + 1), 0.0)
        upper = np.where(k < n, stats.beta.ppf(1 - alpha / 2, k + 1, n - k), 1.0)
    empty = ~(n > 0)
    return np.where(empty, np.nan, lower), np.where(empty, np.nan, upper)


def t_interval(mean: np.ndarray, std: np.ndarray, count: np.ndarray, confidence: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
    """Student-t confidence interval of a mean from its sample mean, sample std (ddof = 1) and size.

    Returns
    -------
    lower, upper : numpy.ndarray
        mean ∓ t_{n−1, (1+c)/2} · std / sqrt(n); NaN for n < 2. Equal to
        ``scipy.stats.t.interval(c, n − 1, mean, std / sqrt(n))``.
    """
    from scipy import stats

    check_confidence(confidence)
    n = np.asarray(count, dtype=np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        half = stats.t.ppf(0.5 + confidence / 2, np.where(n >= 2, n - 1, np.nan)) * np.asarray(std) / np.sqrt(n)
    return mean - half, mean + half


def mean_interval(values: np.ndarray, confidence: float = 0.95) -> Interval:
    """Sample mean along the trailing axis with its Student-t confidence interval (NaN ignored)."""
    x = np.asarray(values, dtype=np.float64)
    count = np.sum(~np.isnan(x), axis=-1)
    sample = moments(x, -1)
    with np.errstate(invalid="ignore", divide="ignore"):
        std = sample.std * np.sqrt(count / (count - 1.0))
    lower, upper = t_interval(sample.mean, std, count, confidence)
    return Interval(sample.mean, lower, upper, count)


def bootstrap_mean_interval(values: np.ndarray, confidence: float = 0.95, resamples: int = BOOTSTRAP_RESAMPLES) -> Interval:
    """Sample mean along the trailing axis with its percentile-bootstrap confidence interval (NaN ignored).

    For a quantity that cannot be negative (counts, forces, peaks) a Student-t
    interval from a few skewed values reaches below zero (a mean impact force
    of 74.5 kN from 4 runs with bounds −11.1 and 160.2 kN). The percentile
    bootstrap of the mean (Efron & Tibshirani 1993, ch. 13) takes its bounds
    from means of resamples of the data, so they lie within the sample's range:
    never below zero for non-negative data, and asymmetric where the data are
    skewed. Its coverage, like the t interval's, approaches the nominal level
    as the sample grows (it is too narrow for a handful of values: state n).

    Parameters
    ----------
    values : numpy.ndarray
        The sample(s), along the trailing axis; NaN is ignored.
    confidence : float
        Two-sided level in (0, 1).
    resamples : int
        Bootstrap resamples (:data:`BOOTSTRAP_RESAMPLES`).

    Returns
    -------
    Interval
        The mean, the (1 − c)/2 and (1 + c)/2 quantiles (type 7) of the
        resampled means, and the count; NaN bounds for fewer than two values.
        Deterministic: the resampling depends only on :data:`BOOTSTRAP_SEED`
        and the sample size, and the values are sorted first, so the interval
        is a function of the sample's values, not of their order.
    """
    check_confidence(confidence)
    x = np.asarray(values, dtype=np.float64)
    flat = np.sort(x.reshape(-1, x.shape[-1]), axis=-1)  # NaN last
    count = np.sum(~np.isnan(flat), axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.nansum(flat, axis=-1) / count
    lower, upper = np.full(len(flat), np.nan), np.full(len(flat), np.nan)
    alpha = 1.0 - confidence
    for n in np.unique(count[count >= 2]):
        rows = count == n
        resampled = flat[rows, :n] @ _resample_weights(int(n), resamples).T / n  # rows x resamples
        lower[rows], upper[rows] = np.quantile(resampled, [alpha / 2, 1 - alpha / 2], axis=-1)
    shape = x.shape[:-1]
    return Interval(mean.reshape(shape), lower.reshape(shape), upper.reshape(shape), count.reshape(shape))


@lru_cache(maxsize=64)
def _resample_weights(n: int, resamples: int) -> np.ndarray:
    """:func:`~stochpound.stats._bootstrap.bootstrap_weights` of n values seeded with (:data:`BOOTSTRAP_SEED`, n), cached read-only."""
    weights = bootstrap_weights(n, resamples, (BOOTSTRAP_SEED, n))
    weights.flags.writeable = False
    return weights


def proportion_interval(events: np.ndarray, confidence: float = 0.95) -> Interval:
    """Fraction of true values along the trailing axis (NaN ignored) with its Clopper–Pearson interval."""
    x = np.asarray(events, dtype=np.float64)
    count = np.sum(~np.isnan(x), axis=-1)
    successes = np.nansum(x, axis=-1)
    lower, upper = clopper_pearson(successes, count, confidence)
    with np.errstate(invalid="ignore", divide="ignore"):
        return Interval(successes / count, lower, upper, count)


def quantiles(values: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Sample quantiles along the trailing axis (NaN ignored), the quantile axis last.

    The linear interpolation of :func:`numpy.nanquantile` (Hyndman & Fan's
    type 7, the default of numpy, R and scipy's ``mquantiles(alphap=1, betap=1)``).
    """
    x = np.asarray(values, dtype=np.float64)
    if x.shape[-1] == 0 or np.all(np.isnan(x)):
        return np.full(x.shape[:-1] + (len(q),), np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # an all-NaN slice gives NaN, as documented
        return np.moveaxis(np.nanquantile(x, np.asarray(q, dtype=np.float64), axis=-1), 0, -1)


def running_mean_interval(values: np.ndarray, confidence: float = 0.95) -> Interval:
    """The mean of the first n values and its t interval, for n = 1 … N along the trailing axis.

    NaN values are skipped (a missing realization leaves the estimate as it
    was); ``count`` is the number of values used so far.
    """
    x = np.asarray(values, dtype=np.float64)
    present = ~np.isnan(x)
    count = np.cumsum(present, axis=-1)
    total = np.cumsum(np.where(present, x, 0.0), axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = total / count
        deviation = np.where(present, x - mean, 0.0)
        # Welford's update: the sum of squared deviations from the running mean
        previous = np.concatenate([np.full(x.shape[:-1] + (1,), np.nan), mean[..., :-1]], axis=-1)
        step = np.where(present, (x - np.nan_to_num(previous)) * deviation, 0.0)
        squares = np.cumsum(np.where(count == 1, 0.0, step), axis=-1)
        std = np.sqrt(squares / (count - 1.0))
    lower, upper = t_interval(mean, std, count, confidence)
    return Interval(mean, lower, upper, count)


def running_proportion_interval(events: np.ndarray, confidence: float = 0.95) -> Interval:
    """The fraction of true values among the first n, with its Clopper–Pearson interval, n = 1 … N."""
    x = np.asarray(events, dtype=np.float64)
    present = ~np.isnan(x)
    count = np.cumsum(present, axis=-1)
    successes = np.cumsum(np.where(present, x, 0.0), axis=-1)
    lower, upper = clopper_pearson(successes, count, confidence)
    with np.errstate(invalid="ignore", divide="ignore"):
        return Interval(successes / count, lower, upper, count)
