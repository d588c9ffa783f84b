"""Splitting the missing cases of an experiment into batches (the unit of work of a worker).

A batch is a range of realizations of one motion and the grid points that
run under them, references first: the realizations are generated once for
the batch and the fixed-base twins of all of them are computed together
(:mod:`stochpound.experiment._compute`). Batches are made lazily, in grid
order, so that the client never holds more than the batches in flight.

How a run is split does not change any result: every case depends only on
itself.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Iterator, Mapping

import numpy as np

from stochpound.experiment._compute import BatchTask, Group
from stochpound.experiment._intensity import task_settings
from stochpound.experiment._experiment import Experiment
from stochpound.store import CASE, KINDS, Point
from stochpound.experiment._sources import ResolvedMotion
from stochpound._memory import sample_bytes
from stochpound.model.scene_file import scene_from_dict

MAX_BATCH = 256
"""Largest automatic number of cases per batch."""
BATCH_BYTES = 256 * 2**20
"""Memory a batch's realizations may take on a worker (motions, twins, one run at a time), bytes."""
MIN_REALIZATIONS = 8
"""An ensemble's batches hold at least this many realizations (when the grid has many points)."""


@dataclass(frozen=True)
class _Point:
    point: Point
    structure: dict
    reference: dict


def automatic_size(n_missing: int, workers: int | None) -> int:
    """Cases per batch: about eight batches per worker slot, at most :data:`MAX_BATCH`."""
    slots = max(1, workers if workers else (os.cpu_count() or 1))
    return max(1, min(MAX_BATCH, n_missing // (slots * 8)))


def make_batches(experiment: Experiment, missing: Mapping[str, np.ndarray], motions: Mapping[str, ResolvedMotion], size: int) -> Iterator[BatchTask]:
    """The batches of the missing cases, lazily, in grid order.

    Parameters
    ----------
    experiment : Experiment
    missing : mapping
        For each kind, a bool array of its grid's shape: the cases to run.
    motions : mapping
        The resolved motions, by label.
    size : int
        Cases per batch (about).
    """
    points = [_Point(p, experiment.structure(p), experiment.reference_structure(p)) for kind in KINDS for p in experiment.points(kind)]
    settings = task_settings(experiment, {label: motion.expected_intensity for label, motion in motions.items()})
    for record, label in enumerate(experiment.motions):
        realizations = experiment.realization_numbers(label)
        columns = experiment.realization_positions(label)
        wanted = np.array([missing[p.point.kind][p.point.position + (record,)][columns] for p in points]).reshape(len(points), len(columns))
        active = np.flatnonzero(wanted.any(axis=1))
        if not len(active):
            continue
        chunk = _realizations_per_batch(experiment, motions[label], size, len(active), len(columns))
        per_batch = max(1, size // chunk)
        for start in range(0, len(columns), chunk):
            block = slice(start, start + chunk)
            rows = [i for i in active if wanted[i, block].any()]
            for first in range(0, len(rows), per_batch):
                groups = tuple(_group(points[i], record, realizations[block], columns[block], wanted[i, block]) for i in rows[first : first + per_batch])
                yield BatchTask(record, motions[label].table, groups, experiment.studied, experiment.output, experiment.solver, settings)


def _group(entry: _Point, record: int, realizations: np.ndarray, columns: np.ndarray, wanted: np.ndarray) -> Group:
    chosen = np.flatnonzero(wanted)
    point = entry.point
    positions = np.array([(*point.position, record, int(c)) for c in columns[chosen]], dtype=np.int64)
    return Group(point.kind, entry.structure, entry.reference, tuple(int(r) for r in realizations[chosen]), positions, point.labels)


def _realizations_per_batch(experiment: Experiment, motion: ResolvedMotion, size: int, n_points: int, n_realizations: int) -> int:
    """Realizations per batch: enough to fill a batch of ``size`` cases over ``n_points`` points (at least
    :data:`MIN_REALIZATIONS`), within :data:`BATCH_BYTES`."""
    wanted = max(math.ceil(size / n_points), MIN_REALIZATIONS)
    case = next(p for p in experiment.points(CASE))
    scene = scene_from_dict(experiment.structure(case))
    n_dof = sum(b.n_floors + (b.base is not None) for b in scene.buildings)
    per_realization = motion.grid[1] * sample_bytes(n_dof, len(scene.buildings), scene.max_floors, len(scene.contacts))
    return max(1, min(n_realizations, wanted, BATCH_BYTES // per_realization))
