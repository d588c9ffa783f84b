"""Writing the store file from the parts, block by block.

The file is created with every variable's metadata and chunking
(:meth:`stochpound.experiment._file_layout.Layout.template`, written by xarray's
netCDF4 back end, the netCDF C library, so that xarray and netCDF tools read it
as any xarray-written file; 4-5 times faster than through h5netcdf, whose
Python layer looks every dimension up again for each variable) but no data; then each block of the grid (:func:`stochpound.experiment._file_layout.blocks`)
is assembled in memory from the parts that hold its cases and written as
one hyperslab per variable. The impact table's rows follow the cases in
grid order, whatever the order in which the parts were written. Memory is
bounded by a block and a few parts, time is linear in the store's size, and
the result does not depend on how the cases were split into parts.

The file is written to a temporary name and renamed over the store
(:mod:`stochpound._atomic`): a reader sees the old file or the new one.
"""

from __future__ import annotations

import io
import json
import math
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import h5py
import netCDF4
import numpy as np
from xarray.backends import NetCDF4DataStore

from stochpound._atomic import check_room, free_bytes, replacing
from stochpound.experiment._experiment import Experiment
from stochpound.store import CASE, KINDS
from stochpound.experiment._parts import part_paths, read_part, split_key
from stochpound.experiment._spec import ExperimentError
from stochpound.experiment._file_layout import INT_FILL, Layout, Spec, StoreAttributes, blocks, layout, union_times

PART_CACHE_BYTES = 64 * 2**20
"""Parts kept in memory while the blocks that need them are written, bytes."""
_CHUNK_CACHE_BYTES = 16 * 2**20
ROOM_FACTOR = 1.1
"""Free room checked before a store file is written: this many times its size (:func:`file_bytes`) ..."""
ROOM_MARGIN = 2**20
"""... and this many bytes more."""
_ID_CHARACTERS = 16
"""Characters of a case id (the strings :func:`file_bytes` writes)."""
_STRING_BYTES = 64
"""Bytes of a variable-length string of up to 32 characters: its 16-byte reference and its global-heap object."""
_HEAP_BYTES = 4096
"""Least size of the global-heap collection HDF5 allocates for the strings of each chunk written, bytes."""
_OBJECT_BYTES = 16 * 2**10
"""Bound of a variable's metadata (its header, attributes and first chunk-index node: 1.4 to 2 KiB and 2 to 5 KiB measured), bytes."""
_INDEX_NODE_CHUNKS = 64
"""Chunks per node of a variable's chunk index (HDF5's version-1 B-tree, 2K entries, K = 32 by default) ..."""
_INDEX_NODE_BYTES = 5 * 2**10
"""... and the size of a node, bytes (4.7 KiB for six dimensions)."""
_MEMORY_HINT = 2**20
"""Initial size of the in-memory file :func:`file_bytes` writes the metadata into, bytes (it grows as needed)."""


@dataclass
class PartsIndex:
    """Which part holds each finished case.

    Attributes
    ----------
    sections : list of (Path, str)
        Every section of every readable part: (part file, ``<kind>.<record>``).
    source : dict[str, numpy.ndarray]
        For each kind, an int array of its grid's shape: the index in
        ``sections`` of the section holding the case, −1 if none (the first
        part, by name, wins if two hold the same case).
    impacts : np.ndarray
        Number of impacts of each finished case (the case grid's shape).
    unreadable : list of Path
        Parts that could not be read (they count as missing).
    """

    sections: list[tuple[Path, str]]
    source: dict[str, np.ndarray]
    impacts: np.ndarray
    unreadable: list[Path]

    @classmethod
    def scan(cls, experiment: Experiment, folder: Path) -> "PartsIndex":
        """Read the positions (and impact counts) of every part in ``folder``."""
        source = {kind: np.full(experiment.grid_shape(kind), -1, dtype=np.int32) for kind in KINDS}
        impacts = np.zeros(experiment.grid_shape(CASE), dtype=np.int64)
        sections: list[tuple[Path, str]] = []
        unreadable = []
        for path in part_paths(folder):
            arrays = read_part(path, ("position", "i:count"))
            found = _sections(experiment, arrays) if arrays is not None else None
            if found is None:
                unreadable.append(path)
                continue
            for prefix, (kind, positions) in found.items():
                index = tuple(positions.T)
                new = source[kind][index] < 0
                source[kind][tuple(positions[new].T)] = len(sections)
                if kind == CASE and f"{prefix}/i:count" in arrays:
                    impacts[tuple(positions[new].T)] = arrays[f"{prefix}/i:count"][new]
                sections.append((path, prefix))
        return cls(sections, source, impacts, unreadable)

    def done(self, kind: str) -> np.ndarray:
        """Which cases of ``kind`` are finished (bool, the grid's shape)."""
        return self.source[kind] >= 0

    @property
    def n_done(self) -> int:
        """Number of finished cases."""
        return sum(int(self.done(kind).sum()) for kind in KINDS)


