"""Per-case summaries, kept time histories and impact table of one run.

The statistics come from :mod:`stochpound.analysis` (one definition for the
whole toolkit); this module only chooses and names what an experiment store
keeps. A case's result is flattened into named numpy arrays (stacked with
other cases' into a part, :mod:`stochpound.experiment.parts`):

* ``s:<name>``: summaries (dimensions ``building`` or none);
* ``t:<name>``: kept time histories (at the motion's samples);
* ``i:<name>``: the impact table's columns.

Units and long names are taken from a tiny real run (:func:`templates`), so
they always match :func:`stochpound.simulate` and :mod:`stochpound.analysis`.

:func:`case_summary` and :func:`reference_summary` define the summaries with
:mod:`stochpound.analysis`. Per case, the experiment evaluates the same
quantities with plain numpy (:func:`case_values`, :func:`reference_values`),
reading the run's variables directly (``run.variables``): xarray's per-call
overhead would cost several times the solver's time. The tests check that
both agree.
"""

from __future__ import annotations

from functools import cache
from typing import Any, Mapping, Sequence

import numpy as np
import xarray as xr

from stochpound.analysis import moments, peak_response
from stochpound.analysis.summary import run_summary, top_floor_total_displacement
from stochpound.records.statistics import moments as sample_moments

#: Summary names of :func:`stochpound.analysis.run_summary` renamed in the store
#: (``mean``/``std`` would shadow Dataset methods).
RENAMES = {
    "mean": "response_mean",
    "variance": "response_variance",
    "std": "response_std",
    "skewness": "response_skewness",
    "excess": "response_excess",
    "correlation": "fixed_base_correlation",
}
_MOMENTS = ("response_mean", "response_variance", "response_std", "response_skewness", "response_excess")
_PEAKS = ("peak_total_displacement", "peak_relative_displacement", "peak_sliding_displacement", "residual_sliding")
#: Summaries of the fixed-base reference (prefixed ``reference_`` in the store).
REFERENCE_SUMMARIES = (*_MOMENTS, "peak_total_displacement", "peak_relative_displacement")
IMPACT_COLUMNS = (
    "impact_contact",
    "impact_start",
    "impact_end",
    "impact_duration",
    "impact_peak_force",
    "impact_peak_time",
    "impact_impulse",
    "impact_onset_velocity",
    "impact_in_phase",
    "impact_complete",
)


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
        ``energy_residual_ratio`` and ``events_total``.
    """
    summary = run_summary(run, studied, fixed_base).drop_vars(list(_PEAKS))
    summary = xr.merge([summary, peak_response(run)]).rename(RENAMES)
    _describe_moments(summary, "")
    summary["fixed_base_correlation"].attrs["long_name"] = (
        "correlation of the studied building's top-floor total displacement with the same building alone on a fixed base"
    )
    summary["events_total"] = xr.DataArray(np.int64(run.attrs.get("events_total", 0)), attrs={"units": "1", "long_name": "events located by the solver"})
    return summary


def reference_summary(run: xr.Dataset, studied: str) -> xr.Dataset:
    """Summaries of the fixed-base reference run (``reference_*``, no building dimension)."""
    peaks = peak_response(run)[["peak_total_displacement", "peak_relative_displacement"]].sel(building=studied, drop=True)
    response = moments(top_floor_total_displacement(run, studied), "time")
    summary = xr.merge([response.rename({name: RENAMES[name] for name in response.data_vars}), peaks])
    _describe_moments(summary, "")
    renamed = summary[list(REFERENCE_SUMMARIES)].rename({name: f"reference_{name}" for name in REFERENCE_SUMMARIES})
    for variable in renamed.data_vars.values():
        variable.attrs["long_name"] = f"{variable.attrs['long_name']} (studied building alone on a fixed base)"
    return renamed


def _describe_moments(summary: xr.Dataset, suffix: str) -> None:
    for name in _MOMENTS:
        summary[name].attrs["long_name"] = f"{summary[name].attrs['long_name']} of the studied building's top-floor total displacement{suffix}"
    summary["response_variance"].attrs["units"] = "m2"  # CF spelling of (m)2


def _nan_abs_max(values: np.ndarray, axis: tuple[int, ...]) -> np.ndarray:
    """max |values| over ``axis`` ignoring NaN (NaN where everything is NaN)."""
    magnitude = np.abs(values)
    result = np.max(np.where(np.isnan(magnitude), -np.inf, magnitude), axis=axis)
    return np.where(np.isneginf(result), np.nan, result)


def top_floor(run: xr.Dataset, studied: str) -> np.ndarray:
    """The studied building's top-floor total displacement over time, m (numpy)."""
    index = list(run.variables["building"].values).index(studied)
    y = run.variables["total_displacement"].values[index]
    top = int(np.sum(~np.all(np.isnan(y), axis=-1)))
    return y[top - 1]


