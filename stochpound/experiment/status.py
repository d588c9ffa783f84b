"""``experiment status``: which cases of a store are done and which are missing."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from stochpound.experiment.model import Case, Experiment
from stochpound.experiment.parts import DEFINITION_FILE, FolderLock, parts_folder
from stochpound.experiment.session import StoreSession
from stochpound.experiment.spec import ExperimentError
from stochpound.experiment.store import open_store


@dataclass
class StatusReport:
    """The state of a store.

    Attributes
    ----------
    store : Path
    experiment : Experiment
    done, missing : list of Case
        Finished and missing cases, in grid order.
    running : bool
        A run holds the parts folder's lock (it is being written now).
    rebuilt : bool
        The store file was rebuilt from the parts.
    """

    store: Path
    experiment: Experiment
    done: list[Case]
    missing: list[Case]
    running: bool = False
    rebuilt: bool = False


def store_status(store: str | Path, rebuild: bool = True) -> StatusReport:
    """Done and missing cases of a store; rebuild the file from its parts when no run is writing it.

    Parameters
    ----------
    store : str or Path
        The store file (its parts folder ``STORE.parts`` is read if present).
    rebuild : bool
        Rewrite the store file from the parts (atomically) if no run holds the lock.

    Raises
    ------
    ExperimentError
        If neither a readable store nor a parts folder exists.
    """
    store = Path(store)
    if not (parts_folder(store) / DEFINITION_FILE).is_file():
        return _from_file(store)
    session = StoreSession.open(store)
    lock = FolderLock(session.folder)
    running = not lock.acquire()
    rebuilt = False
    try:
        if rebuild and not running:
            session.load()
            session.rebuild()
            rebuilt = True
            done_ids = set(session.results)
        else:
            done_ids = session.done_ids()
    finally:
        lock.release()
    return _report(store, session.experiment, done_ids, running, rebuilt)


def _from_file(store: Path) -> StatusReport:
    """Status from the store file alone (its parts folder was removed)."""
    dataset = open_store(store)
    try:
        experiment = Experiment(json.loads(dataset.attrs["definition"]), str(dataset.attrs.get("experiment_text", "")))
        done_ids = set()
        for prefix in ("case", "reference"):
            ids = dataset[f"{prefix}_id"].values.ravel()
            status = dataset[f"{prefix}_status"].values.ravel()
            done_ids |= {str(i) for i, s in zip(ids, status) if s == 1}
    except (KeyError, ValueError) as error:
        raise ExperimentError(f"{store}: not a stochpound experiment store ({error})") from None
    finally:
        dataset.close()
    return _report(store, experiment, done_ids, False, False)


def _report(store: Path, experiment: Experiment, done_ids: set[str], running: bool, rebuilt: bool) -> StatusReport:
    done = [c for c in experiment.cases if c.case_id in done_ids]
    missing = [c for c in experiment.cases if c.case_id not in done_ids]
    return StatusReport(store, experiment, done, missing, running, rebuilt)
