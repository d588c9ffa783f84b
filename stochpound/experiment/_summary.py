"""Per-case summaries, kept time histories and impact table of one run.

The statistics come from :mod:`stochpound.analysis` (one definition for the
whole toolkit); this module only chooses and names what an experiment store
keeps. A case's result is flattened into named numpy arrays (stacked with
other cases' into a part, :mod:`stochpound.experiment._parts`):

* ``s:<name>``: summaries (dimensions ``building`` or none);
* ``t:<name>``: kept time histories (at the motion's samples);
* ``i:<name>``: the impact table's columns.

The store's units and long names are declared once, in the store's
catalogue (``stochpound.store.CATALOGUE``), and the summaries take theirs
from it; the tests hold the catalogue's names and dimensions against a real run.

:func:`case_summary` and :func:`reference_summary` give the summaries as
xarray datasets (their metadata names and describes the store's variables);
per case, the experiment takes the same values from :func:`case_values` and
:func:`reference_values`, which read the run's variables directly
(``run.variables``) and call the numpy kernels of
:mod:`stochpound.stats.kernels` (xarray's per-call overhead would cost
several times the solver's time). Both go through the same kernels; the
tests check that they agree.
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
import xarray as xr

from stochpound.analysis import peak_response
from stochpound.stats import kernels
from stochpound.analysis.names import RESPONSE_MOMENTS, without_aliases
from stochpound.analysis import response_moments, run_summary, top_floor_total_displacement
from stochpound.codes import STORE_NAMES, contact_demands
from stochpound.store import CATALOGUE, IMPACT_TABLE, STOREY_SUMMARIES, WALL_SUMMARIES

_MOMENTS = tuple(RESPONSE_MOMENTS.values())
_PEAKS = ("peak_total_displacement", "peak_relative_displacement", "peak_sliding_displacement", "residual_sliding")
#: Summaries of the fixed-base reference (prefixed ``reference_`` in the store).
REFERENCE_SUMMARIES = (*_MOMENTS, "peak_total_displacement", "peak_relative_displacement")
#: Demand summaries kept with ``[output] demands = true``: name -> (result peak it reduces, long name).
DEMAND_SUMMARIES = {
    "peak_floor_acceleration": ("peak_total_acceleration", "largest peak total (absolute) floor acceleration over the building's floors"),
    "peak_interstorey_drift": ("peak_storey_drift", "largest peak storey drift over the building's storeys"),
    "peak_base_shear": ("peak_base_shear", "largest absolute base shear over the run"),
}
#: The wall summaries (``stochpound.store.WALL_SUMMARIES``): every case computes them (NaN without walls); a store keeps them when its scene has walls.
WALL_PENETRATION, WALL_CLOSURE = WALL_SUMMARIES
#: The storey summaries (``stochpound.store.STOREY_SUMMARIES``): name -> the run's per-storey variable whose largest absolute
#: value over each building's storeys it keeps. Every case computes them (NaN where the run has no such variable); a store
#: keeps them when its buildings have yielding storeys or storey heights.
STOREY_SOURCES = dict(zip((v.name for v in STOREY_SUMMARIES),
                          ("peak_storey_drift_ratio", "peak_storey_ductility", "residual_storey_drift", "residual_storey_drift_ratio")))
#: Columns of the impact table a store keeps (``stochpound.store.IMPACT_TABLE``).
IMPACT_COLUMNS = tuple(v.name for v in IMPACT_TABLE)


def case_summary(run: xr.Dataset, studied: str, fixed_base: xr.DataArray) -> xr.Dataset:
    """Summaries of one case.

    Parameters
    ----------
    run : xarray.Dataset
        Result of :func:`stochpound.simulate`.
    studied : str
        The studied building (its top-floor total displacement is the response).
    fixed_base : xarray.DataArray
        The studied building's top-floor total displacement alone on a fixed
        base under the same motion, m.

    Returns
    -------
    xarray.Dataset
        Peaks and residual sliding per building (m), impact statistics,
        moments of the response, ``fixed_base_correlation``,
        ``energy_residual_ratio``, ``events_total``, ``peak_wall_penetration``
        and ``largest_wall_closure`` (m; NaN without walls), and the storey
        summaries per building (:data:`STOREY_SOURCES`; NaN where the run
        lacks their source).
    """
    summary = without_aliases(run_summary(run, studied, fixed_base)).drop_vars(list(_PEAKS))
    summary = xr.merge([summary, peak_response(run)])
    summary["events_total"] = xr.DataArray(np.int64(run.attrs.get("events_total", 0)))
    summary = summary.merge(_contact_summary(run))
    if "peak_total_acceleration" in run:
        summary = summary.merge(_demand_summary(run))
    summary[WALL_PENETRATION.name] = xr.DataArray(_wall_penetration(run))
    summary[WALL_CLOSURE.name] = xr.DataArray(_wall_closure(run))
    for name, values in _storey_values(run).items():
        summary[name] = xr.DataArray(values, dims=("building",), coords={"building": run["building"].values})
    return _catalogued(summary)


def _catalogued(summary: xr.Dataset) -> xr.Dataset:
    """``summary`` with each variable's ``units`` and ``long_name`` those of the store's catalogue (``stochpound.store.CATALOGUE``)."""
    for name, variable in summary.data_vars.items():
        variable.attrs.update(CATALOGUE[name].attrs)
    return summary


def _demand_summary(run: xr.Dataset) -> xr.Dataset:
    """Per building, the largest over its floors (storeys) of each demand peak (:data:`DEMAND_SUMMARIES`)."""
    summary = xr.Dataset()
    for name, (source, long_name) in DEMAND_SUMMARIES.items():
        peak = run[source].max("floor") if "floor" in run[source].dims else run[source]
        summary[name] = peak.assign_attrs(units=run[source].attrs["units"], long_name=long_name)
    return summary


def _contact_summary(run: xr.Dataset) -> xr.Dataset:
    """Per contact: the peak closure and the inputs of the separation rules (:func:`stochpound.analysis.separation_rules.contact_demands`)."""
    demands = contact_demands(run)
    return demands.rename(STORE_NAMES).drop_vars("contact")


def reference_summary(run: xr.Dataset, studied: str) -> xr.Dataset:
    """Summaries of the fixed-base reference run (``reference_*``, no building dimension)."""
    peaks = peak_response(run)[["peak_total_displacement", "peak_relative_displacement"]].sel(building=studied, drop=True)
    summary = xr.merge([response_moments(top_floor_total_displacement(run, studied)), peaks])
    return _catalogued(summary[list(REFERENCE_SUMMARIES)].rename({name: f"reference_{name}" for name in REFERENCE_SUMMARIES}))


def top_floor(run: xr.Dataset, studied: str) -> np.ndarray:
    """The studied building's top-floor total displacement over time, m (numpy)."""
    index = list(run.variables["building"].values).index(studied)
    y = run.variables["total_displacement"].values[index]
    top = int(np.sum(~np.all(np.isnan(y), axis=-1)))
    return y[top - 1]


