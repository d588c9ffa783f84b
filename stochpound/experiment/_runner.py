"""``experiment run``: the missing cases of an experiment, on dask, into its store.

The client (this process) validates everything, checks the store, writes the
store file once before the first case (a small run in this process: at its end only), submits batches of cases
(:mod:`stochpound.experiment._batches`) with a bounded number in flight,
writes finished cases to part files as results arrive (one per
:data:`~stochpound.experiment._parts.PART_REALIZATIONS` realizations or a few seconds),
rebuilds the store at checkpoints and at the end. Workers only compute
(:mod:`stochpound.experiment._compute`): they need the package, not the
store's file system. The client's memory does not grow with the number of
cases (beyond a few bytes per case for the grid's masks).
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import signal
import sys
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from multiprocessing import forkserver
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator

from stochpound import __version__
from stochpound._signals import handling
from stochpound.experiment._batches import automatic_size, make_batches
from stochpound.experiment._compute import BatchResult, BatchTask, run_batch, warm_up
from stochpound.experiment._estimate import LARGE_RUN_BYTES, LARGE_RUN_CASES, RunEstimate, cpu_seconds, estimate_run, startup_step, startup_steps
from stochpound.experiment._experiment import Experiment
from stochpound.experiment._parts import FolderLock, PartBuffer, RunEntry, append_run, parts_folder, remove_temporaries
from stochpound.experiment._session import (StoreSession, check_store, check_store_path, clear_store, code_identity, machine, missing_summaries, now,
                                           store_complete, stored_definition, stored_text)
from stochpound.experiment._sources import ResolvedMotion, resolve_motions
from stochpound.experiment._spec import ExperimentError, load_definition
from stochpound.experiment._file_assembly import PartsIndex
from stochpound._memory import format_bytes
from stochpound.solvers import first_call
from stochpound.store import NOT_IN_IDENTITY

CHECKPOINT_FACTOR = 20.0
"""A checkpoint waits at least this many times the last rebuild's duration (rebuilds cost at most ~5 % of a run)."""
IN_FLIGHT_PER_WORKER = 2
"""Batches submitted ahead per worker thread."""
CLUSTER_LOG_LEVEL = logging.CRITICAL
"""What dask's own logs print, in this process and in the local workers: nothing short of critical. A case's error
reaches this process as the exception of its future (and stops the run with its message); dask's logs are otherwise
its view of the cluster closing after a Ctrl-C (e.g. "Failed to communicate with scheduler during heartbeat", an ERROR record
written to the terminal after the run's last message, as its heartbeat races the scheduler's close)."""
LOCAL_CLUSTER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.admin.tick.interval": "500ms",
    "distributed.worker.multiprocessing-method": "forkserver",
}
"""dask settings of the local cluster: no statistical profiler in the workers (it samples their threads every
10 ms), slower system monitors and event-loop ticks: idle, the cluster takes about 3 % of a core instead of 13 %;
worker processes forked by multiprocessing's fork server (which ignores SIGINT: :func:`_start_fork_server`)."""
IN_PROCESS_CPU_SECONDS = 3.0
"""Below this estimated CPU time of its cases (:func:`~stochpound.experiment._estimate.cpu_seconds`), a run given
neither workers nor a scheduler runs in this process, without dask: starting local workers takes 3–4 s on an idle
2-core machine (they import their modules and load the compiled solver) and the estimate is low by up to a factor 2
on small runs, whose cases are short (docs/benchmarks.md, "Start-up"). The results are the same either way."""
WORKER_MODULES = ("distributed", "stochpound.experiment._compute")
"""The modules a local worker runs with, imported once by the fork server the workers are forked from (:func:`_start_fork_server`)."""


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
    setup : float
        Of which before the first batch was submitted (store checks and first
        write, the cluster's start, loading the compiled solver in every worker), s.
    executor : str
        Where the cases ran.
    interrupted : bool
        True if the run was stopped (Ctrl-C, SIGTERM).
    repaired : bool
        The store file was damaged and was rebuilt from the finished cases in its parts folder.
    nothing_to_run : bool
        The store was complete: nothing ran and nothing was written.
    """

    store: Path
    total: int
    done_before: int
    done_now: int = 0
    failed: list[tuple[str, str]] = field(default_factory=list)
    elapsed: float = 0.0
    setup: float = 0.0
    executor: str = ""
    interrupted: bool = False
    repaired: bool = False
    nothing_to_run: bool = False

    @property
    def done(self) -> int:
        """Cases finished in total."""
        return self.done_before + self.done_now

    @property
    def complete(self) -> bool:
        """Every case finished."""
        return self.done == self.total


def load_experiment(path: str | Path, *, seed: int | None = None) -> Experiment:
    """Read, validate and expand an experiment file (every scene of the grid is checked).

    Parameters
    ----------
    path : str or Path
        The experiment file.
    seed : int, optional
        Run it with this ``[intensity] seed`` (>= 0) instead of the file's: the seed of a conditional-spectrum selection,
        which chooses the stripes' motions and draws their simulated ones. The experiment's text is the file's with its
        seed line set (``stochpound experiment run --seed``; its store records that text); default store :func:`seed_store`.

    Raises
    ------
    ExperimentError
        Naming the field and the allowed values; with ``seed``, a file without a conditional-spectrum selection.
    """
    definition, text = load_definition(path, seed)
    experiment = Experiment(definition, text, Path(path).parent, str(path))
    experiment.seed_override = seed
    experiment.validate()
    return experiment


def default_store(experiment_path: str | Path) -> Path:
    """The default store of an experiment file: beside it, suffix ``.nc``."""
    return Path(experiment_path).with_suffix(".nc")


def seed_store(experiment_path: str | Path, seed: int) -> Path:
    """The default store of an experiment file run with another ``[intensity] seed``: ``seed<seed>/<its name>.nc`` beside it."""
    path = Path(experiment_path)
    return path.parent / f"seed{seed}" / path.with_suffix(".nc").name


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
    large_ok: bool = True,
    say: Callable[[str], None] | None = None,
) -> RunReport:
    """Run the missing cases of an experiment into its store.

    Parameters
    ----------
    experiment : Experiment
        From :func:`load_experiment`.
    store : str or Path, optional
        Store file (default: beside the experiment file, ``.nc``; :func:`seed_store` for an experiment loaded with another seed).
    workers : int, optional
        Local dask worker processes (default: the machine's cores, or none
        when the cases' CPU time is estimated under 3 s: a small run ends
        sooner in this process); 0 runs every case in this process, without dask.
    scheduler : str, optional
        Address of an existing dask.distributed scheduler (``tcp://host:port``).
    restart : bool
        Discard an existing store and its parts (also one of another definition).
    progress : bool
        Show a progress bar on stderr.
    checkpoint : float
        Least number of seconds between rebuilds of the store file during the
        run (and at least ``CHECKPOINT_FACTOR`` times the last rebuild's duration).
    batch_size : int, optional
        Cases per dask task (default: ``stochpound.experiment._batches.automatic_size``).
    large_ok : bool
        Run a large experiment (``RunEstimate.large`` of ``stochpound.experiment._estimate``);
        if False, one is refused before anything is written (``experiment run`` without ``--yes``).
    say : callable, optional
        Called with a line about each step of the start-up (the estimate, the
        cluster's start, the solver's compilation), as it begins.

    Returns
    -------
    RunReport

    Raises
    ------
    ExperimentError
        Before any case runs: a bad motion, a store path that is an input of the
        run (the experiment file, its scene, record or hazard file), a file that is
        not a store without parts to rebuild it from (``restart`` discards only a
        store), a store of another definition (without ``restart``), a store being written by another run, or a large
        experiment without ``large_ok``. The existing store is then left unchanged.
    OSError
        If the store's folder cannot be written.

    Notes
    -----
    A store whose file says every case is done is left as it is: no cluster
    starts and nothing runs (``nothing_to_run``); only when its definition's
    entries outside the identity (the ``[hazard]``) or its text alone (comments) changed is it rewritten
    from its parts with the new ones (its runs kept).
    """
    started = time.monotonic()
    quiet = say is None
    say = say or (lambda message: None)
    source = experiment.path or f"{experiment.name}.toml"
    seed = experiment.seed_override
    store = Path(store) if store is not None else default_store(source) if seed is None else seed_store(source, seed)
    check_store_path(store, experiment, restart)
    motions = resolve_motions(experiment)
    repair = False
    if not restart:
        repair = check_store(store, experiment.sha256)
        if store.is_file() and not repair and store_complete(store):
            if FolderLock(parts_folder(store)).held():
                raise _busy(store)
            missing = missing_summaries(store, experiment, {label: m.grid for label, m in motions.items()})
            if missing:
                raise ExperimentError(f"{store}: written by an earlier stochpound without {', '.join(missing)}, which it keeps now: "
                                      "run the experiment again with --restart to recompute its cases")
            stored, new = stored_definition(store), json.loads(experiment.definition_json)
            # the scene's provenance alone (the same content, from another file or inline) leaves the store as it is
            changed = [key for key in NOT_IN_IDENTITY if key != "scene_source" and stored.get(key) != new.get(key)]
            if stored_text(store) != experiment.text:  # the same definition, another text (comments): the store records the
                changed.append("text")  # file's text and path
            if changed:
                _record_hazard(store, experiment, {label: m.grid for label, m in motions.items()}, say, changed)
            return RunReport(store, experiment.n_cases, experiment.n_cases, elapsed=time.monotonic() - started, nothing_to_run=True)
    elif store.is_dir():
        raise ExperimentError(f"{store}: is a folder; --store must name a file")
    grids = {label: m.grid for label, m in motions.items()}
    checked = _check_size(experiment, grids, store, restart, large_ok, _cores(workers, scheduler), workers is None and scheduler is None)
    parts_folder(store).mkdir(parents=True, exist_ok=True)
    lock = FolderLock(parts_folder(store))
    if not lock.acquire():
        raise _busy(store)
    with lock, _interrupts() as stop:
        if restart:
            clear_store(store)
        remove_temporaries(parts_folder(store))
        session = StoreSession.create(store, experiment, grids)
        session.scan(remove_unreadable=True)
        report = RunReport(store, experiment.n_cases, session.index.n_done, repaired=repair)
        small = workers is None and scheduler is None and in_process(experiment, grids, report.total - report.done_before)
        workers = 0 if small else workers
        if _local_workers(workers, scheduler):
            _start_fork_server()  # it imports the workers' modules while this process writes the store and compiles the solver
        report.executor = _describe_executor(workers, scheduler) + (" for a small run" if small else "")
        if repair:
            say(f"{store}: damaged; rebuilding it from the {report.done_before} finished cases in {session.folder.name}/")
        if report.done_before < report.total and not quiet:  # the estimate measures the store's size: only for someone to read it
            say(_estimate(experiment, grids, report.total - report.done_before, _local_workers(workers, scheduler), checked, small)
                .describe(_cores(workers, scheduler)))
        if small:
            say("running in this process, without dask: a run this small ends sooner than local workers would start (--workers N starts N)")
        cold = not first_call.engine_cached()
        identity = code_identity()
        append_run(session.folder, RunEntry(now(), machine(), report.executor, **identity))
        missing = session.missing()
        if not small:  # a small run's store is written at its end (its parts keep the finished cases meanwhile)
            session.rebuild()
        checkpoints = _Checkpoints(checkpoint, session)
        bar: Any = _NoBar()
        realizations = sum(len(experiment.realizations(label)) for label in experiment.motions)
        meta = {"stochpound_version": __version__, "sources_sha256": identity["sources_sha256"]}
        buffer = PartBuffer(session.folder, meta, experiment.n_cases / realizations)

        def ready() -> None:
            nonlocal bar
            report.setup = time.monotonic() - started
            compiled = first_call.measured("compile") if cold else 0.0  # timed as it happened: the rest is the start-up of any run
            first_call.record(startup_step(_local_workers(workers, scheduler)), report.setup - (compiled or 0.0))
            bar = _progress_bar(report, experiment.name, progress)  # after the start-up's messages

        try:
            size = batch_size or automatic_size(experiment.n_cases - report.done_before, workers)
            batches = make_batches(experiment, missing, motions, size)
            with contextlib.closing(execute(batches, experiment, motions, workers, scheduler, ready, say)) as results:
                for task, result in results:
                    _record(experiment, report, buffer, task, result)
                    if stop.requested:
                        raise KeyboardInterrupt
                    bar.update(result.done)
                    if checkpoints.due():
                        buffer.flush()
                        checkpoints.start()
        except KeyboardInterrupt:
            report.interrupted = True
        finally:
            bar.close()  # first: an error below is printed on a line of its own, not on the bar's
            buffer.flush()
            checkpoints.wait()
            session.rebuild()
            report.elapsed = time.monotonic() - started
            report.setup = report.setup or report.elapsed  # stopped before the first batch: all of it was start-up
    return report


def _record_hazard(store: Path, experiment: Experiment, grids: dict[str, tuple[float, int]], say: Callable[[str], None],
                   changed: list[str]) -> None:
    """Rewrite a complete store from its parts with the experiment's hazard, design and text (``changed``: no run depends on them: the runs are kept)."""
    lock = FolderLock(parts_folder(store))
    if not lock.acquire():
        raise _busy(store)
    with lock:
        session = StoreSession.create(store, experiment, grids)
        if session.scan().n_done < experiment.n_cases:  # its parts folder lost cases: rewriting would lose them
            raise ExperimentError(f"{store}: the {' and the '.join(changed)} changed, but {session.folder.name}/ lacks finished cases to rewrite the store from; "
                                  "keep the store as it is, or run again with --restart")
        session.rebuild()
    for table in ("design", "limit_states"):
        if table in changed:
            say(f"{store}: the [{table}] changed; no run depends on it: the cases are kept and the new table is recorded in the store")
    if "text" in changed:
        say(f"{store}: the experiment file's text changed, not its definition's identity (comments, the scene's source); the cases are kept "
            "and the new text and its file's path are recorded in the store")
    if "site" in changed:
        say(f"{store}: how the [site] scenario was obtained is recorded in the store (no run depends on it: the cases are kept)")
    if "hazard" not in changed:
        return
    hazard = experiment.definition.hazard
    what = "removed" if hazard is None else f"from {hazard.file or hazard.bundled or 'a power law'}" + (f" (sha256 {hazard.file_sha256[:12]}…)" if hazard.file_sha256 else "")
    say(f"{store}: the hazard changed ({what}); no run depends on it: the cases are kept and the new curve is recorded in the store")


def _busy(store: Path) -> ExperimentError:
    return ExperimentError(f"{store}: another run is writing this store (its parts folder is locked)")


def _check_size(experiment: Experiment, grids: dict[str, tuple[float, int]], store: Path, restart: bool, large_ok: bool,
                cores: int, default_workers: bool) -> RunEstimate | None:
    """Refuse a large run (:attr:`RunEstimate.large`, its finished cases not counted) unless ``large_ok``; the estimate made (None if none).

    A run small enough to run in this process with the ``default_workers`` (:func:`in_process`, all its cases
    counted) gets the estimate without the store's measured size (:func:`_estimate`).
    """
    if large_ok:
        return None
    estimate = estimate_run(experiment, grids, experiment.n_cases, measure_store=not (default_workers and in_process(experiment, grids, experiment.n_cases)))
    if estimate.large and not restart and parts_folder(store).is_dir():
        estimate = estimate_run(experiment, grids, experiment.n_cases - PartsIndex.scan(experiment, parts_folder(store)).n_done)
    if estimate.large:
        raise ExperimentError(
            f"{experiment.path or experiment.name}: {estimate.describe(cores)}; "
            f"above {LARGE_RUN_CASES:,} cases or {format_bytes(LARGE_RUN_BYTES)} of store: give --yes to run it"
        )
    return estimate


def _estimate(experiment: Experiment, grids: dict[str, tuple[float, int]], cases: int, workers: int, checked: RunEstimate | None,
              small: bool) -> RunEstimate:
    """The estimate of a run of ``cases`` cases on ``workers`` local workers: :func:`_check_size`'s (``checked``) when it counted
    as many cases (the store's size is measured once), with this run's start-up steps. A ``small`` run's (run in this process
    by default, :func:`in_process`) does not measure the store's size: its data's is given (half a second less start-up)."""
    if checked is None or checked.cases != cases:
        return estimate_run(experiment, grids, cases, workers, measure_store=not small)
    return replace(checked, startup=startup_steps(cases, workers))


def _record(experiment: Experiment, report: RunReport, buffer: PartBuffer, task: BatchTask, result: BatchResult) -> None:
    """Queue a batch's finished cases for the next part; note its failures."""
    buffer.add(result.arrays)
    report.done_now += result.done
    for kind, position, error in result.failures:
        report.failed.append((experiment.case_at(kind, position).describe(), error))


class _Checkpoints:
    """Rebuilds of the store during a run, in a background thread (batches go on being submitted meanwhile):
    ``interval`` s after the previous one ended, and at least :data:`CHECKPOINT_FACTOR` times its duration.

    The rebuild reads only complete parts (written atomically), so parts may
    be written while it runs. An error in it is raised in the run at the next
    :meth:`due` or :meth:`wait`.
    """

    def __init__(self, interval: float, session: StoreSession) -> None:
        self.interval = interval
        self.session = session
        self.next = time.monotonic() + interval
        self.thread: threading.Thread | None = None
        self.error: BaseException | None = None

    def due(self) -> bool:
        """No rebuild running and its time has come (raises a failed rebuild's error)."""
        self._raise()
        return (self.thread is None or not self.thread.is_alive()) and time.monotonic() >= self.next

    def start(self) -> None:
        """Start a rebuild."""
        self.thread = threading.Thread(target=self._rebuild, name="stochpound-checkpoint", daemon=True)
        self.thread.start()

    def wait(self) -> None:
        """Wait for a running rebuild to end (raises its error)."""
        if self.thread is not None:
            self.thread.join()
        self._raise()

    def _rebuild(self) -> None:
        started = time.monotonic()
        try:
            self.session.rebuild()
        except BaseException as error:  # noqa: BLE001 - handed to the run's thread
            self.error = error
        finished = time.monotonic()
        self.next = finished + max(self.interval, CHECKPOINT_FACTOR * (finished - started))

    def _raise(self) -> None:
        if self.error is not None:
            error, self.error = self.error, None
            raise error


def execute(
    batches: Iterable[BatchTask],
    experiment: Experiment,
    motions: dict[str, ResolvedMotion],
    workers: int | None,
    scheduler: str | None,
    ready: Callable[[], None] = lambda: None,
    say: Callable[[str], None] = lambda message: None,
) -> Iterator[tuple[BatchTask, BatchResult]]:
    """Run batches and yield (task, result) as they finish (in any order); call ``ready()`` before the first is submitted.

    ``say`` is called with a line as each step of the start-up begins.

    On dask, every worker first loads the compiled solver (:func:`~stochpound.experiment._compute.warm_up`).

    ``workers=0`` (and no scheduler) runs them in this process; otherwise on a
    local dask cluster of ``workers`` processes or on the given scheduler,
    with at most :data:`IN_FLIGHT_PER_WORKER` batches per worker thread
    submitted ahead (the batches are made as they are submitted). A batch
    whose task fails as a whole (e.g. its worker died) is reported as failed
    for each of its cases.
    """
    labels = list(experiment.motions)
    spectrum = experiment.intensity is not None  # the kernels the batches run (stochpound.experiment._compute.warm_up)
    if workers == 0 and scheduler is None:
        _warm_up(say, spectrum)  # the compile on a cold cache is start-up, not the first batch's time
        ready()
        for task in batches:
            yield task, run_batch(task, motions[labels[task.record]].motion)
        return
    from distributed import as_completed

    with _dask_client(workers, scheduler, say, spectrum) as client:
        shipped = {m: client.scatter(motions[label].motion, broadcast=True, hash=False) for m, label in enumerate(labels) if motions[label].motion is not None}
        ahead = IN_FLIGHT_PER_WORKER * max(1, sum(client.nthreads().values()))
        pending = iter(batches)
        tasks: dict[Any, BatchTask] = {}
        running = as_completed()
        ready()

        def submit() -> None:
            task = next(pending, None)
            if task is not None:
                future = client.submit(run_batch, task, shipped.get(task.record), pure=False)
                tasks[future] = task
                running.add(future)

        try:
            for _ in range(ahead):
                submit()
            for future in running:
                task = tasks.pop(future)
                try:
                    result = future.result()
                except Exception as error:  # noqa: BLE001 - e.g. KilledWorker: the batch's cases are reported as failed
                    message = f"{type(error).__name__}: {error}"
                    result = BatchResult(failures=[(g.kind, tuple(int(i) for i in p), message) for g in task.groups for p in g.positions])
                future.release()
                submit()
                yield task, result
        finally:
            client.cancel(list(tasks))


def _warm_up(say: Callable[[str], None], spectrum: bool) -> None:
    """Compile the kernels the batches run in this process (a log line says so, and the compile is timed) or load them from numba's cache."""
    if first_call.engine_cached():
        say("loading the compiled solver…")
    with first_call.announced_compile():
        warm_up(spectrum)


def _start_fork_server() -> None:
    """Start multiprocessing's fork server, which forks the local workers, unless it runs: it imports :data:`WORKER_MODULES` once.

    Each worker forked from it starts with them imported, instead of importing
    them itself (seconds of CPU each). The server starts at once and imports
    them in the background, while this process goes on (writing the store,
    compiling the solver); it is started while SIGINT is ignored: it, and every
    worker process it forks, inherit the ignored SIGINT. A Ctrl-C in a
    terminal reaches every process of the foreground group; the workers then
    stop with the cluster instead of printing their own tracebacks. Ignoring
    lasts as long as the fork server's fork and exec (milliseconds, once per
    process): a Ctrl-C then is lost.
    """
    with handling(signal.SIG_IGN):
        forkserver.set_forkserver_preload(["__main__", *WORKER_MODULES])  # "__main__": multiprocessing's default
        forkserver.ensure_running()


def _load_solver(client: Any, spectrum: bool, one_per_host_first: bool) -> Any:
    """Have every worker of ``client`` compile or load the batches' kernels (:func:`~stochpound.experiment._compute.warm_up`).

    ``one_per_host_first``: one worker of each host first, then the others,
    which then load from numba's cache what the first compiled (a cluster
    this process did not start, whose caches may be cold); otherwise all at
    once (local workers, which load what this process compiled).
    """
    from distributed import wait

    workers = client.scheduler_info()["workers"]
    first: dict[str, str] = {}
    for address, info in workers.items():
        first.setdefault(info.get("host", address) if one_per_host_first else address, address)
    for group in (list(first.values()), [address for address in workers if address not in first.values()]):
        wait([client.submit(warm_up, spectrum, pure=False, workers=[address]) for address in group])
    return client


@contextmanager
def _dask_client(workers: int | None, scheduler: str | None, say: Callable[[str], None], spectrum: bool = True) -> Iterator[Any]:
    """A client whose workers have loaded the compiled solver (with the spectrum's kernel if ``spectrum``): of the scheduler, or of a local cluster."""
    import dask
    from distributed import Client, LocalCluster

    for name in ("distributed", "distributed.nanny", "distributed.worker", "distributed.scheduler", "distributed.core"):
        logging.getLogger(name).setLevel(CLUSTER_LOG_LEVEL)
    if scheduler is not None:
        say(f"connecting to the dask scheduler {scheduler}…")
        client = Client(scheduler, timeout="30s")
        try:
            yield _load_solver(client, spectrum, one_per_host_first=True)
        finally:
            client.close(timeout=10)
        return
    _start_fork_server()  # started by the run already, unless _dask_client is called on its own
    _warm_up(say, spectrum)  # before the workers start: they load what it compiles
    n_workers = workers or os.cpu_count() or 1
    say(f"starting a local dask cluster ({n_workers} worker{'s' if n_workers > 1 else ''})…")
    cluster = client = None
    requested: list[int] = []
    try:
        # a SIGINT during the cluster's start (which an exception would leave half made) is raised once it can be closed
        with dask.config.set(LOCAL_CLUSTER_CONFIG), handling(lambda signum, frame: requested.append(signum)):
            cluster = LocalCluster(  # its HTTP server on a free port (the default, 8787, may be taken: a warning)
                n_workers=n_workers, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=CLUSTER_LOG_LEVEL
            )
        if requested:
            raise KeyboardInterrupt
        client = _load_solver(Client(cluster), spectrum, one_per_host_first=False)
        yield client
    finally:
        if client is not None:
            client.close(timeout=10)
        if cluster is not None:
            cluster.close(timeout=10)


def in_process(experiment: Experiment, grids: dict[str, tuple[float, int]], cases: int) -> bool:
    """True if ``cases`` of the experiment take less CPU time than :data:`IN_PROCESS_CPU_SECONDS` (estimated): the
    run then ends sooner in this process than on local workers, which take seconds to start (the default's choice)."""
    return cpu_seconds(experiment, grids, cases) < IN_PROCESS_CPU_SECONDS


def _local_workers(workers: int | None, scheduler: str | None) -> int:
    """Worker processes of the local cluster a run starts (0: it runs in this process, or on a scheduler's cluster)."""
    if scheduler is not None or workers == 0:
        return 0
    return workers or os.cpu_count() or 1


def _cores(workers: int | None, scheduler: str | None) -> int:
    """Cores the cases run on: the local workers (this machine's cores for a scheduler's unknown cluster)."""
    if workers == 0 and scheduler is None:
        return 1
    return workers or os.cpu_count() or 1


def _describe_executor(workers: int | None, scheduler: str | None) -> str:
    if scheduler is not None:
        return f"dask scheduler {scheduler}"
    if workers == 0:
        return "this process (no dask)"
    return f"local dask cluster, {_cores(workers, scheduler)} worker processes"


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

    with handling(handler, (signal.SIGINT, signal.SIGTERM)):
        yield flag


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
