"""What a run will cost, estimated before it starts: CPU time and the store's size.

``experiment run`` prints the estimate before anything is written and, above
:data:`LARGE_RUN_CASES` cases to run or :data:`LARGE_RUN_BYTES` of store,
asks for ``--yes`` (docs/experiments.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from stochpound.experiment._experiment import Experiment
from stochpound.store import KINDS, Point
from stochpound.experiment._spec import AUTO
from stochpound.experiment._file_layout import Layout, Spec, layout
from stochpound.experiment._file_assembly import file_bytes
from stochpound._memory import format_bytes
from stochpound.model.scene_file import scene_from_dict
from stochpound.solvers import first_call
from stochpound.solvers.first_call import compile_text

COMPILE = "compiling the solver"
"""The start-up step of compiling the exact solver into numba's empty cache."""
LARGE_RUN_CASES = 1_000_000
"""Above this many cases to run, ``experiment run`` asks for ``--yes``."""
LARGE_RUN_BYTES = 10 * 2**30
"""... or above this estimated size of the store file (10 GiB)."""
CPU_SECONDS_PER_SAMPLE = {"exact": 1.2e-5, "ivp": 2e-3}
"""CPU time of a case per sample of its motion, by solver (``auto``: the one each grid point's scene gets). The exact
solver's is measured on a whole experiment, not on the engine alone: the earlier flagship stochastic study ran 81 000
cases of 1001 samples in 8.1 min on 2 cores, 12 ms of CPU a case with its summaries, parts and fixed-base twin (the
engine alone takes 0.09–0.2 ms per second of motion, docs/benchmarks.md). The ivp solver's is a rough order of
magnitude (0.1 s of CPU per second of motion at 0.02 s)."""


@dataclass(frozen=True)
class RunEstimate:
    """The estimated cost of the cases still to run.

    Attributes
    ----------
    cases : int
        Cases to run.
    cpu_seconds : float
        Their CPU time (one core), s.
    store_bytes : int
        Size of the complete store file without its impact table (:func:`~stochpound.experiment._file_assembly.file_bytes`:
        measured on its metadata written in memory, time histories uncompressed), bytes; the parts folder holds about as much again.
        Unless ``store_measured``: its variables' data alone, uncompressed (a small run's, not worth the measurement's half second).
    history_bytes : int
        The time histories' part of ``store_bytes``, uncompressed (the file holds them compressed: usually less), bytes.
    startup : tuple of (str, float or None)
        The start-up steps before the first case runs, each with its duration last measured on this machine (s; None if never):
        compiling the solver (when numba's cache of it is empty), then the rest (:func:`startup_step`: loading it, the store,
        a local cluster), as the runner last timed them (:mod:`stochpound.solvers.first_call`).
    """

    cases: int
    cpu_seconds: float
    store_bytes: int
    history_bytes: int = 0
    startup: tuple[tuple[str, float | None], ...] = ()
    store_measured: bool = True

    @property
    def large(self) -> bool:
        """Above :data:`LARGE_RUN_CASES` cases or :data:`LARGE_RUN_BYTES` of store."""
        return self.cases > LARGE_RUN_CASES or self.store_bytes > LARGE_RUN_BYTES

    def describe(self, cores: int) -> str:
        """``1,000 cases to run: roughly 2 min on 2 cores after a start-up of about 9 s (...), store about 1.2 MiB (and as much again in its .parts folder)``."""
        wall = self.cpu_seconds / max(1, cores)
        size = f"about {format_bytes(self.store_bytes)}"
        if not self.store_measured:
            size += " of data before compression"
        elif self.history_bytes:
            size += f" or less ({format_bytes(self.history_bytes)} of it time histories before compression)"
        return (
            f"{self.cases:,} cases to run: roughly {_duration(wall)} on {cores} core{'s' if cores > 1 else ''}{self._startup_text()}, "
            f"store {size} (and as much again in its .parts folder)"
        )


    def _startup_text(self) -> str:
        """`` after a start-up of about 45 s (compiling the solver 38 s, starting 2 workers 7 s, as last timed here)``, or what is not yet timed."""
        if not self.startup:
            return ""
        if all(seconds is not None for _, seconds in self.startup):
            steps = ", ".join(f"{step} {_duration(seconds)}" for step, seconds in self.startup)
            return f" after a start-up of about {_duration(sum(s for _, s in self.startup))} ({steps}, as last timed on this machine)"
        steps = ", ".join(f"{step} ({_duration(seconds)} when last timed on this machine)" if seconds is not None else
                          f"{step} ({'not yet timed on this machine' if step != COMPILE else compile_text()})" for step, seconds in self.startup)
        return f" after a start-up: {steps}"


