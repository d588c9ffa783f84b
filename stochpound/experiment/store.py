"""The experiment store: one netCDF4/HDF5 file assembled from the finished cases.

The store is rebuilt from the parts (:mod:`stochpound.experiment.parts`) and
written atomically (temporary file renamed into place) at the start and end of
a run, at checkpoints, on ``status`` and on resume: it is always a complete,
readable file, whatever happens to the run. Its layout (docs/experiments.md):

* coordinates: the grid's dimensions (variant axes, ``gap``…, ``mu``), the
  motion's (``record``, ``realization``), ``building``, ``floor``, ``contact``
  and, with time histories, ``time`` (the union of the motions' sample times);
* ``case_status`` (−1 not in the grid, 0 missing, 1 done) and ``case_id`` on
  the case dimensions, ``reference_status``/``reference_case_id`` likewise;
* per-case summaries on the case dimensions (plus ``building``), the
  fixed-base reference's ``reference_*`` summaries on the reference dimensions;
* kept time histories on the case dimensions plus their own and ``time``;
* the impact table on dimension ``impact``, with the case's coordinates
  (``impact_case_id``, ``impact_<dim>``);
* provenance attributes.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

import numpy as np
import xarray as xr

from stochpound.experiment.model import CASE, REFERENCE, Case, Dim, Experiment
from stochpound.experiment.spec import ExperimentError
from stochpound.experiment.summary import IMPACT_COLUMNS, templates, variable_attrs
from stochpound.results.dataset import write_dataset

#: Version of the store layout.
STORE_FORMAT = 1
_INT_FILL = -1
_STATUS_ATTRS = {
    "units": "1",
    "flag_values": np.array([-1, 0, 1], dtype=np.int8),
    "flag_meanings": "not_in_grid missing done",
}


def build_store(
    experiment: Experiment,
    results: Mapping[str, Mapping[str, np.ndarray]],
    motion_grids: Mapping[str, tuple[float, int]],
    attrs: Mapping[str, Any],
) -> xr.Dataset:
    """Assemble the store dataset from the finished cases.

    Parameters
    ----------
    experiment : Experiment
    results : mapping
        Part arrays of the finished cases, by case id (unknown ids are ignored).
    motion_grids : mapping
        (dt in s, number of samples) of each motion, by label (for ``time``).
    attrs : mapping
        Provenance attributes.

    Returns
    -------
    xarray.Dataset
    """
    coords = _coordinates(experiment, motion_grids)
    case_dims = [d.name for d in experiment.dims]
    reference_dims = [d.name for d in experiment.reference_dims]
    _, summary_template, reference_template = templates()
    cases = {CASE: [c for c in experiment.cases if c.kind == CASE], REFERENCE: [c for c in experiment.cases if c.kind == REFERENCE]}
    variables: dict[str, xr.Variable] = {}
    for kind, dims, template, prefix in ((CASE, case_dims, summary_template, "case"), (REFERENCE, reference_dims, reference_template, "reference")):
        done = [c for c in cases[kind] if c.case_id in results]
        variables.update(_status(prefix, dims, coords, cases[kind], results))
        for name, variable in template.data_vars.items():
            variables[name] = _grid_variable(name, dims + list(variable.dims), coords, done, results, f"s:{name}", variable.dtype)
    variables.update(_time_histories(experiment, case_dims, reference_dims, coords, cases, results))
    if experiment.output["impacts"]:
        variables.update(_impact_table(experiment, cases[CASE], results))
    n_total = len(experiment.cases)
    n_done = sum(1 for c in experiment.cases if c.case_id in results)
    dataset = xr.Dataset(variables, coords=coords)
    dataset = dataset.set_coords([name for name in variables if name == "impact_case_id" or name.startswith("impact_") and name[7:] in case_dims])
    dataset.attrs.update(
        {
            "title": f"stochpound experiment {experiment.name}",
            "Conventions": "CF-1.10",
            "stochpound_store_format": STORE_FORMAT,
            **attrs,
            "cases_total": n_total,
            "cases_done": n_done,
            "complete": int(n_done == n_total),
        }
    )
    return dataset


def _coordinates(experiment: Experiment, motion_grids: Mapping[str, tuple[float, int]]) -> dict[str, xr.Variable]:
    coords: dict[str, xr.Variable] = {}
    for dim in experiment.dims:
        coords[dim.name] = _dim_coordinate(experiment, dim)
    motions = experiment.motions
    coords["record_kind"] = xr.Variable(("record",), np.array([motions[m]["kind"] for m in motions], dtype=object), {"units": "1", "long_name": "record or synthetic ensemble"})
    coords["record_motion"] = xr.Variable(
        ("record",), np.array([_describe_motion(motions[m]["motion"]) for m in motions], dtype=object), {"units": "1", "long_name": "the motion's scene table (JSON)"}
    )
    scene = experiment.definition["scene"]
    coords["building"] = xr.Variable(("building",), np.array(experiment.building_names, dtype=object), {"units": "1", "long_name": "building name, left to right"})
    coords["floor"] = xr.Variable(("floor",), np.arange(1, experiment.max_floors + 1), {"units": "1", "long_name": "floor number, 1 = lowest"})
    coords["contact"] = xr.Variable(("contact",), np.arange(len(scene.get("contact", []))), {"units": "1", "long_name": "contact index"})
    if experiment.output["time_histories"]:
        coords["time"] = xr.Variable(("time",), union_times(motion_grids), {"units": "s", "long_name": "time (union of the motions' sample times)"})
    return coords


def _dim_coordinate(experiment: Experiment, dim: Dim) -> xr.Variable:
    if dim.kind == "variant":
        return xr.Variable((dim.name,), np.array(dim.values, dtype=object), {"units": "1", "long_name": f"variant of axis {dim.name}"})
    if dim.kind == "gap":
        gap = next(g for g in experiment.definition["gaps"] if g["name"] == dim.name)
        return xr.Variable((dim.name,), np.array(dim.values, float), {"units": "m", "long_name": f"at-rest gap of contacts {gap['contacts']}"})
    if dim.kind == "mu":
        chosen = experiment.definition["mu"]["buildings"]
        which = ", ".join(chosen) if chosen else "every isolated building"
        return xr.Variable(("mu",), np.array(dim.values, float), {"units": "1", "long_name": f"friction coefficient of {which} (inf: fixed base)"})
    if dim.kind == "record":
        return xr.Variable(("record",), np.array(dim.values, dtype=object), {"units": "1", "long_name": "ground motion (record or synthetic ensemble)"})
    return xr.Variable(("realization",), np.array(dim.values, dtype=np.int64), {"units": "1", "long_name": "realization index (0 for a record)"})


def _describe_motion(table: Mapping[str, Any]) -> str:
    from stochpound.experiment.spec import canonical_json

    return canonical_json(table)


def union_times(motion_grids: Mapping[str, tuple[float, int]]) -> np.ndarray:
    """Sorted union of every motion's sample times k·dt (rounded to 1e-9 s)."""
    times = [np.round(np.arange(int(n)) * float(dt), 9) for dt, n in motion_grids.values()]
    return np.unique(np.concatenate(times)) if times else np.zeros(0)


