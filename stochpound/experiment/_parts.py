"""The store's sidecar folder ``STORE.parts/``: finished cases, persisted in batches.

Layout::

    STORE.parts/
        experiment.json        the canonical definition, its sha256, the file text, motion grids
        runs.jsonl             one line per run: start time, host, workers, version, code identity
        .lock                  held (flock) by the run writing this folder
        part-<run>-<n>.npz     finished cases (numpy .npz, no pickles): the cases of at
                               least :data:`PART_REALIZATIONS` realizations, or a few
                               seconds of work, each

A part holds *sections*, one per kind of case and motion (``case.1`` is the
grid's cases under the motion at index 1 on ``record``). A section's arrays
are named ``<kind>.<record>/<name>``:

* ``position``: (n, n_dims) positions of its cases in the grid of their kind;
* ``s:<name>``: summaries, stacked (n, ...);
* ``t:<name>``: kept time histories, stacked (n, ..., n_samples) and padded
  with NaN to the section's largest shape; ``t:time`` their sample times, s;
* ``i:count``: impacts of each case, ``i:<name>``: the impact table's columns,
  the cases' rows one after the other.

Every file is written to a temporary name in the folder
(``.<name>.<random>.tmp``), flushed to disk (fsync) and renamed into place,
so a part that exists is complete: a run killed at any moment loses only the
cases not yet in a part (those in flight, and at most one part's worth
waiting to be written) and leaves, at worst, a stray temporary file, which
the next run deletes. HDF5 is never appended in place.
"""

from __future__ import annotations

import fcntl
import json
import os
import secrets
import time
import dataclasses
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, Sequence

import numpy as np

from stochpound._atomic import replacing, temporaries
from stochpound.experiment._spec import ExperimentError
from stochpound.store import definition_sha256

DEFINITION_FILE = "experiment.json"
RUNS_FILE = "runs.jsonl"
LOCK_FILE = ".lock"
PART_PREFIX = "part-"
PART_SUFFIX = ".npz"
PART_REALIZATIONS = 500
"""A part is written once the cases of this many realizations wait in the buffer (:class:`PartBuffer`): 500 times
the experiment's cases per realization (2 for one grid point and its fixed-base reference)."""
_PART_CASES = int(os.environ.get("STOCHPOUND_EXPERIMENT_PART_CASES", "0") or 0)
"""Testing aid: a number of cases that replaces that threshold, to make a small run write several parts."""
PART_SECONDS = 5.0
"""... or once the oldest waiting case finished this many seconds ago."""
PART_BYTES = 64 * 2**20
"""... or once the waiting cases' arrays hold this many bytes (time histories)."""
#: Testing aid: seconds to wait between writing a file and renaming it into place,
#: which widens the window in which a test can kill a run during a write.
_WRITE_DELAY = float(os.environ.get("STOCHPOUND_EXPERIMENT_WRITE_DELAY", "0") or 0)


def parts_folder(store: str | Path) -> Path:
    """The sidecar folder of a store file."""
    store = Path(store)
    return store.with_name(store.name + ".parts")


def atomic_write(path: Path, write: Any) -> None:
    """Write a file atomically: ``write(file_object)`` into a temporary file, fsync, rename (:mod:`stochpound._atomic`)."""
    with replacing(path) as temporary:
        with open(temporary, "wb") as stream:
            write(stream)
            stream.flush()
            os.fsync(stream.fileno())
        if _WRITE_DELAY:
            time.sleep(_WRITE_DELAY)


# ---------------------------------------------------------------- sections


def section_key(kind: str, record: int, name: str) -> str:
    """Name of a part array: ``<kind>.<record>/<name>``."""
    return f"{kind}.{record}/{name}"


def split_key(key: str) -> tuple[str, int, str]:
    """(kind, record, name) of a part array's name."""
    section, name = key.split("/", 1)
    kind, record = section.rsplit(".", 1)
    return kind, int(record), name


