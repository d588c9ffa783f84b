"""``experiment run``: the missing cases of an experiment, on dask, into its store.

The client (this process) validates everything, checks the store, writes the
store file once before the first case, submits batches of cases, writes one
part per finished case as results arrive, rebuilds the store at checkpoints
and at the end. Workers only compute (:mod:`stochpound.experiment.compute`):
they need the package, not the store's file system.
"""

from __future__ import annotations

import json
import logging
import os
import signal
import sys
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator, Sequence

from stochpound import __version__
from stochpound.experiment.compute import CaseOutcome, CaseTask, run_batch
from stochpound.experiment.model import REFERENCE, Case, Experiment
from stochpound.experiment.parts import FolderLock, append_run, parts_folder, remove_temporaries, write_part
from stochpound.experiment.session import StoreSession, check_store, clear_store, git_commit, machine, now
from stochpound.experiment.sources import ResolvedMotion, resolve_motions
from stochpound.experiment.spec import ExperimentError, canonical_json, load_definition


@dataclass
class RunReport:
    """What a run did.

    Attributes
    ----------
    store : Path
        The store file.
    total : int
        Cases of the experiment (references included).
    done_before : int
        Cases already finished when the run started.
    done_now : int
        Cases finished by this run.
    failed : list of (str, str)
        Cases that raised, described, with their tracebacks.
    elapsed : float
        Wall time of the run, s.
    executor : str
        Where the cases ran.
    interrupted : bool
        True if the run was stopped (Ctrl-C, SIGTERM).
    """

    store: Path
    total: int
    done_before: int
    done_now: int = 0
    failed: list[tuple[str, str]] = field(default_factory=list)
    elapsed: float = 0.0
    executor: str = ""
    interrupted: bool = False

    @property
    def done(self) -> int:
        """Cases finished in total."""
        return self.done_before + self.done_now

    @property
    def complete(self) -> bool:
        """Every case finished."""
        return self.done == self.total


def load_experiment(path: str | Path) -> Experiment:
    """Read, validate and expand an experiment file (every scene of the grid is checked).

    Raises
    ------
    ExperimentError
        Naming the field and the allowed values.
    """
    definition, text = load_definition(path)
    experiment = Experiment(definition, text, Path(path).parent, str(path))
    experiment.validate()
    return experiment


def default_store(experiment_path: str | Path) -> Path:
    """The default store of an experiment file: beside it, suffix ``.nc``."""
    return Path(experiment_path).with_suffix(".nc")


