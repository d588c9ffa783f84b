"""``experiment run`` of a rare-event experiment: subset simulation level by level, its chains in batches, into a resumable store.

Each level's chains (level 0's samples) are split into batches of about
:data:`RUNS_PER_BATCH` runs, the same split every time; a batch runs in this
process or on a dask worker. With adaptive conditional sampling
(``proposal = "acs"``) a level's chains run in adaptation groups, one after
the other (the batches of a group together): a group's spread follows from
the acceptance of the level's earlier groups, read from their batch files,
and from λ at the end of the previous level, kept in its level file (the experiments' cluster,
:mod:`stochpound.experiment._runner`) and is written to the parts folder as
it finishes (:mod:`stochpound.experiment._rare_event_store`). A level whose
batches are all written is written as a level file, which names the next
level's threshold and seeds. An interrupted run resumes at the batches
missing from the level under way; every chain draws from a generator of its
own (``stochpound.analysis.SubsetSampler``), so the store is the same,
bit for bit, whatever the workers, the batches' order and the interruptions.
"""

from __future__ import annotations

import functools
import json
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np

from stochpound.analysis import INITIAL_SCALE, SubsetLevel, SubsetSampler, scene_response
from stochpound.experiment._parts import FolderLock, parts_folder
from stochpound.experiment._runner import _describe_executor, _interrupts
from stochpound.experiment._rare_event_store import (
    DEFINITION_FILE, FinishedLevel, batch_path, finished_levels, load_arrays, save_arrays, save_level, stored_definition, write_store,
)
from stochpound.experiment._rare_event_table import CLOSURES, RareEventDefinition
from stochpound.experiment._spec import ExperimentError
from stochpound.model.scene_file import scene_from_dict
from stochpound.store import canonical_json, with_motion, with_open_gaps

RUNS_PER_BATCH = 100
"""Runs a batch takes (level 0: samples; a level of chains: chains × states a chain): part of the definition of the split."""


@dataclass(frozen=True)
class RareEventTask:
    """One batch: chains ``first`` .. ``first + len(y) − 1`` (or level 0's samples) of level ``level``, started at ``u``
    (``spread``: aCS's σ of their adaptation group)."""

    definition: str
    level: int
    first: int
    count: int
    threshold: float = -np.inf
    u: np.ndarray | None = None
    y: np.ndarray | None = None
    spread: np.ndarray | None = None


@dataclass
class RareEventReport:
    """What a rare-event run did: the store, the levels and batches finished before and by it, and its wall time (s)."""

    store: Path
    levels: int = 0
    batches_before: int = 0
    batches_now: int = 0
    runs: int = 0
    complete: bool = False
    interrupted: bool = False
    elapsed: float = 0.0
    executor: str = ""


@functools.lru_cache(maxsize=4)
def _sampler(definition: str) -> tuple[SubsetSampler, str]:
    """The sampler of a canonical definition's JSON (cached: a worker builds it once), and the response's units."""
    typed = RareEventDefinition.from_dict(json.loads(definition))
    table, scene = typed.table, typed.scene
    if table.response in CLOSURES:  # the contact-free pair: its closure does not depend on the gap
        scene = with_open_gaps(scene)
    function, n, units = scene_response(scene_from_dict(with_motion(scene)), typed.motion, table.sampled, table.building, table.floor,
                                        table.contact or 0)
    if table.capacity is not None:
        capacity, demand = table.capacity, function
        function, units = (lambda u: demand(u) / capacity), "1"
    return SubsetSampler(function, n, table.samples_per_level, table.p0, table.seed, table.proposal), units


def rare_event_sampler(definition: RareEventDefinition) -> SubsetSampler:
    """The sampler of a rare-event experiment: its response as a function of the motion's normals, N, p0 and seed.

    Its ``start`` (level 0's independent samples), on a sampler of another
    seed, gives crude Monte Carlo of the same response.
    """
    return _sampler(canonical_json(definition.to_dict()))[0]