def _moment_values(response: np.ndarray) -> dict[str, np.ndarray]:
    return dict(zip(_MOMENTS, kernels.moments(response)))


def case_values(run: xr.Dataset, studied: str, fixed_base: np.ndarray) -> dict[str, np.ndarray]:
    """The values of :func:`case_summary`, computed with the numpy kernels (names of the store)."""
    variables = run.variables
    y, u, s = (variables[name].values for name in ("total_displacement", "relative_displacement", "sliding_displacement"))
    columns = [variables[name].values for name in ("impact_in_phase", "impact_peak_force", "impact_duration", "impact_impulse")]
    impacts = kernels.impact_counts(*columns, np.ones(columns[0].shape, dtype=bool))
    response = top_floor(run, studied)
    return {
        **{name: np.int64(value) if name.startswith("impacts") else np.float64(value) for name, value in impacts._asdict().items()},
        **_moment_values(response),
        "energy_residual_ratio": kernels.energy_residual_ratio(variables["energy_residual"].values, variables["energy_input"].values),
        "fixed_base_correlation": kernels.pearson(response, fixed_base),
        "peak_total_displacement": kernels.abs_peak(y, (1, 2)),
        "peak_relative_displacement": kernels.abs_peak(u, (1, 2)),
        "peak_sliding_displacement": kernels.abs_peak(s),
        "residual_sliding": kernels.final_value(s),
        "events_total": np.int64(run.attrs.get("events_total", 0)),
        **_contact_values(run),
        **_demand_values(run),
        WALL_PENETRATION.name: _wall_penetration(run),
        WALL_CLOSURE.name: _wall_closure(run),
        **_storey_values(run),
    }