def run_experiment(
    experiment: Experiment,
    store: str | Path | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    restart: bool = False,
    progress: bool = True,
    checkpoint: float = 30.0,
    batch_size: int | None = None,
) -> RunReport:
    """Run the missing cases of an experiment into its store.

    Parameters
    ----------
    experiment : Experiment
        From :func:`load_experiment`.
    store : str or Path, optional
        Store file (default: beside the experiment file, ``.nc``).
    workers : int, optional
        Local dask worker processes (default: the machine's cores); 0 runs
        every case in this process, without dask.
    scheduler : str, optional
        Address of an existing dask.distributed scheduler (``tcp://host:port``).
    restart : bool
        Discard an existing store and its parts (also one of another definition).
    progress : bool
        Show a progress bar on stderr.
    checkpoint : float
        Seconds between rebuilds of the store file during the run.
    batch_size : int, optional
        Cases per dask task (default: chosen from the number of cases and workers).

    Returns
    -------
    RunReport

    Raises
    ------
    ExperimentError
        Before any case runs: a bad motion, an unreadable store, a store of
        another definition (without ``restart``), or a store being written by
        another run. The existing store is then left unchanged.
    """
    started = time.monotonic()
    store = Path(store) if store is not None else default_store(experiment.path or f"{experiment.name}.toml")
    motions = resolve_motions(experiment)
    if not restart:
        check_store(store, experiment.sha256)
    elif store.is_dir():
        raise ExperimentError(f"{store}: is a folder; --store must name a file")
    parts_folder(store).mkdir(parents=True, exist_ok=True)
    lock = FolderLock(parts_folder(store))
    if not lock.acquire():
        raise ExperimentError(f"{store}: another run is writing this store (its parts folder is locked)")
    with lock, _interrupts() as stop:
        if restart:
            clear_store(store)
        remove_temporaries(parts_folder(store))
        session = StoreSession.create(store, experiment, {label: m.grid for label, m in motions.items()})
        session.load(remove_unreadable=True)
        missing = [c for c in experiment.cases if c.case_id not in session.results]
        report = RunReport(store, len(experiment.cases), len(experiment.cases) - len(missing))
        report.executor = _describe_executor(workers, scheduler)
        append_run(session.folder, {"started": now(), "machine": machine(), "executor": report.executor, "stochpound_version": __version__, "git_commit": git_commit()})
        session.rebuild()
        bar = _progress_bar(report, experiment.name, progress)
        last_checkpoint = time.monotonic()
        try:
            batches = make_batches(experiment, missing, motions, batch_size or _auto_batch(len(missing), workers))
            for outcomes in execute(batches, motions, workers, scheduler):
                for outcome in outcomes:
                    if outcome.arrays is not None or not stop.requested:
                        _record(session, report, outcome)
                if stop.requested:
                    raise KeyboardInterrupt
                bar.update(sum(1 for o in outcomes if o.arrays is not None))
                if time.monotonic() - last_checkpoint > checkpoint:
                    session.rebuild()
                    last_checkpoint = time.monotonic()
        except KeyboardInterrupt:
            report.interrupted = True
        finally:
            bar.close()
            session.rebuild()
            report.elapsed = time.monotonic() - started
    return report


def _record(session: StoreSession, report: RunReport, outcome: CaseOutcome) -> None:
    case = session.experiment.case_index[outcome.case_id]
    if outcome.arrays is None:
        report.failed.append((case.describe(), outcome.error or ""))
        return
    meta = {"case_id": case.case_id, "kind": case.kind, "labels": json.loads(canonical_json(dict(case.labels))), "stochpound_version": __version__}
    write_part(session.folder, case.case_id, meta, outcome.arrays)
    session.results[case.case_id] = outcome.arrays
    report.done_now += 1


@dataclass(frozen=True)
class Batch:
    """Cases that run together in one task: one motion source, and for an ensemble one grid point."""

    label: str
    tasks: tuple[CaseTask, ...]


def make_batches(experiment: Experiment, cases: Sequence[Case], motions: dict[str, ResolvedMotion], size: int) -> list[Batch]:
    """Group cases into batches of at most ``size`` that share their motion source.

    Records batch consecutive grid points; an ensemble batches consecutive
    realizations of one grid point (the shape a batched ensemble solver wants).
    """
    order = list(experiment.motions)

    def key(case: Case) -> tuple:
        labels = case.label_dict
        return (order.index(labels["record"]), case.kind != REFERENCE, case.position)

    batches: list[Batch] = []
    current: list[CaseTask] = []
    current_key: tuple | None = None
    for case in sorted(cases, key=key):
        labels = case.label_dict
        synthetic = motions[labels["record"]].table is not None
        group = (labels["record"], case.kind, case.position[:-2] if synthetic else None)
        if current and (group != current_key or len(current) >= size):
            batches.append(Batch(current_key[0], tuple(current)))
            current = []
        current_key = group
        current.append(_task(experiment, case, motions[labels["record"]]))
    if current:
        batches.append(Batch(current_key[0], tuple(current)))
    return batches


def _task(experiment: Experiment, case: Case, motion: ResolvedMotion) -> CaseTask:
    labels = case.label_dict
    table = None if motion.table is None else {**motion.table, "realization": labels["realization"]}
    structure = experiment.structure(case)
    reference = structure if case.kind == REFERENCE else experiment.reference_structure(case)
    return CaseTask(
        case.case_id, case.kind, structure, reference, (labels["record"], labels["realization"]), table,
        experiment.studied, experiment.output, experiment.solver,
    )


