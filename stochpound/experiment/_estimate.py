"""What a run will cost, estimated before it starts: CPU time and the store's size.

``experiment run`` prints the estimate before anything is written and, above
:data:`LARGE_RUN_CASES` cases to run or :data:`LARGE_RUN_BYTES` of store,
asks for ``--yes`` (docs/experiments.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from stochpound.experiment._grid import KINDS, Experiment, Point
from stochpound.experiment._spec import AUTO
from stochpound.experiment._store import layout
from stochpound.experiment._store_writer import file_bytes
from stochpound._memory import format_bytes
from stochpound.model.scene_file import scene_from_dict
from stochpound.store import canonical_json

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
        Size of the complete store file without its impact table (:func:`~stochpound.experiment._store_writer.file_bytes`:
        measured on its metadata written in memory, time histories uncompressed), bytes; the parts folder holds about as much again.
    history_bytes : int
        The time histories' part of ``store_bytes``, uncompressed (the file holds them compressed: usually less), bytes.
    """

    cases: int
    cpu_seconds: float
    store_bytes: int
    history_bytes: int = 0

    @property
    def large(self) -> bool:
        """Above :data:`LARGE_RUN_CASES` cases or :data:`LARGE_RUN_BYTES` of store."""
        return self.cases > LARGE_RUN_CASES or self.store_bytes > LARGE_RUN_BYTES

    def describe(self, cores: int) -> str:
        """``1,000 cases to run: roughly 2 min on 2 cores, store about 1.2 MiB (and as much again in STORE.parts/)``."""
        wall = self.cpu_seconds / max(1, cores)
        size = f"about {format_bytes(self.store_bytes)}"
        if self.history_bytes:
            size += f" or less ({format_bytes(self.history_bytes)} of it time histories before compression)"
        return (
            f"{self.cases:,} cases to run: roughly {_duration(wall)} on {cores} core{'s' if cores > 1 else ''}, "
            f"store {size} (and as much again in its .parts folder)"
        )


def estimate_run(experiment: Experiment, motion_grids: Mapping[str, tuple[float, int]], cases: int) -> RunEstimate:
    """Estimate the cost of running ``cases`` of the experiment's cases (the missing ones).

    Parameters
    ----------
    experiment : Experiment
    motion_grids : mapping of str to (float, int)
        Sample spacing (s) and number of samples of each motion.
    cases : int
        Cases to run (their share of the experiment's samples is counted).
    """
    per_point = sum(len(experiment.realizations(label)) * samples for label, (_, samples) in motion_grids.items())
    cpu = 0.0
    for kind in KINDS:
        for point in experiment.points(kind):
            cpu += per_point * CPU_SECONDS_PER_SAMPLE[_method(experiment, point)]
    share = cases / experiment.n_cases if experiment.n_cases else 0.0
    store = layout(experiment, motion_grids, 0)
    histories = sum(spec.dtype.itemsize * math.prod(store.sizes[d] for d in spec.dims) for spec in store.of("history"))
    return RunEstimate(cases, cpu * share, file_bytes(store, {"definition": canonical_json(experiment.definition)}), histories)


def _method(experiment: Experiment, point: Point) -> str:
    """The solver of a grid point's cases: the experiment's, or with ``auto`` the one :func:`stochpound.simulate` picks."""
    method = experiment.solver["method"]
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