def stack_cases(cases: Sequence[dict[str, np.ndarray]], positions: np.ndarray, times: np.ndarray) -> dict[str, np.ndarray]:
    """One section's arrays (module docstring) from the part arrays of its cases.

    Parameters
    ----------
    cases : sequence of dict
        Each case's ``s:``, ``t:`` and ``i:`` arrays (:mod:`stochpound.experiment._summary`).
    positions : np.ndarray
        (n, n_dims) their grid positions.
    times : np.ndarray
        Sample times of their motion, s.
    """
    stacked: dict[str, np.ndarray] = {"position": np.asarray(positions, dtype=np.int64)}
    for name in cases[0]:
        values = [case[name] for case in cases]
        if name.startswith("s:"):
            stacked[name] = np.stack(values)
        elif name.startswith("t:"):
            stacked[name] = _stack_padded([np.asarray(v, dtype=float) for v in values])
            stacked["t:time"] = np.asarray(times, dtype=float)
        else:
            stacked[name] = np.concatenate(values)
            stacked["i:count"] = np.array([len(v) for v in values], dtype=np.int64)
    return stacked


def _stack_padded(values: Sequence[np.ndarray]) -> np.ndarray:
    shape = np.max([v.shape for v in values], axis=0)
    out = np.full((len(values), *shape), np.nan)
    for row, value in zip(out, values):
        row[tuple(slice(0, n) for n in value.shape)] = value
    return out