def _auto_batch(n_cases: int, workers: int | None) -> int:
    slots = max(1, workers if workers else (os.cpu_count() or 1))
    return max(1, min(16, n_cases // (slots * 16)))


def execute(batches: Sequence[Batch], motions: dict[str, ResolvedMotion], workers: int | None, scheduler: str | None) -> Iterator[list[CaseOutcome]]:
    """Run batches and yield their outcomes as they finish (in any order).

    ``workers=0`` (and no scheduler) runs them in this process; otherwise on a
    local dask cluster of ``workers`` processes or on the given scheduler.
    """
    if not batches:
        return
    if workers == 0 and scheduler is None:
        for batch in batches:
            yield run_batch(batch.tasks, motions[batch.label].motion)
        return
    from distributed import as_completed

    with _dask_client(workers, scheduler) as client:
        shipped = {label: client.scatter(m.motion, broadcast=True, hash=False) for label, m in motions.items() if m.motion is not None}
        futures = {client.submit(run_batch, batch.tasks, shipped.get(batch.label), pure=False): batch for batch in batches}
        try:
            for future in as_completed(futures):
                batch = futures[future]
                try:
                    outcomes = future.result()
                except Exception as error:  # noqa: BLE001 - e.g. KilledWorker: report the batch's cases as failed
                    outcomes = [CaseOutcome(task.case_id, error=f"{type(error).__name__}: {error}") for task in batch.tasks]
                future.release()
                yield outcomes
        finally:
            client.cancel(list(futures))


@contextmanager
def _dask_client(workers: int | None, scheduler: str | None) -> Iterator[Any]:
    from distributed import Client, LocalCluster

    for name in ("distributed", "distributed.nanny", "distributed.worker", "distributed.scheduler", "distributed.core"):
        logging.getLogger(name).setLevel(logging.ERROR)
    if scheduler is not None:
        client = Client(scheduler, timeout="30s")
        try:
            yield client
        finally:
            client.close(timeout=10)
        return
    _compile_solver_once()
    cluster = LocalCluster(
        n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=logging.ERROR
    )
    client = Client(cluster)
    try:
        yield client
    finally:
        client.close(timeout=10)
        cluster.close(timeout=10)


def _compile_solver_once() -> None:
    """Compile the exact solver's kernels in this process before the local workers start.

    numba caches compiled kernels on disk (``cache=True``): compiled once here,
    every local worker loads them in about a second instead of compiling them
    concurrently.
    """
    from stochpound.solvers.exact import compile_engine

    compile_engine()


def _describe_executor(workers: int | None, scheduler: str | None) -> str:
    if scheduler is not None:
        return f"dask scheduler {scheduler}"
    if workers == 0:
        return "this process (no dask)"
    return f"local dask cluster, {workers or os.cpu_count() or 1} worker processes"


class _StopFlag:
    """Set by SIGINT/SIGTERM, in case the KeyboardInterrupt is swallowed (e.g. inside compiled code)."""

    requested = False


@contextmanager
def _interrupts() -> Iterator[_StopFlag]:
    """Treat SIGINT and SIGTERM as a request to stop: raise KeyboardInterrupt and remember it."""
    flag = _StopFlag()

    def handler(signum: int, frame: Any) -> None:
        flag.requested = True
        raise KeyboardInterrupt

    try:
        previous = {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    except ValueError:  # not the main thread
        yield flag
        return
    try:
        yield flag
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


class _NoBar:
    def update(self, n: int) -> None:
        pass

    def close(self) -> None:
        pass


def _progress_bar(report: RunReport, name: str, enabled: bool) -> Any:
    if not enabled:
        return _NoBar()
    from tqdm import tqdm

    return tqdm(total=report.total, initial=report.done_before, unit="case", desc=name, file=sys.stderr, smoothing=0.1, dynamic_ncols=True)
