"""Measurements that run in a fresh interpreter (started by :func:`benchmarks.timing.run_subprocess`).

Each probe prints one JSON object on its last line of output. They run in a
subprocess because they need a clean process (first-call compile time), a
process tree whose memory belongs to one measurement (sampled by the parent,
see :class:`benchmarks.timing.MemoryPeaks`), several cores (ensembles), or a
timeout (large scenes).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from typing import Any


def _emit(data: dict[str, Any]) -> None:
    print(json.dumps(data), flush=True)


def _timed(call: Callable[[], Any]) -> tuple[float, Any]:
    start = time.perf_counter()
    result = call()
    return time.perf_counter() - start, result


def first_call() -> None:
    """Import, scene (a), then exact runs: the first compiles or loads the numba kernels; the best of 100 warm ones.

    Also reports the compile settings: numba's default when ``NUMBA_OPT`` is
    set, else the engine's own (:mod:`stochpound.solvers.compiling`).
    """
    import os
    import sys

    imported, scene = _timed(_main_scene)
    import stochpound
    from stochpound.solvers.compiling import OPTIMISATION_LEVEL

    first, _ = _timed(lambda: stochpound.simulate(scene))
    second, _ = _timed(lambda: stochpound.simulate(scene))
    warm = min(_timed(lambda: stochpound.simulate(scene))[0] for _ in range(100))
    settings = f"numba's default (LLVM {os.environ['NUMBA_OPT']})" if "NUMBA_OPT" in os.environ else f"stochpound's (LLVM {OPTIMISATION_LEVEL})"
    _emit({"import": imported, "first": first, "second": second, "warm": warm, "settings": settings, "numba": "numba" in sys.modules})


def _main_scene():
    from benchmarks.scenes import MAIN_SCENE

    return MAIN_SCENE.scene()


def _ensemble_setup(runs: int, lazy: bool):
    """Scene (c), ``runs`` Kanai–Tajimi motions of 30 s at dt 0.01 s, and a 2-realization warm-up run."""
    from benchmarks.scenes import STUDY_SCENES, kanai_tajimi_motions, lazy_kanai_tajimi_motions
    from stochpound.experiment import simulate_ensemble

    scene = STUDY_SCENES[2].scene()
    make = lazy_kanai_tajimi_motions if lazy else kanai_tajimi_motions
    generated, motions = _timed(lambda: make(runs, 30.0, 0.01))
    warm_up, _ = _timed(lambda: simulate_ensemble(scene, motions.isel(realization=slice(0, 2)), keep="summary", workers=1))
    return simulate_ensemble, scene, motions, generated, warm_up


def ensemble_throughput(runs: int, workers: int) -> None:
    """Wall time of a summaries-only ensemble on scene (c) (motions made beforehand, after a warm-up)."""
    simulate_ensemble, scene, motions, generated, warm_up = _ensemble_setup(runs, lazy=False)
    elapsed, result = _timed(lambda: simulate_ensemble(scene, motions, keep="summary", workers=workers))
    _emit({
        "generated": generated, "warm_up": warm_up, "elapsed": elapsed, "realizations": result.sizes["realization"],
        "mean_impacts": float(result["impacts"].mean()), "mean_events": float(result["events_total"].mean()),
    })


def ensemble_memory(runs: int, workers: int) -> None:
    """A summaries-only ensemble whose motions are generated lazily; its peak memory is sampled by the parent.

    Dask runs its synchronous scheduler: a thread pool created in this
    process would not survive the ``fork`` of the ensemble's workers.
    """
    import dask
    import psutil

    dask.config.set(scheduler="synchronous")
    simulate_ensemble, scene, motions, _, _ = _ensemble_setup(runs, lazy=True)
    baseline = psutil.Process().memory_full_info().pss
    elapsed, result = _timed(lambda: simulate_ensemble(scene, motions, keep="summary", workers=workers, batch_size=64))
    _emit({"baseline": baseline, "elapsed": elapsed, "realizations": result.sizes["realization"], "result_bytes": result.nbytes})


def scene_size(buildings: int, floors: int, gap: float, duration: float) -> None:
    """First-call and best-of-3 warm time of the exact solver on a row of buildings."""
    import stochpound
    from benchmarks.scenes import building_row

    scene = building_row(buildings, floors, gap=gap, duration=duration)
    first, run = _timed(lambda: stochpound.simulate(scene))
    warm = min(_timed(lambda: stochpound.simulate(scene))[0] for _ in range(3))
    state = 2 * sum(b.n_floors + (b.base is not None) for b in scene.buildings)
    _emit({
        "first": first, "warm": warm, "impacts": run.sizes.get("impact", 0), "events": run.attrs["events_total"],
        "modes": run.attrs["modes_visited"], "dofs": state,
    })


def single_cell(path: str, runs: int) -> None:
    """The experiment's one case run alone: ``runs`` warm ``simulate`` calls, and the cost of their motions.

    The case's scene and its Kanai–Tajimi table (intensity resolved to S0)
    come from the experiment file at ``path``. Mean wall times per
    realization: ``simulate`` (motion made beforehand), the motion generated
    ``BATCH`` at a time, and generated one at a time.
    """
    import dataclasses

    import numpy as np

    import stochpound
    from stochpound import motions as generators
    from stochpound.experiment import CASE, load_experiment, resolve_motions
    from stochpound.motions.ground import SampledMotion

    batch = 64
    experiment = load_experiment(path)
    scene = stochpound.scene_from_dict(experiment.structure(experiment.points(CASE)[0]))
    table = next(iter(resolve_motions(experiment).values())).table
    parameters = {k: v for k, v in table.items() if k not in ("type", "interpolation", "realization")}
    generate = getattr(generators, table["type"])

    def batched() -> list:
        values = [generate(batch, start=start, **parameters).values for start in range(0, runs, batch)]
        return [SampledMotion(table["dt"], row, "linear") for row in np.concatenate(values)[:runs]]

    batched()
    motion_batched, motions = _timed(batched)
    motion_single, _ = _timed(lambda: [SampledMotion(table["dt"], generate(1, start=i, **parameters).values[0], "linear") for i in range(min(runs, 100))])
    for motion in motions[:20]:
        stochpound.simulate(dataclasses.replace(scene, motion=motion))
    cpu = time.process_time()
    elapsed, results = _timed(lambda: [stochpound.simulate(dataclasses.replace(scene, motion=motion)) for motion in motions])
    cpu = time.process_time() - cpu
    _emit({
        "runs": runs, "simulate": elapsed / runs, "simulate_cpu": cpu / runs, "motion_batched": motion_batched / runs, "motion_single": motion_single / min(runs, 100),
        "mean_impacts": float(np.mean([r.sizes.get("impact", 0) for r in results])),
    })


def experiment_run(path: str, workers: int, store: str) -> None:
    """``stochpound experiment run PATH --store STORE --workers N`` in this process (the command's own function).

    Also the CPU time of this process (the client, with the local cluster's
    scheduler and nannies; imports included) and of its children (the
    workers, reaped when the cluster closes).
    """
    from stochpound.experiment import load_experiment, run_experiment

    import resource

    started = time.perf_counter()
    report = run_experiment(load_experiment(path), store, workers=workers, progress=False)
    usage = {who: resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)}
    cpu = {who: u.ru_utime + u.ru_stime for who, u in usage.items()}
    _emit({
        "wall": time.perf_counter() - started, "elapsed": report.elapsed, "setup": report.setup, "done": report.done_now,
        "total": report.total, "failed": len(report.failed), "complete": report.complete,
        "cpu_client": cpu[resource.RUSAGE_SELF], "cpu_workers": cpu[resource.RUSAGE_CHILDREN],
    })


def store_analysis(store: str) -> None:
    """Questions answered on a store with dask (lazily, chunk by chunk): pounding probability, mean response, impact table."""
    import dask

    import stochpound
    from stochpound.analysis import pounding_probability

    dask.config.set(scheduler="synchronous")
    ds = stochpound.open_store(store)
    record = str(ds["record"].values[0])
    started = time.perf_counter()
    probability = pounding_probability(ds["impacts"].sel(record=record), "realization").compute()
    mean_std = float(ds["response_std"].sel(record=record).mean("realization").compute().values.ravel()[0])
    largest = float(ds["impact_peak_force"].max().compute())
    in_phase = int(ds["impact_in_phase"].sum().compute())
    _emit({
        "elapsed": time.perf_counter() - started, "realizations": int(probability["realizations"].values.ravel()[0]),
        "probability": float(probability["probability"].values.ravel()[0]), "mean_response_std": mean_std,
        "impacts": int(ds.sizes["impact"]), "largest_impact_force": largest, "impacts_in_phase": in_phase,
    })
