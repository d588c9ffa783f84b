"""The experiment store's layout: one netCDF4/HDF5 file, its dimensions, variables and chunks.

Layout (docs/experiments.md):

* coordinates: the grid's dimensions (variant axes, ``gap``…, ``mu``), the
  motion's (``record``, ``realization``), ``building``, ``floor``, ``contact``
  and, with time histories, ``time`` (the union of the motions' sample times);
* ``case_status`` (−1 not in the grid, 0 missing, 1 done) and ``case_id`` on
  the case dimensions, ``reference_status``/``reference_id`` likewise;
* per-case summaries on the case dimensions (plus ``building``), the
  fixed-base reference's ``reference_*`` summaries on the reference dimensions;
* kept time histories on the case dimensions plus their own and ``time``;
* the impact table on dimension ``impact``, with the case's coordinates
  (``impact_case_id``, ``impact_<dim>``);
* provenance attributes.

Every variable on the case dimensions is chunked in *blocks* of consecutive
grid positions (:func:`blocks`): along ``realization`` for an ensemble, so
that the file opens lazily chunked along realization and is written, block by
block, in time and memory independent of the number of cases
(:mod:`stochpound.experiment._file_assembly`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator, Mapping

import numpy as np
import xarray as xr

from stochpound.store import CASE_SUMMARIES, IMPACT_TABLE, REFERENCE_HISTORY, REFERENCE_SUMMARIES, SETS, STOREY_SUMMARIES, StoreVariable, TIME_HISTORIES, WALL_SUMMARIES, canonical_json
from stochpound.experiment import _intensity as intensity
from stochpound.experiment._experiment import Experiment
from stochpound.store import CASE, REFERENCE, Dim, MotionTable, TomlTable
from stochpound.experiment._summary import DEMAND_SUMMARIES
from stochpound.model.scene_file import scene_from_dict
from stochpound.motions.records import METADATA_FIELDS
from stochpound.results.dataset import scene_parameters

#: Version of the store layout.
STORE_FORMAT = 1
INT_FILL = -1
"""On-disk fill value of integer variables (decoded to NaN by xarray)."""
SUMMARY_BLOCK = 65536
"""Largest number of grid positions in a block of the summaries (and chunk of the file)."""
HISTORY_BLOCK_BYTES = 4 * 2**20
"""Largest size of a block (and chunk) of a time-history variable, bytes."""
IMPACT_CHUNK = 262144
"""Rows per chunk of the impact table."""
_STATUS_ATTRS = {
    "units": "1",
    "flag_values": np.array([-1, 0, 1], dtype=np.int8),
    "flag_meanings": "not_in_grid missing done",
}
PREFIX = {CASE: "case", REFERENCE: "reference"}
"""Name prefix of the status and id variables of each kind."""


@dataclass(frozen=True)
class Spec:
    """One variable of the store.

    Attributes
    ----------
    name : str
    kind : str or None
        The kind of case of a grid variable (None for the impact table).
    family : str
        ``status``, ``id``, ``summary``, ``history`` or ``impact`` (the table's
        columns, their case id and labels).
    dims : tuple of str
    dtype : numpy dtype
        In memory (bool is stored as int8 with ``dtype = "bool"``, ``<U1``
        stands for variable-length strings).
    attrs : mapping of str to str or np.ndarray
        The variable's attributes (units, long name, flags).
    chunks : tuple of int
        Chunk shape in the file (a block of the grid, whole trailing dimensions).
    encoding : mapping of str to int or bool
        Further encoding (``_FillValue`` of integers, compression).
    coordinate : bool
        A coordinate (the impact table's case id and labels).
    """

    name: str
    kind: str | None
    family: str
    dims: tuple[str, ...]
    dtype: np.dtype
    attrs: Mapping[str, str | np.ndarray]
    chunks: tuple[int, ...]
    encoding: Mapping[str, int | bool] = field(default_factory=dict)
    coordinate: bool = False


StoreAttributes = Mapping[str, str | int | float]
"""A store's global attributes, as netCDF keeps them (text and numbers): its provenance (the definition and its identity,
the experiment file, the code, the solver's settings) and its progress."""


@dataclass(frozen=True)
class Layout:
    """Coordinates, dimension sizes and variables of an experiment's store."""

    coords: dict[str, xr.Variable]
    sizes: dict[str, int]
    specs: list[Spec]

    def of(self, family: str, kind: str | None = None) -> list[Spec]:
        """The variables of a family (and kind)."""
        return [s for s in self.specs if s.family == family and (kind is None or s.kind == kind)]

    def template(self, attrs: StoreAttributes) -> xr.Dataset:
        """The store as a dataset whose variables are lazy placeholders (dask), the file's encoding in ``encoding``."""
        import dask.array as da

        variables = {}
        for spec in self.specs:
            shape = tuple(self.sizes[d] for d in spec.dims)
            placeholder = da.empty(shape, dtype=spec.dtype, chunks=spec.chunks, name=f"placeholder-{spec.name}")  # named: no tokenizing
            variable = xr.Variable(spec.dims, placeholder, dict(spec.attrs))
            variable.encoding = {"chunksizes": spec.chunks, **spec.encoding}
            variables[spec.name] = variable
        dataset = xr.Dataset(variables, coords=self.coords, attrs=dict(attrs))
        return dataset.set_coords([s.name for s in self.specs if s.coordinate])


def layout(experiment: Experiment, motion_grids: Mapping[str, tuple[float, int]], n_impacts: int) -> Layout:
    """The layout of an experiment's store holding ``n_impacts`` impact rows."""
    coords = _coordinates(experiment, motion_grids)
    sizes = {name: v.size for name, v in coords.items() if v.dims == (name,)}
    specs: list[Spec] = []
    case_summaries = CASE_SUMMARIES + (WALL_SUMMARIES if experiment.has_walls else ()) + (STOREY_SUMMARIES if experiment.has_storey_summaries else ())
    for kind, variables in ((REFERENCE, REFERENCE_SUMMARIES), (CASE, case_summaries)):
        dims = tuple(d.name for d in experiment.kind_dims(kind))
        grid = tuple(sizes[d] for d in dims)
        chunks = block_shape(grid, SUMMARY_BLOCK)
        prefix = PREFIX[kind]
        long = "case" if kind == CASE else "fixed-base reference case"
        specs.append(Spec(f"{prefix}_status", kind, "status", dims, np.dtype(np.int8), {**_STATUS_ATTRS, "long_name": f"{long} status"}, chunks))
        specs.append(Spec(f"{prefix}_id", kind, "id", dims, np.dtype("<U1"), {"units": "1", "long_name": f"{long} id"}, chunks))
        for variable in variables:
            if variable.name in DEMAND_SUMMARIES and not experiment.output.demands:
                continue
            if any(sizes[d] == 0 for d in variable.dims):  # e.g. per-contact summaries of a scene without contacts
                continue
            dtype = _store_dtype(np.dtype(variable.dtype))
            encoding = {} if dtype.kind == "f" else {"_FillValue": INT_FILL}
            specs.append(Spec(variable.name, kind, "summary", dims + variable.dims, dtype, variable.attrs, chunks + tuple(sizes[d] for d in variable.dims), encoding))
    specs += _intensity_specs(experiment, sizes)
    specs += _history_specs(experiment, sizes)
    if experiment.output.impacts:
        specs += _impact_specs(experiment, max(n_impacts, 0))
    return Layout(coords, {**sizes, "impact": n_impacts}, specs)


def _intensity_specs(experiment: Experiment, sizes: Mapping[str, int]) -> list[Spec]:
    """The per-case intensity variables (:mod:`stochpound.experiment._intensity`), on the case dimensions."""
    dims = tuple(d.name for d in experiment.kind_dims(CASE))
    chunks = block_shape(tuple(sizes[d] for d in dims), SUMMARY_BLOCK)
    specs = []
    for name in intensity.store_names(experiment.intensity):
        extra = ("spectrum_period",) if name == "motion_psa" else ()
        attrs = intensity.summary_attrs(experiment.intensity, name)
        specs.append(Spec(name, CASE, "summary", dims + extra, np.dtype(float), attrs, chunks + tuple(sizes[d] for d in extra)))
    return specs


def _history_specs(experiment: Experiment, sizes: Mapping[str, int]) -> list[Spec]:
    names = experiment.output.time_histories
    jobs: list[tuple[StoreVariable, str]] = [(TIME_HISTORIES[name], CASE) for name in names]
    if "total_displacement" in names:
        jobs.append((REFERENCE_HISTORY, REFERENCE))
    specs = []
    for variable, kind in jobs:
        dims = tuple(d.name for d in experiment.kind_dims(kind))
        trailing = tuple(sizes[d] for d in variable.dims) + (sizes["time"],)
        per_case = 8 * math.prod(trailing)
        grid = block_shape(tuple(sizes[d] for d in dims), max(1, HISTORY_BLOCK_BYTES // per_case))
        encoding = {"zlib": True, "complevel": 1}
        specs.append(Spec(variable.name, kind, "history", dims + variable.dims + ("time",), np.dtype(float), variable.attrs, grid + trailing, encoding))
    return specs


def _impact_specs(experiment: Experiment, n_impacts: int) -> list[Spec]:
    chunks = (max(1, min(IMPACT_CHUNK, n_impacts)),)
    specs = [Spec(v.name, None, "impact", v.dims, np.dtype(v.dtype), v.attrs, chunks) for v in IMPACT_TABLE]
    specs.append(Spec("impact_case_id", None, "impact", ("impact",), np.dtype("<U1"), {"units": "1", "long_name": "id of the case of the impact"}, chunks, coordinate=True))
    for dim in experiment.dims:
        units = _dim_coordinate(experiment, dim).attrs["units"]
        dtype = np.dtype("<U1") if dim.kind in ("variant", "record") else np.dtype(np.int64) if dim.kind == "realization" else np.dtype(float)
        specs.append(Spec(f"impact_{dim.name}", None, "impact", ("impact",), dtype, {"units": units, "long_name": f"{dim.name} of the case of the impact"}, chunks, coordinate=True))
    return specs


def block_shape(shape: tuple[int, ...], target: int) -> tuple[int, ...]:
    """Shape of the blocks (and chunks) of a grid: whole trailing dimensions, at most ``target`` positions.

    The trailing dimensions that fit whole are kept whole; the dimension
    before them is split in runs of consecutive indices; the leading ones
    have length 1. A block is a hyperslab of consecutive positions in C order.
    """
    block = [1] * len(shape)
    room = max(1, target)
    for axis in range(len(shape) - 1, -1, -1):
        if shape[axis] <= room:
            block[axis] = shape[axis]
            room //= max(1, shape[axis])
        else:
            block[axis] = room
            break
    return tuple(max(1, b) for b in block)


def blocks(shape: tuple[int, ...], block: tuple[int, ...]) -> Iterator[tuple[slice, ...]]:
    """The blocks of a grid, in C order, as tuples of slices."""
    ranges = [range(0, n, b) for n, b in zip(shape, block)]
    for starts in itertools.product(*ranges):
        yield tuple(slice(s, min(s + b, n)) for s, b, n in zip(starts, block, shape))


def record_motions(experiment: Experiment) -> list[str]:
    """Each motion's scene table as the store's ``record_motion`` holds it (canonical JSON), in the ``record`` order."""
    return [canonical_json(motion.motion) for motion in experiment.motions.values()]


def _coordinates(experiment: Experiment, motion_grids: Mapping[str, tuple[float, int]]) -> dict[str, xr.Variable]:
    coords: dict[str, xr.Variable] = {}
    for dim in experiment.dims:
        coords[dim.name] = _dim_coordinate(experiment, dim)
    motions = experiment.motions
    coords["record_kind"] = xr.Variable(("record",), np.array([motions[m].kind for m in motions], dtype=object), {"units": "1", "long_name": "record or synthetic ensemble"})
    coords["record_motion"] = xr.Variable(("record",), np.array(record_motions(experiment), dtype=object), {"units": "1", "long_name": "the motion's scene table (JSON)"})
    coords.update(_suite_coordinates(experiment))
    if experiment.selection is not None:
        coords.update(experiment.selection.coordinates())
    if experiment.intensity is not None:
        coords["spectrum_period"] = xr.Variable(
            ("spectrum_period",), intensity.SPECTRUM_PERIODS, {"units": "s", "long_name": "period of the stored spectra (5 % damping)"}
        )
    scene = experiment.definition.scene
    coords["building"] = xr.Variable(("building",), np.array(experiment.building_names, dtype=object), {"units": "1", "long_name": "building name, left to right"})
    coords["floor"] = xr.Variable(("floor",), np.arange(1, experiment.max_floors + 1), {"units": "1", "long_name": "floor number, 1 = lowest"})
    coords["contact"] = xr.Variable(("contact",), np.arange(len(TomlTable(scene, "scene").tables("contact"))), {"units": "1", "long_name": "contact index"})
    coords.update(_scene_coordinates(experiment))
    if experiment.output.time_histories:
        coords["time"] = xr.Variable(("time",), union_times(motion_grids), {"units": "s", "long_name": "time (union of the motions' sample times)"})
    return coords


def _scene_coordinates(experiment: Experiment) -> dict[str, xr.Variable]:
    """What each grid point ran, as a result names it (:func:`stochpound.results.dataset.scene_parameters`): the bases and the contacts' laws.

    On the case dimensions without ``record`` and ``realization``, then ``building`` or ``contact``
    (walls, whose number a variant may change, are left out: the definition gives them).
    """
    points = experiment.points(CASE)
    dims = tuple(d.name for d in experiment.kind_dims(CASE)[:-2])
    shape = experiment.grid_shape(CASE)[:-2]
    columns: dict[str, list[np.ndarray]] = {}
    attrs: dict[str, tuple[tuple[str, ...], dict[str, str]]] = {}
    for point in points:
        scene = scene_from_dict(experiment.structure(point), base_dir=experiment.base_dir)
        for name, (variable_dims, values, variable_attrs) in scene_parameters(scene).items():
            if variable_dims in (("building",), ("contact",)):
                columns.setdefault(name, []).append(np.asarray(values))
                attrs[name] = (variable_dims, variable_attrs)
    coords = {}
    for name, values in columns.items():
        variable_dims, variable_attrs = attrs[name]
        data = np.stack(values).reshape(shape + values[0].shape)
        coords[name] = xr.Variable(dims + variable_dims, data.astype(object) if data.dtype.kind == "U" else data, variable_attrs)
    return coords


def _suite_coordinates(experiment: Experiment) -> dict[str, xr.Variable]:
    """Metadata of the motions from suites on ``record`` (event, station, component, magnitude, distance...; none without such motions)."""
    from stochpound.motions.records import is_suite_member, load_suite_member, record_metadata

    rows: list[Mapping[str, float | str]] = []
    for source in experiment.motions.values():
        record = MotionTable.of_source(source).record or ""
        peer = record_metadata(record, experiment.base_dir) if source.kind == "record" and record and not is_suite_member(record) else {}
        if is_suite_member(record):
            rows.append(load_suite_member(record).metadata)
        elif source.kind == "simulated":  # its own earthquake: no event (a cluster of its own), the scenario's magnitude, distance and Vs30
            table = source.motion
            rows.append({"suite": "simulated", "magnitude": table["magnitude"], "distance": table["distance_km"], "vs30": table["vs30"]})
        elif "event" in peer:  # a file of a PEER download: its row of the search report
            rows.append({**peer, "suite": source.suite or str(Path(record).parent)})
        elif source.suite is not None:  # a folder without a search report: the file name is all that is known
            rows.append({"suite": source.suite, "component": Path(record).name})
        else:
            rows.append({})
    if not any(rows):
        return {}
    coords = {"record_suite": xr.Variable(("record",), np.array([str(m.get("suite", "")) for m in rows], dtype=object), {"units": "1", "long_name": "suite of the motion"})}
    for name, units in METADATA_FIELDS.items():
        values = [m.get(name, "" if name in _TEXT_FIELDS else np.nan) for m in rows]
        if name in _TEXT_FIELDS:
            coords[f"record_{name}"] = xr.Variable(("record",), np.array([str(v) for v in values], dtype=object), {"units": "1", "long_name": f"{name} of the motion"})
        else:
            coords[f"record_{name}"] = xr.Variable(("record",), np.array(values, dtype=float), {"units": units or "1", "long_name": f"{name} of the motion"})
    return coords


_TEXT_FIELDS = ("event", "station", "component")


def _dim_coordinate(experiment: Experiment, dim: Dim) -> xr.Variable:
    if dim.kind == "variant":
        return xr.Variable((dim.name,), np.array(dim.values, dtype=object), {"units": "1", "long_name": f"variant of axis {dim.name}"})
    if dim.kind == "gap":
        gap = experiment.definition.gap_axis(dim.name)
        walls = f" and walls {list(gap.walls)}" if gap.walls else ""
        sets = " and ".join(what for what, indices in (("contacts", gap.contacts), ("walls", gap.walls)) if indices)
        return xr.Variable((dim.name,), np.array(dim.values, float), {"units": "m", "long_name": f"at-rest gap of contacts {list(gap.contacts)}{walls}", SETS: sets})
    if dim.kind == "mu":
        chosen = experiment.definition.mu.buildings
        which = ", ".join(chosen) if chosen else "every isolated building"
        return xr.Variable(("mu",), np.array(dim.values, float), {"units": "1", "long_name": f"friction coefficient of {which} (inf: fixed base)"})
    if dim.kind == "record":
        return xr.Variable(("record",), np.array(dim.values, dtype=object), {"units": "1", "long_name": "ground motion (record or synthetic ensemble)"})
    if dim.kind == "intensity":
        setting = experiment.intensity
        return xr.Variable(("intensity",), np.array(dim.values, float), {"units": setting.units, "long_name": f"target intensity level, {setting.description}"})
    return xr.Variable(("realization",), np.array(dim.values, dtype=np.int64), {"units": "1", "long_name": "realization index (0 for a record)"})


def union_times(motion_grids: Mapping[str, tuple[float, int]]) -> np.ndarray:
    """Sorted union of every motion's sample times k·dt (rounded to 1e-9 s)."""
    times = [np.round(np.arange(int(n)) * float(dt), 9) for dt, n in motion_grids.values()]
    return np.unique(np.concatenate(times)) if times else np.zeros(0)


def _store_dtype(dtype: np.dtype) -> np.dtype:
    if np.issubdtype(dtype, np.bool_):
        return np.dtype(np.int8)
    if np.issubdtype(dtype, np.integer):
        return np.dtype(np.int64)
    return np.dtype(np.float64)