def _storey_values(run: xr.Dataset) -> dict[str, np.ndarray]:
    """Per building, the largest absolute value over its storeys of each of :data:`STOREY_SOURCES` (NaN where the run lacks it)."""
    variables = run.variables
    missing = np.full(variables["building"].shape, np.nan)
    return {name: kernels.abs_peak(variables[source].values, 1) if source in variables else missing for name, source in STOREY_SOURCES.items()}


def _wall_penetration(run: xr.Dataset) -> np.float64:
    """The largest wall penetration of the run, m, from its walls' located peak closures (:func:`stochpound.stats.kernels.wall_penetration`; NaN without walls)."""
    variables = run.variables
    if "peak_wall_closure" not in variables:
        return np.float64(np.nan)
    return np.float64(kernels.wall_penetration(variables["peak_wall_closure"].values, variables["wall_gap"].values))


def _wall_closure(run: xr.Dataset) -> np.float64:
    """The largest peak closure toward a wall over the run and its walls, m (:func:`stochpound.stats.kernels.largest_wall_closure`; NaN without walls)."""
    variables = run.variables
    if "peak_wall_closure" not in variables:
        return np.float64(np.nan)
    return np.float64(kernels.largest_wall_closure(variables["peak_wall_closure"].values))


def _demand_values(run: xr.Dataset) -> dict[str, np.ndarray]:
    """The values of :func:`_demand_summary` with the numpy kernels (none for a run without demands)."""
    variables = run.variables
    if "peak_total_acceleration" not in variables:
        return {}
    return {
        name: kernels.abs_peak(variables[source].values, 1) if variables[source].ndim == 2 else variables[source].values.astype(float)
        for name, (source, _) in DEMAND_SUMMARIES.items()
    }


def _contact_values(run: xr.Dataset) -> dict[str, np.ndarray]:
    """The values of :func:`_contact_summary` with the numpy kernels."""
    variables = run.variables
    names = list(variables["building"].values)
    y = variables["total_displacement"].values

    def floors(side: str) -> np.ndarray:
        buildings = [names.index(b) for b in variables[f"contact_{side}"].values]
        return y[buildings, variables[f"contact_{side}_floor"].values.astype(int) - 1]

    left, right = floors("left"), floors("right")
    return {
        "peak_contact_closure": variables["peak_contact_closure"].values.astype(float),
        "contact_peak_displacement_left": variables["peak_contact_displacement_left"].values.astype(float),
        "contact_peak_displacement_right": variables["peak_contact_displacement_right"].values.astype(float),
        "contact_correlation": kernels.pearson(left, right),
    }


def reference_values(displacement: np.ndarray) -> dict[str, np.ndarray]:
    """The values of :func:`reference_summary`, computed with the numpy kernels (names of the store).

    ``displacement`` (floors × time, m) is the fixed-base building's floor
    displacements, its total and relative displacement alike.
    """
    peak = kernels.abs_peak(displacement, (0, 1))
    values = {**_moment_values(displacement[-1]), "peak_total_displacement": peak, "peak_relative_displacement": peak}
    return {f"reference_{name}": values[name] for name in REFERENCE_SUMMARIES}


def case_arrays(summary: Mapping[str, np.ndarray], run: xr.Dataset, histories: Sequence[str], buildings: Sequence[str], impacts: bool) -> dict[str, np.ndarray]:
    """Flatten a case into the named arrays of a part (module docstring).

    Parameters
    ----------
    summary : mapping
        From :func:`case_values` or :func:`reference_values`.
    run : xarray.Dataset
        The run.
    histories : sequence of str
        Time-history variables to keep.
    buildings : sequence of str
        Buildings whose time histories are kept (variables with a ``building`` dimension).
    impacts : bool
        Keep the impact table.
    """
    arrays = {f"s:{name}": np.asarray(value) for name, value in summary.items()}
    if histories:
        names = list(run.variables["building"].values)
        kept = [names.index(b) for b in buildings if b in names]
        for name in histories:
            variable = run.variables[name]
            arrays[f"t:{name}"] = variable.values[kept] if variable.dims[0] == "building" else variable.values
    if impacts:
        arrays.update({f"i:{name}": run.variables[name].values for name in IMPACT_COLUMNS})
    return arrays


def reference_arrays(summary: Mapping[str, np.ndarray], displacement: np.ndarray, keep_history: bool) -> dict[str, np.ndarray]:
    """Part arrays of a reference case: its summaries and, if asked, its floors' total displacement (floors × time, m)."""
    arrays = {f"s:{name}": np.asarray(value) for name, value in summary.items()}
    if keep_history:
        arrays["t:reference_total_displacement"] = displacement
    return arrays
