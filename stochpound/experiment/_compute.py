"""Running cases: what a worker does with a batch.

A :class:`BatchTask` is self-contained and picklable (scene dicts, the motion's
table, the output and solver settings), so a batch runs unchanged in this
process, on local dask workers or on a remote cluster. A batch is a set of
realizations of one motion and the grid points that run under them
(:class:`Group`): the realizations are generated once (an ensemble's in one
call), the fixed-base twins of all of them are computed at once
(:mod:`stochpound.solvers.twin`), and each case is simulated and
summarised (:mod:`stochpound.experiment._summary`).

Every result depends only on its case: the solvers limit BLAS to one thread,
a synthetic realization depends only on (seed, realization), and the twin's
recursion computes each realization on its own.
"""

from __future__ import annotations

import dataclasses
import traceback
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from stochpound import motions as synthetic_motions
from stochpound.experiment import _intensity as intensity
from stochpound.store import REFERENCE, Label, Output, Solver, canonical_json, reference_scene, with_motion
from stochpound.experiment._parts import concatenate, section_key, stack_cases
from stochpound.experiment._spec import AUTO
from stochpound.experiment._summary import case_arrays, case_values, reference_arrays, reference_values
from stochpound.solvers.twin import fixed_base_displacements
from stochpound.model.scene import Scene
from stochpound.model.scene_file import scene_from_dict
from stochpound.motions.ground import GroundMotion, SampledMotion
from stochpound.solvers.simulate import simulate

if TYPE_CHECKING:
    import xarray as xr


@dataclass(frozen=True)
class Group:
    """The cases of one kind at one grid point, under some realizations of the batch's motion.

    Attributes
    ----------
    kind : str
        ``case`` or ``reference``.
    structure : dict
        Scene dict of the grid point (placeholder motion).
    reference : dict
        Scene dict of its fixed-base twin (placeholder motion).
    realizations : tuple of int
        Realization numbers (0 for a record).
    positions : np.ndarray
        (len(realizations), n_dims) int: the cases' positions in the grid of their kind.
    labels : tuple of (str, value)
        The grid point's labels (its ``intensity`` level and gaps scale the motion and give the IDA capacities).
    """

    kind: str
    structure: dict
    reference: dict
    realizations: tuple[int, ...]
    positions: np.ndarray
    labels: tuple = ()


@dataclass(frozen=True)
class BatchTask:
    """Everything a worker needs to run a batch.

    Attributes
    ----------
    record : int
        Index of the motion on the store's ``record`` dimension.
    motion_table : dict or None
        An ensemble's scene ``[motion]`` table (realizations are generated
        from it on the worker); None when the motion is shipped with the batch.
    groups : tuple of Group
    studied : str
        The studied building.
    output : Output
        What the store keeps (the definition's).
    solver : Solver
        The solver settings (the definition's).
    intensity : Scaling or None
        :func:`stochpound.experiment._intensity.task_settings` of an intensity-conditioned experiment.
    """

    record: int
    motion_table: dict | None
    groups: tuple[Group, ...]
    studied: str
    output: Output
    solver: Solver
    intensity: intensity.Scaling | None = None

    @property
    def n_cases(self) -> int:
        """Number of cases in the batch."""
        return sum(len(g.realizations) for g in self.groups)


@dataclass
class BatchResult:
    """What a batch produced.

    Attributes
    ----------
    arrays : dict[str, numpy.ndarray]
        Part arrays of the finished cases, by section (:func:`stochpound.experiment._parts.section_key`).
    done : int
        Number of finished cases.
    failures : list of (str, tuple, str)
        (kind, position, traceback) of each case that raised.
    """

    arrays: dict[str, np.ndarray] = field(default_factory=dict)
    done: int = 0
    failures: list[tuple[str, tuple[int, ...], str]] = field(default_factory=list)


def run_batch(task: BatchTask, motion: GroundMotion | None = None) -> BatchResult:
    """Run a batch: generate its motions, compute the twins, simulate and summarise every case.

    Parameters
    ----------
    task : BatchTask
    motion : GroundMotion, optional
        The batch's recorded (or analytic) motion; None for an ensemble,
        whose realizations are generated here from the task's table.

    Returns
    -------
    BatchResult
        A case that raises is reported with its traceback and the batch goes
        on; an error shared by all cases (the motion, a twin) fails them all.
    """
    try:
        grounds = _motions(task, motion)
        twins = _twins(task, grounds)
        measures = {r: intensity.measures_of(task.intensity, ground) for r, ground in grounds.items()} if task.intensity else {}
    except Exception:  # noqa: BLE001 - reported for every case of the batch
        error = traceback.format_exc(limit=8)
        return BatchResult(failures=[(g.kind, tuple(int(i) for i in p), error) for g in task.groups for p in g.positions])
    result, sections, runs = BatchResult(), [], {}
    for group in task.groups:
        section = _group(task, group, grounds, twins[canonical_json(group.reference)], measures, runs, result.failures)
        if section:
            sections.append(section)
            result.done += len(section[section_key(group.kind, task.record, "position")])
    result.arrays = concatenate(sections)
    return result


