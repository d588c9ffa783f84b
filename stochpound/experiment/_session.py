"""A store and its parts folder: identity checks, loading the finished cases, rebuilding the file.

Used by ``experiment run`` (with the folder's lock held) and by
``experiment status``.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import hashlib
import json
import os
import platform
import subprocess
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from stochpound import __version__
from stochpound.experiment._experiment import Experiment
from stochpound.store import KINDS, MotionTable
from stochpound._atomic import check_not_input, temporaries
from stochpound._text_files import attribute_text
from stochpound.experiment._parts import (DEFINITION_FILE, RUNS_FILE, FolderRecord, RunEntry, part_paths, parts_folder, read_experiment_json, read_runs,
                                          write_experiment_json)
from stochpound.experiment._spec import ExperimentError
from stochpound.store import definition_sha256
from stochpound.experiment._file_layout import PREFIX, layout, record_motions
from stochpound.experiment._file_assembly import PartsIndex, write_store


def now() -> str:
    """Current UTC time, ISO 8601."""
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def choice_sha256(records: list[str], motion_tables: list[str], scale_factors: np.ndarray) -> str:
    """The identity of a choice of the stripes' motions: the pool's motions (labels and scene tables, in the ``record`` order)
    and each stripe's scale factors (intensity × record, NaN where the motion is not chosen), every bit of them."""
    scales = [[None if np.isnan(value) else float(value).hex() for value in row] for row in np.asarray(scale_factors, dtype=float)]
    table = {"record": [str(label) for label in records], "record_motion": [str(motion) for motion in motion_tables], "scale_factor": scales}
    return hashlib.sha256(json.dumps(table, sort_keys=True).encode()).hexdigest()


def experiment_choice(experiment: Experiment) -> str:
    """:func:`choice_sha256` of the motions the experiment's stripes choose ("" where they choose none)."""
    if experiment.selection is None:
        return ""
    scales = experiment.selection.coordinates()["selection_scale_factor"].values
    return choice_sha256(list(experiment.motions), record_motions(experiment), scales)


def stored_choice(store: Path) -> str:
    """:func:`choice_sha256` of the choice a store file records ("" without one: no file, no selection, unreadable)."""
    import xarray as xr

    try:
        with xr.open_dataset(store, engine="h5netcdf", decode_times=False) as data:
            if "selection_scale_factor" not in data.variables:
                return ""
            return choice_sha256(list(data["record"].values), list(data["record_motion"].values), data["selection_scale_factor"].values)
    except (OSError, ValueError, KeyError):
        return ""


def check_choice(store: Path, record: FolderRecord, choice: str) -> None:
    """Refuse to add cases to a store whose finished cases ran another choice of the stripes' motions.

    The choice is recorded in the parts folder (``choice_sha256``), or read from the store file for a folder written before
    it was kept. It changes only with the selection's code (another version of stochpound, or a constant of its pools): the
    definition, and so the store's identity, is the same, but a case of a stripe would run another motion than its neighbours.

    Raises
    ------
    ExperimentError
        One line naming the store, if the folder holds finished cases of another choice.
    """
    recorded = record.choice_sha256 or (stored_choice(store) if store.is_file() else "")
    if choice and recorded and recorded != choice and part_paths(parts_folder(store)):
        raise ExperimentError(f"{store}: its finished cases ran another choice of the stripes' motions than this stochpound makes for the same "
                              "definition (the selection's code changed since); use --restart to run every case again, or --store to write elsewhere")


def store_identity(store: Path) -> str:
    """The identity of an existing store file's runs, by today's rule (:func:`~stochpound.store.definition_sha256`).

    Computed from the store's ``definition`` attribute, so that a store
    written while its hazard was part of the identity keeps its runs; its
    ``definition_sha256`` attribute for a store without that attribute.

    Raises
    ------
    ExperimentError
        If the file is not a readable experiment store.
    """
    import h5py

    try:
        with h5py.File(store, "r") as handle:
            if "definition" in handle.attrs:
                return definition_sha256(json.loads(attribute_text(handle.attrs["definition"])))
            value = handle.attrs["definition_sha256"]
    except KeyError:
        raise ExperimentError(f"{store}: not a stochpound experiment store (no definition_sha256 attribute)") from None
    except OSError as error:
        raise ExperimentError(f"{store}: not a readable netCDF4/HDF5 file ({error})") from None
    return attribute_text(value)