def _moment_values(response: np.ndarray) -> dict[str, np.ndarray]:
    mean, std, skewness, excess = sample_moments(response)
    return {
        "response_mean": np.float64(mean),
        "response_variance": np.float64(std * std),
        "response_std": np.float64(std),
        "response_skewness": np.float64(skewness),
        "response_excess": np.float64(excess),
    }


def case_values(run: xr.Dataset, studied: str, fixed_base: np.ndarray) -> dict[str, np.ndarray]:
    """The values of :func:`case_summary`, computed with numpy (names of the store)."""
    variables = run.variables
    y, u, s = (variables[name].values for name in ("total_displacement", "relative_displacement", "sliding_displacement"))
    in_phase = variables["impact_in_phase"].values.astype(bool)
    count = np.int64(in_phase.size)

    def largest(name: str) -> np.float64:
        values = variables[name].values
        return np.float64(values.max()) if values.size else np.float64(0.0)

    response = top_floor(run, studied)
    residual, energy_input = np.abs(variables["energy_residual"].values), np.abs(variables["energy_input"].values)
    return {
        "impacts": count,
        "impacts_in_phase": np.int64(in_phase.sum()),
        "impacts_out_of_phase": np.int64(count - in_phase.sum()),
        "peak_impact_force": largest("impact_peak_force"),
        "longest_impact": largest("impact_duration"),
        "total_impulse": np.float64(variables["impact_impulse"].values.sum()),
        **_moment_values(response),
        "energy_residual_ratio": np.float64(residual.max() / energy_input.max()),
        "fixed_base_correlation": np.float64(np.corrcoef(response, fixed_base)[0, 1]),
        "peak_total_displacement": _nan_abs_max(y, (1, 2)),
        "peak_relative_displacement": _nan_abs_max(u, (1, 2)),
        "peak_sliding_displacement": np.abs(s).max(axis=1),
        "residual_sliding": s[:, -1].copy(),
        "events_total": np.int64(run.attrs.get("events_total", 0)),
    }


def reference_values(displacement: np.ndarray) -> dict[str, np.ndarray]:
    """The values of :func:`reference_summary`, computed with numpy (names of the store).

    ``displacement`` (floors × time, m) is the fixed-base building's floor
    displacements, its total and relative displacement alike.
    """
    peak = _nan_abs_max(displacement, (0, 1))
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


@cache
def templates() -> tuple[xr.Dataset, xr.Dataset, xr.Dataset]:
    """A tiny real run and its case and reference summaries (metadata: dims, dtypes, units, long names)."""
    from stochpound.scene_file import scene_from_dict
    from stochpound.simulate import simulate

    building = {"mass": [1.0], "stiffness": [1.0]}
    scene = scene_from_dict(
        {
            "building": [{"name": "A", **building}, {"name": "B", **building}],
            "contact": [{"between": [["A", 1], ["B", 1]], "gap": 1.0, "stiffness": 1.0, "restitution": 0.5}],
            "motion": {"type": "constant", "acceleration": 1.0, "duration": 2.0, "dt": 1.0},
        },
        source="template",
    )
    run = simulate(scene, "ivp")  # the reference path: the tiny run only provides metadata
    response = top_floor_total_displacement(run, "A")
    return run, case_summary(run, "A", response), reference_summary(run.isel(building=[0]), "A")


def variable_attrs(name: str) -> dict[str, Any]:
    """Units and long name of a result, summary or reference variable."""
    run, summary, reference = templates()
    for dataset in (summary, reference, run):
        if name in dataset.variables:
            return {k: dataset[name].attrs[k] for k in ("units", "long_name") if k in dataset[name].attrs}
    if name == "reference_total_displacement":
        return {"units": "m", "long_name": "total displacement of the studied building alone on a fixed base"}
    raise KeyError(name)