def _group(
    task: BatchTask, group: Group, grounds: dict[int, GroundMotion], twins: dict[int, np.ndarray], measures: dict[int, intensity.CaseVariables],
    runs: dict[tuple[str, int], xr.Dataset], failures: list[tuple[str, tuple[int, ...], str]]
) -> dict[str, np.ndarray]:
    """The section of a group's finished cases (empty if none finished); failures are appended to ``failures``.

    ``runs`` keeps the batch's IDA runs: their grid points differ only in gaps that are all infinite, so each motion runs once.
    """
    try:
        scene = _scene(group.structure) if group.kind != REFERENCE else None
    except Exception:  # noqa: BLE001 - reported for every case of the group
        failures.extend((group.kind, tuple(int(i) for i in position), traceback.format_exc(limit=8)) for position in group.positions)
        return {}
    finished, positions = [], []
    for realization, position in zip(group.realizations, group.positions):
        try:
            ground, twin, extra = grounds[realization], twins[realization], {}
            if task.intensity is not None:
                ground, twin, extra = intensity.scaled_case(task.intensity, task.record, dict(group.labels), ground, twin, measures[realization])
            ida = task.intensity is not None and task.intensity.ran == "ida" and scene is not None
            key = (canonical_json(group.structure), realization) if ida else None
            finished.append(_case(task, scene, ground, twin, extra, dict(group.labels), runs, key))
        except Exception:  # noqa: BLE001 - reported per case, the batch goes on
            failures.append((group.kind, tuple(int(i) for i in position), traceback.format_exc(limit=8)))
            continue
        positions.append(position)
    if not finished:
        return {}
    stacked = stack_cases(finished, np.array(positions, dtype=np.int64), grounds[group.realizations[0]].times)
    return {section_key(group.kind, task.record, name): values for name, values in stacked.items()}


def _case(
    task: BatchTask, scene: Scene | None, ground: GroundMotion, twin: np.ndarray, extra: intensity.CaseVariables, labels: Mapping[str, Label],
    runs: dict[tuple[str, int], xr.Dataset], key: tuple[str, int] | None
) -> dict[str, np.ndarray]:
    """Part arrays of one case: ``scene`` (placeholder motion) under ``ground``, or, without a scene, a reference case (its twin's response).

    ``extra``: the intensity variables of the case (none without ``[intensity]``); a run with a ``key`` is kept in ``runs`` and reused.
    """
    if scene is None:
        return reference_arrays({**reference_values(twin), **extra}, twin, "total_displacement" in task.output.time_histories)
    solver = task.solver
    method = None if solver.method == AUTO else solver.method
    run = runs.get(key) if key is not None else None
    if run is None:
        run = simulate(
            dataclasses.replace(scene, motion=ground), method, integrator=solver.integrator, rtol=solver.rtol, atol=solver.atol,
            demands=task.output.demands,
        )
        if key is not None:
            runs[key] = run
    summary = {**case_values(run, task.studied, twin[-1]), **extra}
    if task.intensity is not None and task.intensity.ran == "ida":
        summary["ida_capacity"] = intensity.capacity_of(task.intensity, summary, labels)
    return case_arrays(summary, run, task.output.time_histories, task.output.buildings, task.output.impacts)


_SCENES: dict[str, Scene] = {}


def _scene(structure: dict) -> Scene:
    """The scene of a structure dict (placeholder motion), cached per worker by its canonical JSON."""
    key = canonical_json(structure)
    scene = _SCENES.get(key)
    if scene is None:
        if len(_SCENES) >= 256:
            _SCENES.clear()
        scene = _SCENES[key] = scene_from_dict(structure, source="experiment")
    return scene


def _motions(task: BatchTask, motion: GroundMotion | None) -> dict[int, GroundMotion]:
    """The batch's ground motion of each realization: the shipped motion, or an ensemble's realizations generated in one call."""
    realizations = sorted({r for group in task.groups for r in group.realizations})
    if task.motion_table is None:
        return {r: motion for r in realizations}
    table = task.motion_table
    parameters = {k: v for k, v in table.items() if k not in ("type", "interpolation", "realization")}
    first = realizations[0]
    generated = getattr(synthetic_motions, table["type"])(realizations[-1] - first + 1, start=first, **parameters)
    values, dt = np.asarray(generated.values, dtype=float), float(table["dt"])
    return {r: SampledMotion(dt, values[r - first], "linear", f"{table['type']} realization {r}") for r in realizations}


def _twins(task: BatchTask, grounds: dict[int, GroundMotion]) -> dict[str, dict[int, np.ndarray]]:
    """Fixed-base twins' floor displacements (floors × time, m) by reference structure and realization."""
    wanted: dict[str, tuple[dict, set[int]]] = {}
    for group in task.groups:
        key = canonical_json(group.reference)
        wanted.setdefault(key, (group.reference, set()))[1].update(group.realizations)
    twins = {}
    for key, (reference, realizations) in wanted.items():
        order = sorted(realizations)
        displacements = fixed_base_displacements(_scene(reference), [grounds[r] for r in order])
        twins[key] = dict(zip(order, displacements))
    return twins


def warm_up(spectrum: bool = True) -> None:
    """Compile the kernels a batch runs (or load them from numba's cache): the exact solver's engine, the twin's recursion
    and, with ``spectrum``, the response spectrum's kernel (an experiment with ``[intensity]`` measures its motions).

    numba caches compiled kernels on disk (``cache=True``): compiled once
    by the process that starts the local workers, before they start, every
    worker loads them in a fraction of a second instead of compiling them
    concurrently; a kernel an experiment does not run is not compiled.
    """
    from stochpound.solvers.exact import WARM_UP_SCENE, compile_engine

    compile_engine()
    if spectrum:
        intensity.warm_up()
    twin = scene_from_dict(with_motion(reference_scene(WARM_UP_SCENE, "B2"), WARM_UP_SCENE["motion"]), source="warm_up")
    fixed_base_displacements(twin, [twin.motion])