def run_batch(task: RareEventTask) -> dict[str, np.ndarray]:
    """Run one batch: its responses (chains, states), accepted moves and the normals of its states that may seed the next level."""
    sampler, _ = _sampler(task.definition)
    if task.level == 0:
        u, y = sampler.start(range(task.first, task.first + task.count))
        states, responses, accepted = u[:, None, :], y[:, None], 0
    else:
        run = sampler.advance(task.level, task.u, task.y, task.threshold, range(task.first, task.first + task.count), task.spread)
        states, responses, accepted = run.states, run.responses, run.accepted
    flat = responses.reshape(-1)
    keep = min(sampler.chains, flat.size)
    candidates = np.flatnonzero(flat >= np.sort(flat)[::-1][keep - 1])  # the batch's p0·N largest, ties included: the level's seeds are among them
    return {"responses": responses, "accepted": np.int64(accepted), "candidates": candidates + task.first * responses.shape[1],
            "candidate_states": states.reshape(flat.size, -1)[candidates]}


def run_rare_event(definition: RareEventDefinition, store: str | Path | None = None, *, workers: int | None = 0, scheduler: str | None = None,
                   restart: bool = False, say: Callable[[str], None] | None = None, stop_after: int | None = None) -> RareEventReport:
    """Run a rare-event experiment into its store, resuming a run interrupted earlier.

    Parameters
    ----------
    definition : RareEventDefinition
        From :func:`~stochpound.experiment.load_rare_event`.
    store : str or Path, optional
        The store file (default: beside the experiment file, ``.nc``).
    workers : int, optional
        Local dask worker processes; 0 (the default) runs the batches in this process.
    scheduler : str, optional
        Address of an existing dask.distributed scheduler.
    restart : bool
        Discard the store and its parts first.
    say : callable, optional
        Called with a line about each level.
    stop_after : int, optional
        Stop (as if interrupted) after this many batches: for tests of resuming.

    Raises
    ------
    ExperimentError
        A store of another definition (without ``restart``), or one being written by another run.
    """
    started, say = time.monotonic(), say or (lambda message: None)
    store = Path(store) if store is not None else Path(definition.path or definition.name).with_suffix(".nc")
    text = canonical_json(definition.to_dict())
    folder = parts_folder(store)
    folder.mkdir(parents=True, exist_ok=True)
    lock = FolderLock(folder)
    if not lock.acquire():
        raise ExperimentError(f"{store}: another run is writing this store (its parts folder is locked)")
    report = RareEventReport(store, executor=_describe_executor(workers or 0 if scheduler is None else None, scheduler))
    with lock, _interrupts():
        if restart:
            for path in [*folder.glob("*.npz"), folder / DEFINITION_FILE, store]:
                path.unlink(missing_ok=True)
        known = stored_definition(store)
        if known is not None and canonical_json(known) != text:
            raise ExperimentError(f"{store}: made by another definition (its [rare_event], scene or motion differ); give --restart to discard it")
        (folder / DEFINITION_FILE).write_text(text)
        sampler, units = _sampler(text)
        levels = finished_levels(store)
        report.batches_before = len(list(folder.glob("batch-*.npz")))
        try:
            with _Executor(workers, scheduler, say) as execute:
                while not levels or levels[-1].next_threshold is not None:
                    if stop_after is not None and report.batches_now >= stop_after:
                        raise KeyboardInterrupt
                    levels.append(_level(store, sampler, definition, levels, execute, report, stop_after))
                    last = levels[-1]
                    say(f"level {len(levels) - 1}: {last.runs} runs, "
                        + (f"next threshold {last.next_threshold:.6g} {units}" if last.next_threshold is not None else "the last level"))
        except KeyboardInterrupt:
            report.interrupted = True
        finally:
            levels = finished_levels(store)
            write_store(store, definition, levels, units)
    report.levels, report.runs = len(levels), int(sum(f.runs for f in levels))
    report.complete = bool(levels) and levels[-1].next_threshold is None
    report.elapsed = time.monotonic() - started
    return report