def stored_definition(store: Path) -> dict[str, Any]:
    """The canonical definition an existing store file holds (its ``definition`` attribute, parsed; {} without one)."""
    import h5py

    with h5py.File(store, "r") as handle:
        return json.loads(attribute_text(handle.attrs["definition"])) if "definition" in handle.attrs else {}


def stored_text(store: Path) -> str:
    """The experiment text an existing store file records (its ``experiment_text`` attribute; "" without one)."""
    import h5py

    with h5py.File(store, "r") as handle:
        return attribute_text(handle.attrs["experiment_text"]) if "experiment_text" in handle.attrs else ""


def check_store(store: Path, sha256: str) -> bool:
    """Refuse a store (or parts folder) that belongs to another experiment definition, or a file that is not a store.

    Returns
    -------
    bool
        True if the store file is damaged (unreadable) but its parts folder
        holds this definition's finished cases: the run rebuilds the file from them.

    Raises
    ------
    ExperimentError
        The store is a folder, is not a store (a file that is no netCDF4/HDF5 store of
        stochpound's, without parts to rebuild it from: ``--restart`` is not offered,
        it would not discard it), or was made from a different definition.
    """
    hint = "use --restart to discard it and start again, or --store to write elsewhere"
    if store.is_dir():
        raise ExperimentError(f"{store}: is a folder; --store must name a file")
    folder = parts_folder(store)
    parts = has_parts(store)
    damaged = False
    if store.exists():
        try:
            found = store_identity(store)
        except ExperimentError as error:
            if not parts:
                raise ExperimentError(f"{error}; {NOT_A_STORE}") from None
            damaged = True  # rebuilt from the parts, if they hold this definition's cases (checked below)
        else:
            if found != sha256:
                raise ExperimentError(f"{store}: made from a different experiment definition (sha256 {found[:12]}…, this one {sha256[:12]}…); {hint}")
    if parts:
        try:
            found = read_experiment_json(folder).identity
        except ExperimentError as error:
            raise ExperimentError(f"{folder}: unreadable parts folder ({error}); {hint}") from None
        if found != sha256:
            raise ExperimentError(f"{folder}: holds cases of a different experiment definition (sha256 {found[:12]}…, this one {sha256[:12]}…); {hint}")
    return damaged


NOT_A_STORE = ("not a store of stochpound's, so neither a run nor --restart replaces it: give --store another file "
               "(a damaged store without its parts folder: delete it yourself)")
"""Why a file that is not a store is left alone (the end of the message that refuses it)."""


def has_parts(store: Path) -> bool:
    """Whether the store's parts folder holds a run's files (its ``experiment.json`` or finished cases)."""
    folder = parts_folder(store)
    return folder.is_dir() and ((folder / DEFINITION_FILE).exists() or bool(part_paths(folder)))


def check_store_path(store: Path, experiment: Experiment, restart: bool) -> None:
    """Refuse a store path that is an input of the run, or (with ``restart``) a file ``--restart`` cannot tell is a store.

    ``--restart`` discards the store file only when it is a store (a netCDF4/HDF5
    file with stochpound's ``definition_sha256``, :func:`store_identity`) or the
    file of a run's parts folder (:func:`has_parts`); never another file.

    Raises
    ------
    ExperimentError
        Naming the store and what it is.
    """
    try:
        check_not_input(store, input_files(experiment), "--store")
    except ValueError as error:
        raise ExperimentError(f"{error} (the store to write; default: the experiment file's name with suffix .nc)") from None
    if restart and store.is_file() and not has_parts(store):
        try:
            store_identity(store)
        except ExperimentError as error:
            raise ExperimentError(f"{error}; {NOT_A_STORE}") from None


def input_files(experiment: Experiment) -> list[tuple[Path, str]]:
    """The files a run reads, each with what it is: the experiment file, its scene file, record files and hazard file."""
    base = experiment.base_dir
    definition = experiment.definition
    found = [(Path(experiment.path), "the experiment file")] if experiment.path else []
    source = definition.scene_source or {}
    if "file" in source:
        found.append((base / source["file"], "the experiment's scene file"))
    if definition.hazard is not None and definition.hazard.file:
        found.append((base / definition.hazard.file, "the experiment's hazard file"))
    tables = [MotionTable.of_source(source) for source in definition.motions]
    found += [(base / table.record, "a record file of the experiment") for table in tables if table.file_sha256 and table.record is not None]
    return found


