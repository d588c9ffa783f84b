"""One name for each per-run quantity, and the names it had before, kept working as aliases.

The moments of the studied response are ``response_mean``, ``response_variance``,
``response_std``, ``response_skewness`` and ``response_excess`` everywhere (the
experiment store's names), and the correlation with the fixed-base twin is
``fixed_base_correlation``. :func:`stochpound.analysis.run_summary` used to call
them ``mean`` … ``excess`` and ``correlation``, and
:func:`stochpound.simulate_ensemble` ``top_floor_mean`` … ``top_floor_excess``:
those names remain in their results as aliases (the same data, with an
``alias_of`` attribute), so code written against them keeps working.
"""

from __future__ import annotations

from collections.abc import Mapping

import xarray as xr

from stochpound.store import VariableAttributes

#: Moment (as :func:`stochpound.analysis.moments` names it) -> the quantity's name.
RESPONSE_MOMENTS = {
    "mean": "response_mean",
    "variance": "response_variance",
    "std": "response_std",
    "skewness": "response_skewness",
    "excess": "response_excess",
}
#: Earlier names of :func:`stochpound.analysis.run_summary`'s results.
RUN_SUMMARY_ALIASES = {**RESPONSE_MOMENTS, "correlation": "fixed_base_correlation"}
#: Earlier names of :func:`stochpound.simulate_ensemble`'s moments.
ENSEMBLE_ALIASES = {f"top_floor_{moment}": name for moment, name in RESPONSE_MOMENTS.items()}


def with_aliases(dataset: xr.Dataset, aliases: Mapping[str, str]) -> xr.Dataset:
    """``dataset`` with each alias (old name -> current name) added as the same data, ``alias_of`` in its attributes."""
    added = {}
    for old, current in aliases.items():
        if current in dataset:
            variable = dataset[current]
            added[old] = variable.copy(deep=False).assign_attrs(variable.attrs, alias_of=current, long_name=f"{VariableAttributes.of(variable, long_name=current).long_name} (alias of {current})")
    return dataset.assign(added)


def without_aliases(dataset: xr.Dataset) -> xr.Dataset:
    """``dataset`` without the variables that are aliases of others."""
    return dataset.drop_vars([name for name, variable in dataset.data_vars.items() if "alias_of" in variable.attrs])