def _split(sampler: SubsetSampler, levels: list[FinishedLevel]) -> list[list[tuple[int, int, int]]]:
    """The level under way's batches, (number, first, count), in its groups (level 0: one group of its samples)."""
    if not levels:
        groups, per = [range(sampler.samples_per_level)], RUNS_PER_BATCH
    else:
        groups, per = sampler.groups(len(levels[-1].next_seeds)), max(1, RUNS_PER_BATCH // sampler.length)
    split, number = [], 0
    for group in groups:
        split.append([])
        for first in range(group.start, group.stop, per):
            split[-1].append((number, first, min(per, group.stop - first)))
            number += 1
    return split


def _tasks(store: Path, sampler: SubsetSampler, text: str, levels: list[FinishedLevel], batches: list[tuple[int, int, int]],
           spread: np.ndarray | None) -> list[tuple[int, RareEventTask]]:
    """The batches of one group of the level under way that are not yet written, with their numbers."""
    index, tasks = len(levels), []
    for number, first, count in batches:
        if batch_path(store, index, number).is_file():
            continue
        if index == 0:
            tasks.append((number, RareEventTask(text, 0, first, count)))
        else:
            previous = levels[-1]
            seeds = previous.next_seeds[first : first + count]
            tasks.append((number, RareEventTask(text, index, first, count, previous.next_threshold, previous.next_states[first : first + count],
                                                previous.level.responses.reshape(-1)[seeds], spread)))
    return tasks


def _level(store: Path, sampler: SubsetSampler, definition: RareEventDefinition, levels: list[FinishedLevel],
           execute: Callable[[list[tuple[int, RareEventTask]]], Iterator[tuple[int, dict[str, np.ndarray]]]], report: RareEventReport,
           stop_after: int | None) -> FinishedLevel:
    """Run the level under way's missing batches, then write the level (with the next level's seeds unless the target is reached)."""
    index = len(levels)
    text = canonical_json(definition.to_dict())
    scale = levels[-1].scale if levels else INITIAL_SCALE
    for group, batches in enumerate(_split(sampler, levels)):
        acs = sampler.proposal == "acs" and index > 0
        spread = sampler.spread(scale) if acs else None
        for number, result in execute(_tasks(store, sampler, text, levels, batches, spread)):
            save_arrays(batch_path(store, index, number), **result)
            report.batches_now += 1
            if stop_after is not None and report.batches_now >= stop_after:
                raise KeyboardInterrupt
        if acs:
            done = [load_arrays(batch_path(store, index, number)) for number, _, _ in batches]
            moves = sum(b["responses"].shape[0] for b in done) * (sampler.length - 1)
            scale = sampler.adapt(scale, sum(int(b["accepted"]) for b in done) / moves, group)
    batches = [load_arrays(path) for path in sorted(parts_folder(store).glob(f"batch-{index:02d}-*.npz"))]
    responses = np.concatenate([b["responses"] for b in batches])
    length = responses.shape[1]
    moves = len(responses) * (length - 1)
    seeds = np.full(len(responses), -1, dtype=np.int64) if index == 0 else levels[-1].next_seeds
    level = SubsetLevel(-np.inf if index == 0 else levels[-1].next_threshold, responses, sum(int(b["accepted"]) for b in batches) / moves if moves else 1.0,
                        None if index == 0 else seeds)
    finished = FinishedLevel(level, seeds, responses.size if index == 0 else moves, scale)
    subset = [f.level for f in levels] + [level]
    if not sampler.done(subset, None, definition.table.target_probability) and len(subset) < definition.table.max_levels:
        threshold, chosen = sampler.seeds(responses, index + 1)
        states = {int(i): row for b in batches for i, row in zip(b["candidates"], b["candidate_states"])}
        finished = replace(finished, next_threshold=threshold, next_seeds=chosen, next_states=np.stack([states[int(i)] for i in chosen]))
    save_level(store, index, finished)
    return finished


class _Executor:
    """A context giving ``execute(tasks)``: an iterator of (number, result) as batches finish, in this process or on dask."""

    def __init__(self, workers: int | None, scheduler: str | None, say: Callable[[str], None]) -> None:
        self.workers, self.scheduler, self.say, self.client = workers, scheduler, say, None

    def __enter__(self) -> Callable[[list[tuple[int, RareEventTask]]], Iterator[tuple[int, dict[str, np.ndarray]]]]:
        if self.workers or self.scheduler is not None:
            from stochpound.experiment._runner import _dask_client  # the experiments' cluster, its workers' solver loaded

            self.context = _dask_client(self.workers, self.scheduler, self.say, spectrum=False)
            self.client = self.context.__enter__()
        return self.execute

    def __exit__(self, *exc: Any) -> None:
        if self.client is not None:
            self.context.__exit__(*exc)

    def execute(self, tasks: list[tuple[int, RareEventTask]]) -> Iterator[tuple[int, dict[str, np.ndarray]]]:
        if self.client is None:
            for number, task in tasks:
                yield number, run_batch(task)
            return
        from distributed import as_completed

        futures = {self.client.submit(run_batch, task, pure=False): number for number, task in tasks}
        try:
            for future in as_completed(futures):
                yield futures[future], future.result()
        finally:
            self.client.cancel(list(futures))
