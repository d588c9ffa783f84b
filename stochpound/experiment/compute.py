"""Running cases: what a worker does with a batch of case tasks.

A :class:`CaseTask` is self-contained and picklable (scene dicts, the motion's
table or the motion itself, the output and solver settings), so a batch runs
unchanged in this process, on local dask workers or on a remote cluster.
Every result depends only on the task: the solvers limit BLAS to one thread,
and a synthetic realization depends only on (seed, realization).

To run synthetic ensembles through a batched solver, only :func:`run_batch`
needs to change (see the note there).
"""

from __future__ import annotations

import dataclasses
import traceback
from collections import OrderedDict
from dataclasses import dataclass
from typing import Any, Callable, Hashable, Sequence

import numpy as np
import xarray as xr

from stochpound.experiment.spec import canonical_json
from stochpound.experiment.summary import case_arrays, case_values, reference_arrays, reference_values, top_floor
from stochpound import motions as synthetic_motions
from stochpound.motions.ground import GroundMotion, SampledMotion
from stochpound.model.scene import Scene
from stochpound.model.scene_file import scene_from_dict
from stochpound.solvers.simulate import simulate


@dataclass(frozen=True)
class CaseTask:
    """Everything a worker needs to run one case.

    Attributes
    ----------
    case_id : str
        The case's id.
    kind : str
        ``case`` or ``reference``.
    structure : dict
        Scene dict of the case (placeholder motion).
    reference : dict
        Scene dict of the studied building alone on a fixed base (placeholder motion).
    motion_key : tuple
        (motion label, realization): identifies the motion for caching.
    motion_table : dict or None
        Scene ``[motion]`` table for a synthetic realization (generated on the
        worker); None when the batch's motion is shipped with it.
    studied : str
        The studied building.
    output : dict
        ``time_histories``, ``buildings`` and ``impacts`` of the definition.
    solver : dict
        ``method``, ``integrator``, ``rtol``, ``atol``.
    """

    case_id: str
    kind: str
    structure: dict
    reference: dict
    motion_key: tuple
    motion_table: dict | None
    studied: str
    output: dict
    solver: dict


@dataclass
class CaseOutcome:
    """The result of one case: its part arrays, or the error that stopped it."""

    case_id: str
    arrays: dict[str, np.ndarray] | None = None
    error: str | None = None


class _LRU:
    """A small least-recently-used cache (per worker process)."""

    def __init__(self, size: int) -> None:
        self.size = size
        self.items: OrderedDict[Hashable, Any] = OrderedDict()

    def get(self, key: Hashable, make: Callable[[], Any]) -> Any:
        if key in self.items:
            self.items.move_to_end(key)
            return self.items[key]
        value = make()
        self.put(key, value)
        return value

    def put(self, key: Hashable, value: Any) -> None:
        self.items[key] = value
        self.items.move_to_end(key)
        if len(self.items) > self.size:
            self.items.popitem(last=False)


_MOTIONS = _LRU(64)          # ground motions by (label, realization)
_REFERENCES = _LRU(1024)     # fixed-base top-floor responses (a few kB each)


def run_batch(tasks: Sequence[CaseTask], motion: GroundMotion | None = None) -> list[CaseOutcome]:
    """Run a batch of cases that share one motion source.

    Parameters
    ----------
    tasks : sequence of CaseTask
    motion : GroundMotion, optional
        The batch's recorded motion (None for synthetic realizations, which
        are generated here from their tables).

    Returns
    -------
    list of CaseOutcome
        One per task, in order; a failing case carries its traceback.

    Notes
    -----
    Synthetic batches are realizations of one grid point; a batched
    ensemble solver would replace the loop below for them (one call for the
    whole batch), keeping :func:`compute_case`'s summaries.
    """
    _generate_ensemble(tasks)
    outcomes = []
    for task in tasks:
        try:
            outcomes.append(CaseOutcome(task.case_id, compute_case(task, motion)))
        except Exception:  # noqa: BLE001 - reported per case, the batch goes on
            outcomes.append(CaseOutcome(task.case_id, error=traceback.format_exc(limit=8)))
    return outcomes


def _generate_ensemble(tasks: Sequence[CaseTask]) -> None:
    """Generate a synthetic batch's realizations in one call (bit for bit those of one-by-one calls)."""
    synthetic = [t for t in tasks if t.motion_table is not None and t.motion_key not in _MOTIONS.items]
    if len(synthetic) < 2:
        return
    table = {k: v for k, v in synthetic[0].motion_table.items() if k != "realization"}
    if any({k: v for k, v in t.motion_table.items() if k != "realization"} != table for t in synthetic):
        return
    indices = sorted({t.motion_table["realization"] for t in synthetic})
    parameters = {k: v for k, v in table.items() if k not in ("type", "interpolation")}
    ensemble = getattr(synthetic_motions, table["type"])(indices[-1] - indices[0] + 1, start=indices[0], **parameters)
    dt = float(table["dt"])
    for task in synthetic:
        row = ensemble.sel(realization=task.motion_table["realization"]).values
        _MOTIONS.put(task.motion_key, SampledMotion(dt, np.asarray(row, dtype=float), "linear", f"{table['type']} realization {task.motion_key[1]}"))


def compute_case(task: CaseTask, motion: GroundMotion | None = None) -> dict[str, np.ndarray]:
    """Simulate one case and return its part arrays (:mod:`stochpound.experiment.summary`)."""
    ground = motion if motion is not None else _MOTIONS.get(task.motion_key, lambda: _generated_motion(task))
    histories = task.output["time_histories"]
    key = (canonical_json(task.reference), task.motion_key, canonical_json(task.solver))
    if task.kind == "reference":
        run = _simulate(task.reference, ground, task.solver)
        _REFERENCES.put(key, top_floor(run, task.studied))
        return reference_arrays(reference_values(run, task.studied), run, "total_displacement" in histories)
    run = _simulate(task.structure, ground, task.solver)
    fixed_base = _REFERENCES.get(key, lambda: top_floor(_simulate(task.reference, ground, task.solver), task.studied))
    summary = case_values(run, task.studied, fixed_base)
    return case_arrays(summary, run, histories, task.output["buildings"], task.output["impacts"])


def _generated_motion(task: CaseTask) -> GroundMotion:
    return scene_from_dict({**task.reference, "motion": task.motion_table}).motion


def build_scene(structure: dict, motion: GroundMotion) -> Scene:
    """The scene of a structure dict (placeholder motion) under ``motion``."""
    return dataclasses.replace(scene_from_dict(structure, source="experiment"), motion=motion)


def _simulate(structure: dict, motion: GroundMotion, solver: dict) -> xr.Dataset:
    return simulate(build_scene(structure, motion), solver["method"], integrator=solver["integrator"], rtol=solver["rtol"], atol=solver["atol"])
