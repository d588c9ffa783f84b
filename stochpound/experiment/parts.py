"""The store's sidecar folder ``STORE.parts/``: one small file per finished case.

Layout::

    STORE.parts/
        experiment.json        the canonical definition, its sha256, the file text, motion grids
        runs.jsonl             one line per run: start time, host, workers, version, git commit
        .lock                  held (flock) by the run writing this folder
        <case_id>.npz          one finished case (numpy .npz, no pickles)

Every file is written to a temporary name in the folder, flushed to disk
(fsync) and renamed into place, so a part that exists is complete: a run
killed at any moment leaves finished parts and, at worst, a stray temporary
file, which the next run deletes. HDF5 is never appended in place.
"""

from __future__ import annotations

import fcntl
import json
import os
import tempfile
import time
import zipfile
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from stochpound.experiment.spec import ExperimentError

DEFINITION_FILE = "experiment.json"
RUNS_FILE = "runs.jsonl"
LOCK_FILE = ".lock"
PART_SUFFIX = ".npz"
_TEMP_PREFIX = ".tmp-"
#: Testing aid: seconds to wait between writing a file and renaming it into place,
#: which widens the window in which a test can kill a run during a write.
_WRITE_DELAY = float(os.environ.get("STOCHPOUND_EXPERIMENT_WRITE_DELAY", "0") or 0)


def parts_folder(store: str | Path) -> Path:
    """The sidecar folder of a store file."""
    store = Path(store)
    return store.with_name(store.name + ".parts")


def atomic_write(path: Path, write: Any) -> None:
    """Write a file atomically: ``write(file_object)`` into a temporary file, fsync, rename."""
    handle, temporary = tempfile.mkstemp(prefix=_TEMP_PREFIX + path.name + ".", dir=path.parent)
    try:
        with os.fdopen(handle, "wb") as stream:
            write(stream)
            stream.flush()
            os.fsync(stream.fileno())
        if _WRITE_DELAY:
            time.sleep(_WRITE_DELAY)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def write_part(folder: Path, case_id: str, meta: dict[str, Any], arrays: dict[str, np.ndarray]) -> Path:
    """Write one finished case atomically as ``<case_id>.npz``."""
    path = folder / f"{case_id}{PART_SUFFIX}"
    payload = {"meta": np.array(json.dumps(meta)), **arrays}
    atomic_write(path, lambda stream: np.savez(stream, **payload))
    return path


def read_part(path: Path) -> tuple[dict[str, Any], dict[str, np.ndarray]] | None:
    """Read a part; None if it cannot be read (it is then treated as missing)."""
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {key: data[key] for key in data.files}
        meta = json.loads(str(arrays.pop("meta")))
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None
    return meta, arrays


def part_ids(folder: Path) -> set[str]:
    """Case ids of the part files present in the folder."""
    if not folder.is_dir():
        return set()
    return {p.name[: -len(PART_SUFFIX)] for p in folder.iterdir() if p.name.endswith(PART_SUFFIX) and not p.name.startswith(".")}


def remove_temporaries(folder: Path) -> None:
    """Delete temporary files left by an interrupted write (call with the lock held)."""
    for path in folder.glob(_TEMP_PREFIX + "*"):
        path.unlink(missing_ok=True)
    for path in folder.parent.glob(f".{folder.name[: -len('.parts')]}.*.tmp"):
        path.unlink(missing_ok=True)


def read_definition(folder: Path) -> dict[str, Any]:
    """The contents of ``experiment.json`` (definition, sha256, text, motion grids, created)."""
    path = folder / DEFINITION_FILE
    try:
        return json.loads(path.read_text())
    except FileNotFoundError:
        raise ExperimentError(f"{folder}: not an experiment store folder ({DEFINITION_FILE} missing)") from None
    except (OSError, ValueError) as error:
        raise ExperimentError(f"{path}: unreadable ({error}); use --restart to start the store again") from None


def write_definition(folder: Path, record: dict[str, Any]) -> None:
    """Write ``experiment.json`` atomically."""
    atomic_write(folder / DEFINITION_FILE, lambda stream: stream.write(json.dumps(record, indent=1).encode()))


def append_run(folder: Path, entry: dict[str, Any]) -> None:
    """Append one line to ``runs.jsonl`` (the run history)."""
    with open(folder / RUNS_FILE, "a") as stream:
        stream.write(json.dumps(entry) + "\n")
        stream.flush()
        os.fsync(stream.fileno())


def read_runs(folder: Path) -> list[dict[str, Any]]:
    """The run history (lines that cannot be parsed, e.g. cut by a kill, are skipped)."""
    runs = []
    try:
        lines = (folder / RUNS_FILE).read_text().splitlines()
    except FileNotFoundError:
        return runs
    for line in lines:
        try:
            runs.append(json.loads(line))
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


def iter_parts(folder: Path, ids: set[str]) -> Iterator[tuple[str, dict[str, Any], dict[str, np.ndarray]]]:
    """Read the parts of the given case ids; unreadable ones are skipped."""
    for case_id in sorted(ids):
        content = read_part(folder / f"{case_id}{PART_SUFFIX}")
        if content is not None:
            yield case_id, *content
