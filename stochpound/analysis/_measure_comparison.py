"""The conditioned g* of each candidate measure against the answer without a measure (issue 44, item 5; docs/measure-free.md).

At a site of ruptures, each candidate intensity measure gives its own g*
(the risk chain on stripes of that measure, selected to the exact
conditional spectrum), once per seed of the selection; the answer without
a measure (:func:`~stochpound.analysis.store_measure_free`) is the
reference. For every configuration, measure and target this puts side by
side the conditioned g* (the median over the seeds and the seed-to-seed
spread, max/min), the measure-free g* with its interval, and their ratio:
a measure *agrees* where the ratio of its median is within ``tolerance``
(×1.2 by default, the issue's) either way. Given each measure's sufficiency
test (:func:`~stochpound.analysis.store_sufficiency` of one of its stores),
a row that does not agree carries the measured reason: the demand's trend
with M, ln R or ε within that measure's stripes, or that it has none (then
the miss is not the measure's insufficiency by that test, and lies in the
selection, the fit or the motions).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from stochpound.analysis._measure_free_store import StoreMeasureFree, configuration_label
from stochpound.analysis._sufficiency import StoreSufficiency

TOLERANCE = 1.2
"""The largest ratio either way at which a measure's g* agrees with the measure-free one (the issue's ×1.2)."""


def compare_measures(conditioned: Mapping[str, Sequence[xr.DataArray]], free: StoreMeasureFree, *,
                     tolerance: float = TOLERANCE, sufficiency: Mapping[str, StoreSufficiency] | None = None) -> pd.DataFrame:
    """The conditioned g* of every measure, over its seeds, beside the measure-free g* (module docstring).

    Parameters
    ----------
    conditioned : mapping of str to sequence of xarray.DataArray
        For each measure (its label), g* (m) of each seed of the selection: over ``target`` (probabilities) and the
        configuration dimensions of ``free`` (e.g. ``StoreRisk.separation["separation"]``).
    free : StoreMeasureFree
        The answer without a measure for the same store's configurations (its closure's level is g*).
    tolerance : float
        The ratio (> 1) either way within which a measure agrees.
    sufficiency : mapping of str to StoreSufficiency, optional
        For some or all measures (by label), the sufficiency test of one of its stores, over the same configurations.

    Returns
    -------
    pandas.DataFrame
        One row per configuration, measure and target: ``measure-free`` g* and its ``lower``, ``upper``; the conditioned
        ``median`` over the seeds, ``lowest``, ``highest`` and ``seed spread`` (max/min); ``seeds``; ``ratio``
        (median / measure-free) and ``agrees`` (the ratio within ``tolerance`` either way); with ``sufficiency``, also
        ``insufficient`` (the covariates of significant trend, comma-separated, "" for none) and ``reason`` (a row that does not
        agree: :meth:`Sufficiency.reason`, with its n; "" for a row that agrees or a measure without a test).

    Raises
    ------
    ValueError
        One line naming the argument: no measure, a measure without seeds, a target or configuration the
        measure-free answer does not have, a tolerance not above 1, a sufficiency test of a measure not compared.
    """
    if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)) or not 1.0 < tolerance < math.inf:
        raise ValueError(f"tolerance: must be a ratio > 1, got {tolerance!r}")
    if not conditioned or any(not seeds for seeds in conditioned.values()):
        raise ValueError("conditioned: must give one or more measures, each with g* of one or more seeds")
    sufficiency = sufficiency or {}
    unknown = [name for name in sufficiency if name not in conditioned]
    if unknown:
        raise ValueError(f"sufficiency: {unknown[0]!r} is not one of the measures compared ({', '.join(conditioned)})")
    rows = []
    for labels, results in zip(free.configurations, free.results):
        closure = results[0]
        for measure, seeds in conditioned.items():
            for t, target in enumerate(closure.target.values):
                values = np.array([_at(g_star, labels, float(target), measure) for g_star in seeds])
                reference = float(closure.level.values[t])
                median = float(np.median(values))
                agrees = bool(1.0 / tolerance <= median / reference <= tolerance)
                rows.append({"configuration": configuration_label(labels), "measure": measure, "target": float(target),
                             "measure-free": reference, "lower": float(closure.level_lower.values[t]),
                             "upper": float(closure.level_upper.values[t]), "median": median, "lowest": float(values.min()),
                             "highest": float(values.max()), "seed spread": float(values.max() / values.min()), "seeds": values.size,
                             "ratio": median / reference, "agrees": agrees,
                             **_reason(sufficiency.get(measure), labels, agrees, bool(sufficiency))})
    return pd.DataFrame(rows).set_index(["configuration", "measure", "target"])


def _reason(test: StoreSufficiency | None, labels: tuple[tuple[str, Any], ...], agrees: bool, wanted: bool) -> dict[str, str]:
    """The ``insufficient`` and ``reason`` columns of a row (none without any sufficiency test)."""
    if not wanted:
        return {}
    if test is None:
        return {"insufficient": "", "reason": ""}
    result = test.result(labels)
    return {"insufficient": ", ".join(result.insufficient), "reason": "" if agrees else result.reason()}


def _at(g_star: xr.DataArray, labels: tuple[tuple[str, Any], ...], target: float, measure: str) -> float:
    """g* of one configuration (its (dimension, label) pairs) and target, or a one-line error naming what the measure's answer lacks."""
    where = {"target": target, **dict(labels)}
    missing = [dim for dim in where if dim not in g_star.dims]
    if missing:
        raise ValueError(f"conditioned[{measure!r}]: g* has no dimension {missing[0]!r} (the measure-free answer's configurations: "
                         f"{', '.join(where)})")
    try:
        return float(g_star.sel(where).item())
    except KeyError:
        raise ValueError(f"conditioned[{measure!r}]: g* has no value at {where}") from None
