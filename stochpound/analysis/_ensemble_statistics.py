"""Ensemble statistics of an experiment store, per grid cell: what the realizations of each cell show together.

For every cell of the grid (every combination of the store's axes but
``realization``) and every per-case summary: the mean with its confidence
interval; for the peaks, quantiles too; and the probability of pounding with
its exact interval. Lazy on the dask-backed store of
:func:`stochpound.open_store`: nothing is read until computed.
"""

from __future__ import annotations

from collections.abc import Sequence

import xarray as xr

from stochpound.analysis._intervals import QUANTILES, mean_interval, quantiles
from stochpound.analysis._pounding import pounding_probability
from stochpound.store import VariableAttributes

#: Per-case summaries whose ensemble mean is estimated (store names).
SUMMARIES = (
    "response_std",
    "response_skewness",
    "response_excess",
    "fixed_base_correlation",
    "peak_total_displacement",
    "peak_relative_displacement",
    "peak_sliding_displacement",
    "residual_sliding",
    "impacts_in_phase",
    "impacts_out_of_phase",
    "peak_impact_force",
    "reference_response_std",
    "reference_peak_total_displacement",
    "reference_peak_relative_displacement",
    "peak_floor_acceleration",
    "peak_interstorey_drift",
    "peak_base_shear",
    "peak_wall_penetration",
)
#: Summaries whose quantiles are given too.
PEAKS = (
    "peak_total_displacement",
    "peak_relative_displacement",
    "peak_sliding_displacement",
    "peak_impact_force",
    "reference_peak_total_displacement",
    "reference_peak_relative_displacement",
    "peak_floor_acceleration",
    "peak_interstorey_drift",
    "peak_base_shear",
    "peak_wall_penetration",
)
#: Summaries estimated over the realizations that pound only (their value is 0 without an impact).
GIVEN_POUNDING = ("peak_impact_force",)
#: Summaries that can be of either sign: their means get a Student-t interval. Every other summary (counts, forces,
#: peaks, standard deviations) cannot be negative and gets the percentile bootstrap, whose bounds stay within the
#: sample's range (:func:`stochpound.stats.kernels.bootstrap_mean_interval`).
SIGNED = ("response_skewness", "response_excess", "fixed_base_correlation", "residual_sliding")


def interval_method(name: str) -> str:
    """The interval method of a summary's mean: ``t`` for a signed one (:data:`SIGNED`), else ``bootstrap``."""
    return "t" if name in SIGNED else "bootstrap"


def ensemble_statistics(
    store: xr.Dataset, dim: str = "realization", confidence: float = 0.95, q: Sequence[float] = QUANTILES
) -> xr.Dataset:
    """Per-cell ensemble statistics of every summary of ``store``.

    Parameters
    ----------
    store : xarray.Dataset
        An experiment store (:func:`stochpound.open_store`), or a selection
        of one (e.g. ``store.sel(record="kt_firm")``).
    dim : str
        The ensemble dimension.
    confidence : float
        Two-sided confidence level of every interval, in (0, 1).
    q : sequence of float
        Quantiles of the peaks.

    Returns
    -------
    xarray.Dataset
        For each summary ``s`` of ``SUMMARIES`` in the store:
        ``s_mean``, ``s_lower``, ``s_upper`` (interval of the mean: Student t
        for a summary of either sign, the percentile bootstrap for one that
        cannot be negative, ``interval_method``); for the peaks ``s_quantile`` (dimension ``quantile``);
        ``peak_impact_force_*`` over the realizations with at least one
        impact (``peak_impact_force_count`` of them); and
        ``pounding_probability`` with its Clopper–Pearson bounds
        ``pounding_probability_lower``/``_upper`` and ``realizations``
        (cases done). Missing cases are left out. Lazy.
    """
    variables: dict[str, xr.DataArray] = {}
    for name in (s for s in SUMMARIES if s in store and dim in store[s].dims):
        data = store[name]
        if name in GIVEN_POUNDING:
            data = data.where(store["impacts"] > 0).assign_attrs(data.attrs, long_name=f"{VariableAttributes.of(data, long_name=name).long_name}, given pounding")
        interval = mean_interval(data, dim, confidence, interval_method(name))
        for part in ("mean", "lower", "upper"):
            variables[f"{name}_{part}"] = interval[part]
        if name in GIVEN_POUNDING:
            variables[f"{name}_count"] = interval["count"]
        if name in PEAKS:
            variables[f"{name}_quantile"] = quantiles(data, q, dim)
    if "impacts" in store:
        probability = pounding_probability(store["impacts"], dim, confidence)
        variables["pounding_probability"] = probability["probability"]
        variables["pounding_probability_lower"] = probability["lower"]
        variables["pounding_probability_upper"] = probability["upper"]
        variables["realizations"] = probability["realizations"]
    return xr.Dataset(variables, attrs={"confidence": confidence})