def _shape(dims: list[str], coords: Mapping[str, xr.Variable]) -> tuple[int, ...]:
    return tuple(coords[d].size for d in dims)


def _status(prefix: str, dims: list[str], coords: Mapping[str, xr.Variable], cases: list[Case], results: Mapping[str, Any]) -> dict[str, xr.Variable]:
    shape = _shape(dims, coords)
    status = np.full(shape, -1, dtype=np.int8)
    ids = np.full(shape, "", dtype=object)
    for case in cases:
        status[case.position] = 1 if case.case_id in results else 0
        ids[case.position] = case.case_id
    long = "case" if prefix == "case" else "fixed-base reference case"
    return {
        f"{prefix}_status": xr.Variable(dims, status, {**_STATUS_ATTRS, "long_name": f"{long} status"}),
        f"{prefix}_id": xr.Variable(dims, ids, {"units": "1", "long_name": f"{long} id (parts file name)"}),
    }


def _fill_value(dtype: np.dtype) -> Any:
    return np.nan if np.issubdtype(dtype, np.floating) else _INT_FILL


def _store_dtype(dtype: np.dtype) -> np.dtype:
    if np.issubdtype(dtype, np.bool_):
        return np.dtype(np.int8)
    if np.issubdtype(dtype, np.integer):
        return np.dtype(np.int64)
    return np.dtype(np.float64)


def _grid_variable(name: str, dims: list[str], coords: Mapping[str, xr.Variable], cases: list[Case], results: Mapping[str, Any], key: str, dtype: np.dtype) -> xr.Variable:
    dtype = _store_dtype(dtype)
    data = np.full(_shape(dims, coords), _fill_value(dtype), dtype=dtype)
    for case in cases:
        value = results[case.case_id].get(key)
        if value is not None:
            data[case.position + tuple(slice(0, n) for n in np.shape(value))] = value
    encoding = {} if np.issubdtype(dtype, np.floating) else {"_FillValue": _INT_FILL}
    variable = xr.Variable(dims, data, dict(variable_attrs(name)))
    variable.encoding.update(encoding)
    return variable