def _sections(experiment: Experiment, arrays: dict[str, np.ndarray]) -> dict[str, tuple[str, np.ndarray]] | None:
    """The sections of a part: prefix -> (kind, positions); None if any position is not a case of the grid."""
    found = {}
    for key, positions in arrays.items():
        kind, record, name = split_key(key)
        if name != "position":
            continue
        shape = experiment.grid_shape(kind) if kind in KINDS else ()
        if kind not in KINDS or positions.ndim != 2 or positions.shape[1] != len(shape) or positions.size and (
            (positions < 0).any() or (positions >= shape).any() or not experiment.in_grid(kind)[tuple(positions.T)].all()
        ):
            return None
        found[key[: -len("/position")]] = (kind, positions)
    return found


def write_store(experiment: Experiment, index: PartsIndex, motion_grids: Mapping[str, tuple[float, int]], attrs: StoreAttributes, path: Path) -> Path:
    """(Re)write the store file from the finished cases of ``index``, atomically.

    Parameters
    ----------
    experiment : Experiment
    index : PartsIndex
        The parts to read (:meth:`PartsIndex.scan`).
    motion_grids : mapping
        (dt in s, number of samples) of each motion, by label (for ``time``).
    attrs : mapping
        Provenance attributes (``cases_total``, ``cases_done`` and ``complete`` are added).
    path : Path
        The store file.
    """
    store_layout = layout(experiment, motion_grids, int(index.impacts.sum()))
    n_done = index.n_done
    attrs = {
        "title": f"stochpound experiment {experiment.name}",
        "Conventions": "CF-1.10",
        "stochpound_store_format": 1,
        **attrs,
        "cases_total": experiment.n_cases,
        "cases_done": n_done,
        "complete": int(n_done == experiment.n_cases),
    }
    _check_room(path, store_layout, attrs)
    with replacing(path) as temporary:
        _create(store_layout, attrs, temporary)
        with h5py.File(temporary, "r+", rdcc_nbytes=_CHUNK_CACHE_BYTES) as handle:
            writer = _Writer(experiment, store_layout, index, handle, union_times(motion_grids))
            for kind in KINDS:
                writer.grid(kind)
            for spec in store_layout.of("history"):
                writer.history(spec)
    return path


def _check_room(path: Path, store_layout: Layout, attrs: StoreAttributes) -> None:
    """Raise ``OSError(ENOSPC)`` naming ``path`` unless its disk has room for the file, with a margin (:data:`ROOM_FACTOR`, :data:`ROOM_MARGIN`).

    HDF5 may crash the process when the disk fills while it writes (a
    segfault closing the file), so the room is checked before. The file's
    size is measured (:func:`file_bytes`, half a second) only when the free
    room is below a quick upper bound of it (:data:`_OBJECT_BYTES` per variable).
    """
    free = free_bytes(path)
    if free is None:
        return
    quick = sum(math.prod(count) * per_chunk for count, per_chunk in (_chunks(tuple(store_layout.sizes[d] for d in spec.dims), spec.chunks, spec.dtype)
                                                                       for spec in store_layout.specs))
    quick += sum(v.nbytes for v in store_layout.coords.values()) + _OBJECT_BYTES * (len(store_layout.specs) + len(store_layout.coords))
    quick += 4 * len(json.dumps(dict(attrs), default=str))
    if free >= ROOM_FACTOR * quick + ROOM_MARGIN:
        return
    old = path.stat().st_size if path.is_file() else 0
    check_room(path, max(old, int(ROOM_FACTOR * file_bytes(store_layout, attrs)) + ROOM_MARGIN))


