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

    Also reports the LLVM optimisation level the engine was compiled at
    (``NUMBA_OPT`` if set, else the engine's own).
    """
    import os
    import sys

    imported, scene = _timed(_main_scene)
    import stochpound
    from stochpound.solvers.engine import OPTIMISATION_LEVEL

    first, _ = _timed(lambda: stochpound.simulate(scene))
    second, _ = _timed(lambda: stochpound.simulate(scene))
    warm = min(_timed(lambda: stochpound.simulate(scene))[0] for _ in range(100))
    level = os.environ.get("NUMBA_OPT", str(OPTIMISATION_LEVEL))
    _emit({"import": imported, "first": first, "second": second, "warm": warm, "level": level, "numba": "numba" in sys.modules})


def _main_scene():
    from benchmarks.scenes import MAIN_SCENE

    return MAIN_SCENE.scene()


def _ensemble_setup(runs: int, lazy: bool):
    """Scene (c), ``runs`` Kanai–Tajimi motions of 30 s at dt 0.01 s, and a 2-realization warm-up run."""
    from benchmarks.scenes import STUDY_SCENES, kanai_tajimi_motions, lazy_kanai_tajimi_motions
    from stochpound.experiment.ensemble import simulate_ensemble

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