def estimate_run(experiment: Experiment, motion_grids: Mapping[str, tuple[float, int]], cases: int, workers: int = 0,
                 measure_store: bool = True) -> RunEstimate:
    """Estimate the cost of running ``cases`` of the experiment's cases (the missing ones).

    Parameters
    ----------
    experiment : Experiment
    motion_grids : mapping of str to (float, int)
        Sample spacing (s) and number of samples of each motion.
    cases : int
        Cases to run (their share of the experiment's samples is counted).
    workers : int
        Worker processes of the local cluster the run starts (0: none, the cases run in this process or on a scheduler's).
    measure_store : bool
        Measure the store file's size on its metadata written in memory (:func:`~stochpound.experiment._file_assembly.file_bytes`,
        about half a second); if False, the store's size is its variables' data, uncompressed (:attr:`RunEstimate.store_measured`).
    """
    store = layout(experiment, motion_grids, 0)
    histories = sum(_data_bytes(store, spec) for spec in store.of("history"))
    size = file_bytes(store, {"definition": experiment.definition_json}) if measure_store else sum(_data_bytes(store, spec) for spec in store.specs)
    return RunEstimate(cases, cpu_seconds(experiment, motion_grids, cases), size, histories, startup_steps(cases, workers), measure_store)


def _data_bytes(store: Layout, spec: Spec) -> int:
    """The bytes of a variable's data, uncompressed."""
    return spec.dtype.itemsize * math.prod(store.sizes[d] for d in spec.dims)


def startup_steps(cases: int, workers: int) -> tuple[tuple[str, float | None], ...]:
    """:attr:`RunEstimate.startup` of a run of ``cases`` cases on a local cluster of ``workers`` (0: none)."""
    startup = [(COMPILE, first_call.measured("compile"))] if cases and not first_call.engine_cached() else []
    if cases:
        startup.append((startup_step(workers), first_call.measured(startup_step(workers))))
    return tuple(startup)


def cpu_seconds(experiment: Experiment, motion_grids: Mapping[str, tuple[float, int]], cases: int) -> float:
    """The estimated CPU time (one core) of ``cases`` of the experiment's cases, s: their share of its samples at :data:`CPU_SECONDS_PER_SAMPLE`.

    Parameters
    ----------
    experiment : Experiment
    motion_grids : mapping of str to (float, int)
        Sample spacing (s) and number of samples of each motion.
    cases : int
        Cases to run.
    """
    per_point = sum(len(experiment.realizations(label)) * samples for label, (_, samples) in motion_grids.items())
    cpu = sum(per_point * CPU_SECONDS_PER_SAMPLE[_method(experiment, point)] for kind in KINDS for point in experiment.points(kind))
    return cpu * (cases / experiment.n_cases if experiment.n_cases else 0.0)


def startup_step(workers: int) -> str:
    """The start-up of a run besides a compile (loading the solver, the store, a local cluster of ``workers``), as it is timed and said."""
    return f"starting {workers} local worker{'s' if workers > 1 else ''} and the store" if workers else "opening the store and loading the solver"


def _method(experiment: Experiment, point: Point) -> str:
    """The solver of a grid point's cases: the experiment's, or with ``auto`` the one :func:`stochpound.simulate` picks."""
    method = experiment.solver.method
    if method != AUTO:
        return method
    scene = scene_from_dict(experiment.structure(point), base_dir=experiment.base_dir)
    return "ivp" if scene.nonlinear_laws() else "exact"


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{max(seconds, 1):.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    if seconds < 2 * 86400:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 86400:.1f} days"