def _chunks(shape: tuple[int, ...], chunks: tuple[int, ...] | None, dtype: np.dtype) -> tuple[tuple[int, ...], int]:
    """The chunks of a variable along each dimension, and the bytes of one (strings: :data:`_STRING_BYTES` each and a heap)."""
    strings = dtype.kind in "OU"
    chunks = chunks or shape
    per_chunk = math.prod(chunks) * (_STRING_BYTES if strings else dtype.itemsize) + strings * _HEAP_BYTES
    return tuple(math.ceil(n / c) if c else 0 for n, c in zip(shape, chunks)), per_chunk


def file_bytes(store_layout: Layout, attrs: StoreAttributes) -> int:
    """The size of the store file :func:`write_store` writes for ``store_layout``, bytes, measured on an in-memory file.

    The file's metadata is written as :func:`write_store` writes it, in
    memory (the netCDF library's in-memory file, nothing on disk), then,
    opened by h5py from that image, one element of every
    variable, which allocates its chunk index and its first chunk; the
    other chunks are counted at their uncompressed size (an upper bound
    for the compressed time histories), variable-length strings at
    :data:`_STRING_BYTES` each and a heap of :data:`_HEAP_BYTES` per chunk, and a further chunk-index node per
    :data:`_INDEX_NODE_CHUNKS` chunks.

    Parameters
    ----------
    store_layout : Layout
        The store's layout (its impact table at its length).
    attrs : mapping
        The file's global attributes.

    Returns
    -------
    int
        Bytes: within a few per cent of the written file, or more with time
        histories (they are written compressed), tests/test_experiment_cli.py.
    """
    image = io.BytesIO(_metadata(store_layout, attrs, netCDF4.Dataset("in memory", mode="w", format="NETCDF4", memory=_MEMORY_HINT)))
    rest = 0
    with h5py.File(image, "r+") as handle:
        for spec in store_layout.specs:
            variable = handle[spec.name]
            if variable.size == 0:
                continue
            variable[(0,) * variable.ndim] = "-" * _ID_CHARACTERS if variable.dtype.kind == "O" else 0
            count, per_chunk = _chunks(variable.shape, variable.chunks, variable.dtype)
            chunks = math.prod(count)
            written = 0 if variable.compression else 1  # a compressed chunk of one element takes almost nothing
            rest += (chunks - written) * per_chunk + (chunks // _INDEX_NODE_CHUNKS) * _INDEX_NODE_BYTES
    return image.getbuffer().nbytes + rest


class _MetadataOnly:
    """An xarray array writer that writes in-memory variables (coordinates) and creates the lazy ones empty."""

    def add(self, source: Any, target: Any, region: Any = None) -> None:
        if not hasattr(source, "dask"):
            target[region or ...] = source


def _create(store_layout: Layout, attrs: StoreAttributes, path: Path) -> None:
    """Create the store file: dimensions, coordinates, attributes and every variable (chunked, no data).

    Not ``to_netcdf(compute=False)``: it leaves the file open until the
    delayed write it returns is computed, and that write stores every lazy
    variable's placeholder data (the whole store, before any block of it is
    known); left uncomputed, the file closes whenever the delayed object is
    collected, after :func:`write_store` has renamed it over the store. Here
    ``Dataset.dump_to_store`` (what ``to_netcdf`` itself calls) writes the
    same metadata through a writer that creates the lazy variables empty
    (:class:`_MetadataOnly`, the ``add`` of xarray's ``ArrayWriter``: a change
    to that call raises, it cannot write another file), and the file is
    closed before the blocks are written.
    """
    _metadata(store_layout, attrs, netCDF4.Dataset(path, mode="w", format="NETCDF4"))


def _metadata(store_layout: Layout, attrs: StoreAttributes, handle: netCDF4.Dataset) -> memoryview | None:
    """Write the store's metadata into the new netCDF file ``handle`` and close it (its image for a file in memory).

    The store is built on the open file, not by ``NetCDF4DataStore.open``: that one's write lock is a dask.distributed
    Lock while a client is active, and the last checkpoint's rebuild may run as the run's cluster closes ("IOLoop is
    closed"); only this process writes here.
    """
    store = NetCDF4DataStore(handle)
    try:
        store_layout.template(attrs).dump_to_store(store, writer=_MetadataOnly())
    except BaseException:
        handle.close()
        raise
    return handle.close()


class _Parts:
    """Parts read whole, kept (least recently used first out) within :data:`PART_CACHE_BYTES`."""

    def __init__(self) -> None:
        self.items: OrderedDict[Path, dict[str, np.ndarray]] = OrderedDict()
        self.bytes = 0

    def get(self, path: Path) -> dict[str, np.ndarray]:
        if path in self.items:
            self.items.move_to_end(path)
            return self.items[path]
        arrays = read_part(path)
        if arrays is None:
            raise OSError(f"{path}: part became unreadable while the store was written")
        self.items[path] = arrays
        self.bytes += sum(a.nbytes for a in arrays.values())
        while self.bytes > PART_CACHE_BYTES and len(self.items) > 1:
            _, dropped = self.items.popitem(last=False)
            self.bytes -= sum(a.nbytes for a in dropped.values())
        return arrays


class _Writer:
    """Assembles and writes the blocks of one store file."""

    def __init__(self, experiment: Experiment, store_layout: Layout, index: PartsIndex, handle: h5py.File, union: np.ndarray) -> None:
        self.experiment = experiment
        self.layout = store_layout
        self.index = index
        self.handle = handle
        self.union = union
        self.parts = _Parts()
        counts = index.impacts.ravel()
        self.impact_starts = np.cumsum(counts) - counts  # first row of each case's impacts, in grid order

    # ------------------------------------------------------------ grid variables

    def grid(self, kind: str) -> None:
        """Status, ids and summaries of ``kind`` (and, for cases, the impact table), block by block."""
        specs = self.layout.of("summary", kind)
        status, identifier = self.layout.of("status", kind)[0], self.layout.of("id", kind)[0]
        shape = self.experiment.grid_shape(kind)
        impacts = kind == CASE and bool(self.layout.of("impact"))
        for block in blocks(shape, status.chunks):
            source = self.index.source[kind][block]
            self.handle[status.name][block] = np.where(self.experiment.in_grid(kind)[block], (source >= 0).astype(np.int8), np.int8(-1))
            ids = self._ids(kind, block)
            self.handle[identifier.name][block] = ids
            buffers = {spec.name: np.full(source.shape + spec.chunks[len(shape):], np.nan if spec.dtype.kind == "f" else INT_FILL, dtype=spec.dtype) for spec in specs}
            rows = self._impact_rows(block) if impacts else None
            for section, local, arrays, prefix in self._contributions(kind, block, source):
                for spec in specs:
                    if f"{prefix}/s:{spec.name}" not in arrays:
                        raise ExperimentError(f"{spec.name}: the finished cases in the store's parts folder were computed by an earlier "
                                              "stochpound without it: run the experiment again with --restart to recompute them")
                    buffers[spec.name][local] = arrays[f"{prefix}/s:{spec.name}"][section]
                if rows is not None:
                    self._fill_impacts(rows, block, local, section, arrays, prefix, ids)
            if (source >= 0).any():  # a block without finished cases stays unwritten: the file's fill values
                for spec in specs:
                    self.handle[spec.name][block] = buffers[spec.name]
            if rows is not None and len(rows.columns["impact_case_id"]):
                for name, values in rows.columns.items():
                    self.handle[name][rows.first : rows.first + len(values)] = values

    def _contributions(self, kind: str, block: tuple[slice, ...], source: np.ndarray):
        """(rows of the section, their positions in the block, the part's arrays, the section's prefix) of each section with cases in the block."""
        starts = np.array([s.start for s in block])
        stops = np.array([s.stop for s in block])
        for section_index in np.unique(source[source >= 0]):
            path, prefix = self.index.sections[section_index]
            arrays = self.parts.get(path)
            positions = arrays[f"{prefix}/position"]
            inside = np.flatnonzero(((positions >= starts) & (positions < stops)).all(axis=1))
            local = positions[inside] - starts
            mine = source[tuple(local.T)] == section_index
            yield inside[mine], tuple(local[mine].T), arrays, prefix

    def _ids(self, kind: str, block: tuple[slice, ...]) -> np.ndarray:
        """Case ids of the block as strings ('' where no case is in the grid)."""
        return self.experiment.grid_case_ids(kind)[block].astype("U16").astype(object)

    # ------------------------------------------------------------ impact table

    def _impact_rows(self, block: tuple[slice, ...]) -> ImpactRows:
        """Empty buffers for the impact rows of the block's cases (contiguous in grid order)."""
        shape = self.experiment.grid_shape(CASE)
        flat = np.ravel_multi_index(tuple(np.array([s.start, s.stop - 1]) for s in block), shape)
        counts = self.index.impacts.ravel()
        first, last = int(self.impact_starts[flat[0]]), int(self.impact_starts[flat[1]] + counts[flat[1]])
        columns = {spec.name: np.zeros(last - first, dtype=_file_dtype(spec)) for spec in self.layout.of("impact")}
        return ImpactRows(first, columns)

    def _fill_impacts(self, rows: ImpactRows, block: tuple[slice, ...], local: tuple[np.ndarray, ...], section: np.ndarray, arrays: dict[str, np.ndarray], prefix: str, ids: np.ndarray) -> None:
        """Copy the impact rows of a section's cases in the block to their places in grid order."""
        counts = arrays[f"{prefix}/i:count"]
        section_starts = np.cumsum(counts) - counts
        chosen = counts[section]
        shape = self.experiment.grid_shape(CASE)
        positions = tuple(index + s.start for index, s in zip(local, block))
        flat = np.ravel_multi_index(positions, shape)
        within = np.arange(chosen.sum()) - np.repeat(np.cumsum(chosen) - chosen, chosen)
        source_rows = np.repeat(section_starts[section], chosen) + within
        target_rows = np.repeat(self.impact_starts[flat] - rows.first, chosen) + within
        columns = rows.columns
        for name in columns:
            if name == "impact_case_id":
                columns[name][target_rows] = np.repeat(ids[local], chosen)
            elif f"{prefix}/i:{name}" in arrays:
                columns[name][target_rows] = arrays[f"{prefix}/i:{name}"][source_rows]
        for axis, dim in enumerate(self.experiment.dims):
            values = np.asarray(dim.values, dtype=columns[f"impact_{dim.name}"].dtype)
            columns[f"impact_{dim.name}"][target_rows] = np.repeat(values[positions[axis]], chosen)

    # ------------------------------------------------------------ time histories

    def history(self, spec: Spec) -> None:
        """A time-history variable, block by block (each case's samples placed on the union time axis)."""
        kind = spec.kind
        shape = self.experiment.grid_shape(kind)
        trailing = spec.chunks[len(shape):]
        kept = [self.experiment.building_names.index(b) for b in self.experiment.output.buildings]
        own_dims = spec.dims[len(shape) : -1]  # a part keeps the output buildings only: their rows of ``building``
        for block in blocks(shape, spec.chunks[: len(shape)]):
            source = self.index.source[kind][block]
            if not (source >= 0).any():
                continue
            buffer = np.full(source.shape + trailing, np.nan)
            flat_buffer = buffer.reshape((-1,) + trailing)
            for section, local, arrays, prefix in self._contributions(kind, block, source):
                key = f"{prefix}/t:{spec.name}"
                if key not in arrays or not len(section):
                    continue
                values = arrays[key][section]
                columns = np.searchsorted(self.union, np.round(arrays[f"{prefix}/t:time"], 9))
                where = np.ravel_multi_index(local, source.shape)
                rows = [np.asarray(kept) if dim == "building" else np.arange(n) for dim, n in zip(own_dims, values.shape[1:-1])]
                flat_buffer[np.ix_(where, *rows, columns)] = values
            self.handle[spec.name][block] = buffer


@dataclass(frozen=True)
class ImpactRows:
    """The impact rows of a block's cases, filled section by section before they are written.

    Attributes
    ----------
    first : int
        The first row's index in the store's impact table.
    columns : dict[str, numpy.ndarray]
        A buffer per impact variable (in the file's dtype), by name.
    """

    first: int
    columns: dict[str, np.ndarray]


def _file_dtype(spec: Spec) -> Any:
    """In-memory dtype of a variable's values as written with h5py (bool as int8, strings as objects)."""
    if spec.dtype.kind == "U":
        return object
    if spec.dtype.kind == "b":
        return np.int8
    return spec.dtype