def store_complete(store: Path) -> bool:
    """True if the store file (readable, checked by :func:`check_store`) has no missing case."""
    import h5py

    with h5py.File(store, "r") as handle:
        return all(not (handle[f"{prefix}_status"][()] == 0).any() for prefix in PREFIX.values())


def missing_summaries(store: Path, experiment: Experiment, motion_grids: dict[str, tuple[float, int]]) -> list[str]:
    """The summaries the experiment's store keeps today (:func:`stochpound.experiment._file_layout.layout`) that the store file lacks: one written
    by an earlier stochpound (e.g. ``peak_wall_penetration``, kept since for a scene with walls)."""
    import h5py

    with h5py.File(store, "r") as handle:
        return [spec.name for spec in layout(experiment, motion_grids, 0).of("summary") if spec.name not in handle]


def clear_store(store: Path) -> None:
    """Delete a store file and its parts (``--restart``, after :func:`check_store_path`; call with the folder's lock held).

    Only the parts folder's own files go (``experiment.json``, ``runs.jsonl``,
    the parts and the temporaries of interrupted writes); anything else a
    user put there stays.
    """
    folder = parts_folder(store)
    for path in [folder / DEFINITION_FILE, folder / RUNS_FILE, *part_paths(folder), *temporaries(folder)]:
        path.unlink(missing_ok=True)
    store.unlink(missing_ok=True)


PACKAGE = Path(__file__).resolve().parents[1]
"""The stochpound package's folder."""