def concatenate(parts: Iterable[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Merge the arrays of several results or parts, section by section (cases one after the other)."""
    grouped: dict[str, list[np.ndarray]] = {}
    for arrays in parts:
        for key, values in arrays.items():
            grouped.setdefault(key, []).append(values)
    merged = {}
    for key, values in grouped.items():
        name = split_key(key)[2]
        if name == "t:time" or len(values) == 1:
            merged[key] = values[0]
        elif name.startswith("t:"):
            merged[key] = np.concatenate([_pad_to(v, np.max([w.shape for w in values], axis=0)) for v in values])
        else:
            merged[key] = np.concatenate(values)
    return merged


def _pad_to(values: np.ndarray, shape: np.ndarray) -> np.ndarray:
    widths = [(0, 0)] + [(0, int(n - m)) for n, m in zip(shape[1:], values.shape[1:])]
    return np.pad(values, widths, constant_values=np.nan) if any(w[1] for w in widths) else values


def section_count(arrays: dict[str, np.ndarray]) -> int:
    """Number of cases in a result's or part's arrays."""
    return sum(len(values) for key, values in arrays.items() if key.endswith("/position"))


# ---------------------------------------------------------------- part files


def write_part(folder: Path, name: str, arrays: dict[str, np.ndarray], meta: dict[str, str]) -> Path:
    """Write a part atomically as ``<name>.npz`` (``meta`` is kept as JSON)."""
    path = folder / f"{name}{PART_SUFFIX}"
    payload = {"meta": np.array(json.dumps(meta)), **arrays}
    atomic_write(path, lambda stream: np.savez(stream, **payload))
    return path


def read_part(path: Path, names: Sequence[str] | None = None) -> dict[str, np.ndarray] | None:
    """A part's arrays (only the sections' arrays whose name is in ``names``, if given); None if unreadable."""
    try:
        with np.load(path, allow_pickle=False) as data:
            keys = [k for k in data.files if k != "meta" and (names is None or split_key(k)[2] in names)]
            return {key: data[key] for key in keys}
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None


def recorded_cases(folder: Path) -> int:
    """Finished cases the parts of ``folder`` record, on whatever grid they ran (distinct positions of each kind).

    A folder whose cases ran another choice of the stripes' motions has a grid (its records) that today's choice does not
    rebuild, so its positions cannot be placed in today's grid: this counts them as written. Unreadable parts count none.
    """
    positions: dict[str, set[tuple[int, ...]]] = {}
    for path in part_paths(folder):
        for key, rows in (read_part(path, ("position",)) or {}).items():
            positions.setdefault(split_key(key)[0], set()).update(tuple(int(v) for v in row) for row in np.atleast_2d(rows))
    return sum(len(kind_positions) for kind_positions in positions.values())


def part_paths(folder: Path) -> list[Path]:
    """The part files of a folder, by name."""
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.iterdir() if p.name.startswith(PART_PREFIX) and p.name.endswith(PART_SUFFIX))


class PartBuffer:
    """Finished cases waiting to be written as one part file.

    A part is written when ``cases`` cases wait, when the oldest has waited
    :data:`PART_SECONDS`, or when they hold :data:`PART_BYTES` (:meth:`due`),
    and on :meth:`flush`.

    Parameters
    ----------
    folder : Path
        The parts folder.
    meta : dict[str, str]
        Kept in every part (the code's version and its sources' sha256).
    cases_per_realization : float
        The experiment's cases per realization of its motions: a part holds
        the cases of :data:`PART_REALIZATIONS` realizations.
    """

    def __init__(self, folder: Path, meta: dict[str, str], cases_per_realization: float) -> None:
        self.folder = folder
        self.meta = meta
        self.cases = _PART_CASES or max(1, round(PART_REALIZATIONS * cases_per_realization))
        self.run = secrets.token_hex(4)
        self.written = 0
        self.waiting: list[dict[str, np.ndarray]] = []
        self.count = 0
        self.bytes = 0
        self.oldest = 0.0

    def add(self, arrays: dict[str, np.ndarray]) -> None:
        """Queue the arrays of finished cases; write a part if one is due."""
        if not arrays:
            return
        if not self.waiting:
            self.oldest = time.monotonic()
        self.waiting.append(arrays)
        self.count += section_count(arrays)
        self.bytes += sum(values.nbytes for values in arrays.values())
        if self.due():
            self.flush()

    def due(self) -> bool:
        """Enough cases, bytes or waiting time for a part."""
        return bool(self.waiting) and (
            self.count >= self.cases or self.bytes >= PART_BYTES or time.monotonic() - self.oldest >= PART_SECONDS
        )

    def flush(self) -> None:
        """Write the waiting cases as one part (nothing if none wait)."""
        if not self.waiting:
            return
        self.written += 1
        write_part(self.folder, f"{PART_PREFIX}{self.run}-{self.written:06d}", concatenate(self.waiting), self.meta)
        self.waiting, self.count, self.bytes = [], 0, 0


# ---------------------------------------------------------------- folder


def remove_temporaries(folder: Path) -> None:
    """Delete temporary files left by interrupted writes of the parts and the store (call with the lock held)."""
    for path in temporaries(folder) + temporaries(folder.parent, folder.name[: -len(".parts")]):
        path.unlink(missing_ok=True)


@dataclass(frozen=True)
class FolderRecord:
    """What a parts folder's ``experiment.json`` holds: the run's definition and identity, the experiment file, the motions' grids.

    Attributes
    ----------
    definition_sha256 : str
        The identity of the definition the folder's cases ran (the rule of the time it was written).
    definition : dict or None
        The canonical definition (as its JSON reads back); None in a folder written before it was kept.
    text, text_sha256 : str
        The experiment file's text and its sha256.
    file : str
        The experiment file's path.
    base_dir : str
        The experiment file's folder (absolute).
    motion_grids : tuple of (str, float, int)
        Each motion's label, time step (s) and number of samples.
    created : str
        When the folder was created (UTC, ISO 8601).
    choice_sha256 : str
        The identity of the stripes' choice of motions the folder's cases ran (``experiment._session.choice_sha256``); "" where the
        stripes choose none, or in a folder written before it was kept.
    """

    definition_sha256: str
    definition: dict[str, Any] | None = None
    text: str = ""
    text_sha256: str = ""
    file: str = ""
    base_dir: str = "."
    motion_grids: tuple[tuple[str, float, int], ...] = ()
    created: str = ""
    choice_sha256: str = ""

    @classmethod
    def from_json(cls, data: Any) -> FolderRecord:
        """The record of an ``experiment.json``'s contents (the fields a folder of an older stochpound lacks take their defaults)."""
        grids = tuple((label, float(grid[0]), int(grid[1])) for label, grid in data["motion_grids"].items())
        known = {name: data[name] for name in ("definition", "text", "text_sha256", "file", "base_dir", "created", "choice_sha256") if name in data}
        return cls(data["definition_sha256"], motion_grids=grids, **known)

    def to_json(self) -> dict[str, Any]:
        """The ``experiment.json`` contents, its fields in the order they are written."""
        written = {"definition_sha256": self.definition_sha256, "definition": self.definition, "text": self.text, "text_sha256": self.text_sha256,
                   "file": self.file, "base_dir": self.base_dir, "motion_grids": {label: [dt, samples] for label, dt, samples in self.motion_grids},
                   "created": self.created, "choice_sha256": self.choice_sha256}
        return {key: value for key, value in written.items() if not (key == "definition" and value is None or key == "choice_sha256" and not value)}

    @property
    def identity(self) -> str:
        """The identity of the folder's runs by today's rule (:func:`~stochpound.store.definition_sha256` of its definition, when it has one)."""
        return definition_sha256(self.definition) if self.definition is not None else self.definition_sha256

    @property
    def grids(self) -> dict[str, tuple[float, int]]:
        """(dt, samples) of each motion, by label."""
        return {label: (dt, samples) for label, dt, samples in self.motion_grids}


def read_experiment_json(folder: Path) -> FolderRecord:
    """The contents of ``experiment.json`` (definition, sha256, text, motion grids, created).

    Raises
    ------
    ExperimentError
        If the file is missing, unreadable, or lacks ``definition_sha256``.
    """
    path = folder / DEFINITION_FILE
    try:
        return FolderRecord.from_json(json.loads(path.read_text()))
    except FileNotFoundError:
        raise ExperimentError(f"{folder}: not an experiment store folder ({DEFINITION_FILE} missing)") from None
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as error:
        raise ExperimentError(f"{path}: unreadable ({error}); use --restart to start the store again") from None


def write_experiment_json(folder: Path, record: FolderRecord) -> None:
    """Write ``experiment.json`` atomically."""
    atomic_write(folder / DEFINITION_FILE, lambda stream: stream.write(json.dumps(record.to_json(), indent=1).encode()))


@dataclass(frozen=True)
class RunEntry:
    """One run of an experiment on its parts folder: a line of ``runs.jsonl``, the run history.

    Attributes
    ----------
    started : str
        When it started (UTC, ISO 8601).
    machine : str
        Host, platform, Python and CPU count of the process that ran it.
    executor : str
        Where its cases ran (in this process, local workers, a cluster).
    stochpound_version, git_commit, sources_sha256 : str
        The code that ran it (the commit ``none`` outside a git checkout, or in a line of an older stochpound that lacks it; the others empty).
    """

    started: str = ""
    machine: str = ""
    executor: str = ""
    stochpound_version: str = ""
    git_commit: str = "none"
    sources_sha256: str = ""

    @classmethod
    def from_json(cls, line: str) -> RunEntry:
        """The entry of one line of ``runs.jsonl`` (its fields that this record does not know are ignored).

        Raises
        ------
        ValueError
            If the line is not a JSON table (e.g. cut by a kill).
        """
        data = json.loads(line)
        if not isinstance(data, dict):
            raise ValueError(f"not a JSON table: {line!r}")
        return cls(**{field.name: str(data[field.name]) for field in dataclasses.fields(cls) if field.name in data})

    def to_json(self) -> dict[str, str]:
        """The line's fields, in the order they are written."""
        return dataclasses.asdict(self)


def append_run(folder: Path, entry: RunEntry) -> None:
    """Append one line to ``runs.jsonl`` (the run history)."""
    with open(folder / RUNS_FILE, "a") as stream:
        stream.write(json.dumps(entry.to_json()) + "\n")
        stream.flush()
        os.fsync(stream.fileno())


def read_runs(folder: Path) -> list[RunEntry]:
    """The run history (lines that cannot be parsed, e.g. cut by a kill, are skipped)."""
    runs = []
    try:
        lines = (folder / RUNS_FILE).read_text().splitlines()
    except FileNotFoundError:
        return runs
    for line in lines:
        try:
            runs.append(RunEntry.from_json(line))
        except ValueError:
            continue
    return runs


class FolderLock:
    """An exclusive advisory lock on a parts folder (released by the OS if the holder dies)."""

    def __init__(self, folder: Path) -> None:
        self.path = folder / LOCK_FILE
        self.handle: Any = None

    def acquire(self) -> bool:
        """Take the lock without waiting; False if another process holds it."""
        self.handle = open(self.path, "a+")
        try:
            fcntl.flock(self.handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self.handle.close()
            self.handle = None
            return False
        return True

    def held(self) -> bool:
        """True if another process holds the lock (probed through a read-only handle: nothing is created or written)."""
        try:
            handle = open(self.path)
        except FileNotFoundError:
            return False
        with handle:
            try:
                fcntl.flock(handle, fcntl.LOCK_SH | fcntl.LOCK_NB)
            except BlockingIOError:
                return True
            fcntl.flock(handle, fcntl.LOCK_UN)
        return False

    def release(self) -> None:
        """Release the lock."""
        if self.handle is not None:
            fcntl.flock(self.handle, fcntl.LOCK_UN)
            self.handle.close()
            self.handle = None

    def __enter__(self) -> "FolderLock":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.release()
