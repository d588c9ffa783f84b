"""``experiment status``: which cases of a store are done and which are missing."""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import numpy as np

from stochpound._errors import os_error_message
from stochpound.store import open_store
from stochpound.store import KINDS, Case, ExperimentGrid
from stochpound.experiment._parts import DEFINITION_FILE, FolderLock, parts_folder, recorded_cases
from stochpound.experiment._session import StoreSession
from stochpound.experiment._spec import ExperimentError
from stochpound.experiment._file_layout import PREFIX


@dataclass
class StatusReport:
    """The state of a store.

    Attributes
    ----------
    store : Path
    experiment : ExperimentGrid
        The store's experiment (its grid).
    done_mask : dict[str, numpy.ndarray]
        For each kind, which cases of its grid are finished (bool).
    running : bool
        A run holds the parts folder's lock (it is being written now).
    rebuilt : bool
        The store file was rebuilt from the parts.
    not_rebuilt : str
        Why a rebuild that was due failed (one line naming the file, e.g. a
        full disk), or "" (the parts and the old store file are intact).
    recorded : int or None
        Where the parts ran another choice of the stripes' motions (their grid is not the one today's choice gives):
        the finished cases they record, counted as written; None otherwise.
    """

    store: Path
    experiment: ExperimentGrid
    done_mask: dict[str, np.ndarray]
    running: bool = False
    rebuilt: bool = False
    not_rebuilt: str = ""
    recorded: int | None = None

    @property
    def n_done(self) -> int:
        """Finished cases (those the parts record, where they ran another choice of the stripes' motions)."""
        if self.recorded is not None:
            return self.recorded
        return sum(int(mask.sum()) for mask in self.done_mask.values())

    @property
    def n_missing(self) -> int:
        """Cases still to run."""
        return self.experiment.n_cases - self.n_done

    def cases(self, done: bool, limit: int | None = None) -> list[Case]:
        """The first ``limit`` (default all) finished (``done``) or missing cases, in grid order."""
        return list(itertools.islice(self._cases(done), limit))

    def _cases(self, done: bool) -> Iterator[Case]:
        for kind in KINDS:
            chosen = self.experiment.in_grid(kind) & (self.done_mask[kind] == done)
            for position in zip(*np.nonzero(chosen)):
                yield self.experiment.case_at(kind, position)


def store_status(store: str | Path, rebuild: bool = True) -> StatusReport:
    """Done and missing cases of a store; rebuild the file from its parts when no run is writing it.

    Parameters
    ----------
    store : str or Path
        The store file (its parts folder ``STORE.parts`` is read if present).
    rebuild : bool
        Rewrite the store file from the parts (atomically) if no run holds the
        lock and the folder can be written (a store on a read-only disk is only read).

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
    try:
        running, writable = not lock.acquire(), True
    except OSError:  # the lock file cannot be made or opened for writing (a read-only disk): only read
        running, writable = lock.held(), False
    rebuilt = rebuild and writable and not running
    not_rebuilt, recorded = "", None
    try:
        if rebuilt:
            try:
                session.check_choice()
                session.rebuild()
            except ExperimentError as error:  # cases of another choice of the stripes' motions: the file is not rewritten with this one
                rebuilt, not_rebuilt, recorded = False, str(error), recorded_cases(session.folder)
                session.scan()
            except OSError as error:  # a full disk, say: the parts and the old store file are intact; the status is still known
                rebuilt, not_rebuilt = False, os_error_message(error)
                session.scan()
        else:
            session.scan()
    finally:
        lock.release()
    done = {kind: session.index.done(kind) for kind in KINDS}
    return StatusReport(store, session.experiment, done, running, rebuilt, not_rebuilt, recorded)


def _from_file(store: Path) -> StatusReport:
    """Status from the store file alone (its parts folder was removed)."""
    dataset = open_store(store)
    try:
        experiment = dataset.pound.grid  # a conditional-spectrum store's choice of motions read from it, not chosen again
        done = {kind: dataset[f"{PREFIX[kind]}_status"].values == 1 for kind in KINDS}
    except (KeyError, ValueError) as error:
        raise ExperimentError(f"{store}: not a stochpound experiment store ({error})") from None
    finally:
        dataset.close()
    return StatusReport(store, experiment, done)