def git_commit(package: Path = PACKAGE) -> str:
    """Commit of the git checkout the package is in ("+dirty" if modified), or "none" (an installed copy).

    An installed copy is identified by the version and :func:`sources_sha256`.
    """
    source = package.parent
    try:
        tracked = subprocess.run(["git", "-C", str(source), "ls-files", "--error-unmatch", f"{package.name}/__init__.py"], capture_output=True, timeout=10)
        commit = subprocess.run(["git", "-C", str(source), "rev-parse", "HEAD"], capture_output=True, text=True, timeout=10)
        if tracked.returncode != 0 or commit.returncode != 0:
            return "none"
        dirty = subprocess.run(["git", "-C", str(source), "status", "--porcelain", "--", package.name], capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return "none"
    return commit.stdout.strip() + ("+dirty" if dirty.stdout.strip() else "")


@lru_cache(maxsize=None)
def sources_sha256(package: Path = PACKAGE) -> str:
    """sha256 of the package's Python sources: every ``.py`` file's path (relative, sorted) and contents.

    With the version, it identifies the code of a copy that is not a git
    checkout (``pip install .``), where :func:`git_commit` gives "none".
    """
    digest = hashlib.sha256()
    for path in sorted(package.rglob("*.py")):
        digest.update(path.relative_to(package).as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()


def code_identity() -> dict[str, str]:
    """What identifies the running code: version, git commit (or "none") and sources' sha256."""
    return {"stochpound_version": __version__, "git_commit": git_commit(), "sources_sha256": sources_sha256()}


def machine() -> str:
    """Host, platform, Python and CPU count of this process."""
    return f"{platform.node()}; {platform.platform()}; Python {platform.python_version()}; {os.cpu_count()} CPUs"


class StoreSession:
    """A store file, its parts folder and the experiment they belong to.

    Parameters
    ----------
    store : Path
        The store file.
    experiment : Experiment
    record : FolderRecord
        Contents of ``experiment.json``.
    """

    def __init__(self, store: Path, experiment: Experiment, record: FolderRecord) -> None:
        self.store = Path(store)
        self.folder = parts_folder(self.store)
        self.experiment = experiment
        self.record = record
        self.index: PartsIndex | None = None

    @classmethod
    def create(cls, store: Path, experiment: Experiment, motion_grids: dict[str, tuple[float, int]]) -> "StoreSession":
        """Open the parts folder for a run, writing ``experiment.json`` if it is new.

        Raises
        ------
        ExperimentError
            If the folder's finished cases ran another choice of the stripes' motions than the experiment's now
            (:func:`check_choice`).
        """
        folder = parts_folder(store)
        folder.mkdir(parents=True, exist_ok=True)
        definition, text_sha256 = json.loads(experiment.definition_json), hashlib.sha256(experiment.text.encode()).hexdigest()
        choice = experiment_choice(experiment)
        if (folder / DEFINITION_FILE).exists():
            record = read_experiment_json(folder)
            check_choice(store, record, choice)
            if record.definition != definition or record.text != experiment.text or record.choice_sha256 != choice:  # the same runs
                # (checked by check_store), another hazard, or another text of the same definition (its comments): record it, with
                # the file it came from (the same text from a store's copy elsewhere leaves the store as it is)
                record = dataclasses.replace(record, definition=definition, definition_sha256=experiment.sha256, text=experiment.text,
                                             text_sha256=text_sha256, file=experiment.path, base_dir=str(experiment.base_dir.resolve()),
                                             choice_sha256=choice)
                write_experiment_json(folder, record)
        else:
            grids = tuple((label, dt, samples) for label, (dt, samples) in motion_grids.items())
            record = FolderRecord(experiment.sha256, definition, experiment.text, text_sha256, experiment.path, str(experiment.base_dir.resolve()),
                                  grids, now(), choice)
            write_experiment_json(folder, record)
        return cls(store, experiment, record)

    @classmethod
    def open(cls, store: Path) -> "StoreSession":
        """Open an existing store's parts folder (for ``status``).

        Raises
        ------
        ExperimentError
            If there is no parts folder or it is unreadable.
        """
        folder = parts_folder(store)
        record = read_experiment_json(folder)
        if record.definition is None:
            raise ExperimentError(f"{folder / DEFINITION_FILE}: written by an older stochpound, without the definition; run the experiment again")
        experiment = Experiment(record.definition, record.text, record.base_dir, record.file)
        return cls(store, experiment, record)

    @property
    def motion_grids(self) -> dict[str, tuple[float, int]]:
        """(dt, samples) of each motion."""
        return self.record.grids

    def scan(self, remove_unreadable: bool = False) -> PartsIndex:
        """Find the finished cases in the parts (unreadable parts count as missing, and are deleted if asked)."""
        self.index = PartsIndex.scan(self.experiment, self.folder)
        if remove_unreadable:
            for path in self.index.unreadable:
                path.unlink(missing_ok=True)
        return self.index

    def missing(self) -> dict[str, np.ndarray]:
        """For each kind, which cases of its grid are still to run (bool, from the last :meth:`scan`)."""
        return {kind: self.experiment.in_grid(kind) & ~self.index.done(kind) for kind in KINDS}

    def attrs(self) -> dict[str, str | float]:
        """Provenance attributes of the store."""
        experiment = self.experiment
        solver = experiment.solver
        runs = read_runs(self.folder)
        last = runs[-1] if runs else RunEntry()
        return {
            "experiment_name": experiment.name,
            "experiment_description": experiment.definition.description,
            "experiment_file": self.record.file,
            "experiment_text": self.record.text,
            "experiment_sha256": self.record.text_sha256,
            "definition_sha256": experiment.sha256,
            "definition": experiment.definition_json,
            "studied_building": experiment.studied,
            "stochpound_version": __version__,
            "git_commit": last.git_commit,
            "stochpound_sources_sha256": last.sources_sha256,
            "solver": solver.method,
            "solver_integrator": solver.integrator,
            "solver_rtol": solver.rtol,
            "solver_atol": solver.atol,
            "solver_note": "integrator, rtol and atol apply to the ivp solver only",
            "seeds": json.dumps(experiment.seeds()),
            "created": self.record.created,
            "updated": now(),
            "machine": last.machine or machine(),
            "runs": json.dumps([run.to_json() for run in runs]),
        }

    def check_choice(self) -> None:
        """:func:`check_choice` of the session's store against the choice its experiment makes now (a session made by
        :meth:`open` from the folder's record chooses again when it rebuilds the file).

        Raises
        ------
        ExperimentError
            If the folder's finished cases ran another choice of the stripes' motions.
        """
        check_choice(self.store, self.record, experiment_choice(self.experiment))

    def rebuild(self) -> Path:
        """(Re)write the store file atomically from the parts (scanned again: parts written since count)."""
        return write_store(self.experiment, self.scan(), self.motion_grids, self.attrs(), self.store)