def _time_histories(
    experiment: Experiment, case_dims: list[str], reference_dims: list[str], coords: Mapping[str, xr.Variable], cases: Mapping[str, list[Case]], results: Mapping[str, Any]
) -> dict[str, xr.Variable]:
    names = experiment.output["time_histories"]
    if not names:
        return {}
    run, _, _ = templates()
    union = coords["time"].values
    kept = [experiment.building_names.index(b) for b in experiment.output["buildings"]]
    variables = {}
    jobs = [(name, case_dims, [d for d in run[name].dims if d != "time"], cases[CASE]) for name in names]
    if "total_displacement" in names:
        jobs.append(("reference_total_displacement", reference_dims, ["floor"], cases[REFERENCE]))
    for name, dims, extra, kind_cases in jobs:
        all_dims = dims + extra + ["time"]
        data = np.full(_shape(all_dims, coords), np.nan)
        for case in kind_cases:
            arrays = results.get(case.case_id)
            if arrays is None or f"t:{name}" not in arrays:
                continue
            columns = np.searchsorted(union, np.round(arrays["t:time"], 9))
            values, view = arrays[f"t:{name}"], data[case.position]
            rows = list(enumerate(kept)) if "building" in extra else [(None, None)]
            for j, row in rows:
                source = values if j is None else values[j]
                target = view if row is None else view[row]
                target[tuple(slice(0, n) for n in source.shape[:-1]) + (columns,)] = source
        variable = xr.Variable(all_dims, data, dict(variable_attrs(name)))
        variable.encoding.update({"zlib": True, "complevel": 1})
        variables[name] = variable
    return variables


def _impact_table(experiment: Experiment, cases: list[Case], results: Mapping[str, Any]) -> dict[str, xr.Variable]:
    run, _, _ = templates()
    columns: dict[str, list[np.ndarray]] = {name: [] for name in IMPACT_COLUMNS}
    owners: list[Case] = []
    for case in cases:
        arrays = results.get(case.case_id)
        if arrays is None or "i:impact_start" not in arrays:
            continue
        count = len(arrays["i:impact_start"])
        owners.extend([case] * count)
        for name in IMPACT_COLUMNS:
            columns[name].append(arrays[f"i:{name}"])
    variables = {}
    for name in IMPACT_COLUMNS:
        dtype = run[name].dtype
        data = np.concatenate(columns[name]).astype(dtype) if columns[name] else np.zeros(0, dtype)
        variables[name] = xr.Variable(("impact",), data, dict(variable_attrs(name)))
    variables["impact_case_id"] = xr.Variable(("impact",), np.array([c.case_id for c in owners], dtype=object), {"units": "1", "long_name": "id of the case of the impact"})
    for position, dim in enumerate(experiment.dims):
        values = np.array([c.labels[position][1] for c in owners], dtype=_coordinate_dtype(dim))
        units = _dim_coordinate(experiment, dim).attrs["units"]
        variables[f"impact_{dim.name}"] = xr.Variable(("impact",), values, {"units": units, "long_name": f"{dim.name} of the case of the impact"})
    return variables


def _coordinate_dtype(dim: Dim) -> Any:
    return {"variant": object, "record": object, "realization": np.int64}.get(dim.kind, float)


def write_store(dataset: xr.Dataset, path: str | Path) -> Path:
    """Write the store atomically (temporary file renamed into place)."""
    return write_dataset(dataset, path)


def open_store(path: str | Path, chunks: Any = None) -> xr.Dataset:
    """Open an experiment store lazily (dask-chunked).

    Parameters
    ----------
    path : str or Path
        The store file written by ``stochpound experiment run``.
    chunks : optional
        Dask chunks (default ``{}``: the file's own chunking).

    Returns
    -------
    xarray.Dataset
        Summaries on the grid's dimensions, time histories, the impact table
        and the provenance attributes; nothing is loaded until computed.

    Raises
    ------
    ExperimentError
        If the file is missing or not an experiment store.
    """
    path = Path(path)
    if not path.is_file():
        raise ExperimentError(f"{path}: store not found")
    try:
        dataset = xr.open_dataset(path, engine="h5netcdf", chunks={} if chunks is None else chunks)
    except (OSError, ValueError) as error:
        raise ExperimentError(f"{path}: not a readable netCDF4/HDF5 file ({error})") from None
    if "definition_sha256" not in dataset.attrs:
        dataset.close()
        raise ExperimentError(f"{path}: not a stochpound experiment store (no definition_sha256 attribute)")
    return dataset
