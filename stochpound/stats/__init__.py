"""The numerical core of every statistic, below every package that computes one.

:mod:`stochpound.stats.kernels` holds the numpy kernels, the one
implementation of every statistic of the toolkit; :func:`reduce` applies a
kernel to xarray objects (lazily on dask); :func:`correlation` is the
Pearson correlation of two histories; the resampling of an ensemble's
motions (bootstrap and jackknife weights, BCa intervals) is the one
resampler of the fragility and risk bootstraps and of the percentile
intervals, which cluster motions on their earthquake, one identity per
earthquake across suites (:func:`earthquake_identities`). The ensemble statistics (:mod:`stochpound.analysis`), the
experiment's per-case summaries, the record statistics and the risk chain
all compute with these; this package imports none of them.
"""

from stochpound.stats import kernels
from stochpound.stats._bootstrap import bootstrap_method, bootstrap_weights, interval, jackknife_weights, record_clusters, resampling_obstacle
from stochpound.stats._correlation import correlation
from stochpound.stats._earthquakes import earthquake_identities
from stochpound.stats._ufunc import reduce

__all__ = [
    "kernels",
    "reduce",
    "correlation",
    "bootstrap_weights",
    "jackknife_weights",
    "record_clusters",
    "earthquake_identities",
    "bootstrap_method",
    "resampling_obstacle",
    "interval",
]
