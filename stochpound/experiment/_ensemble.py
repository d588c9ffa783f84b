"""Many ground motions, one scene: batched simulation of an ensemble of realizations.

:func:`simulate_ensemble` runs one scene under every realization of an
ensemble of ground accelerations (e.g. from :func:`stochpound.motions.kanai_tajimi`)
and returns one :class:`xarray.Dataset` with a ``realization`` dimension.
Realizations are simulated in batches, optionally in worker processes; each
realization is computed on its own, so the result does not depend on the
batch size or the number of workers. Each realization's result is the
dataset of :func:`stochpound.simulate` (names, units and long names as
there); only what ``keep`` asks for is held in memory: a summaries-only
ensemble holds one batch of results at a time.

Summaries per realization (see :mod:`stochpound.analysis`):

* per building: ``peak_total_displacement``, ``peak_relative_displacement``,
  ``peak_sliding_displacement``, ``residual_sliding`` (m), and the moments
  ``response_mean``, ``response_variance``, ``response_std`` (m, m²),
  ``response_skewness`` and ``response_excess`` of the top floor's total
  displacement over time (the names of the experiment store; the earlier
  ``top_floor_mean`` … ``top_floor_excess`` remain as aliases,
  :mod:`stochpound.analysis.names`);
* impacts: ``impacts``, ``impacts_in_phase``, ``impacts_out_of_phase``,
  ``peak_impact_force`` (N), ``longest_impact`` (s), ``total_impulse`` (N·s);
* energy: the final ``energy_input``, ``energy_damping``, ``energy_friction``
  and ``energy_impact`` (J);
* ``events_total`` and ``events_chatter_cycles`` of the event logic.
"""

from __future__ import annotations

import dataclasses
import multiprocessing
import os
from collections import deque
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import xarray as xr
from threadpoolctl import threadpool_limits

from stochpound import __version__
from stochpound.analysis import TABLE_COLUMNS, impact_statistics, peak_response
from stochpound.analysis.names import ENSEMBLE_ALIASES, with_aliases
from stochpound.analysis import response_moments
from stochpound._memory import check_memory, sample_bytes
from stochpound.motions.ground import SampledMotion
from stochpound.model.scene import Scene
from stochpound.results.record import ENERGY_TERMS
from stochpound.solvers.simulate import METHODS, simulate

KEEP = ("summary", "histories")
"""What an ensemble keeps: summaries only, or also the displacement and impact force histories."""
HISTORIES = ("total_displacement", "relative_displacement", "sliding_displacement", "impact_force")
"""The time histories an ensemble keeps with ``keep="histories"`` (the names of :func:`stochpound.simulate`)."""
FINAL_ENERGIES = tuple(f"energy_{term}" for term in ENERGY_TERMS)
EVENT_COUNTS = ("events_total", "events_chatter_cycles")


def simulate_ensemble(
    scene: Scene,
    motions: xr.DataArray,
    keep: str = "summary",
    method: str = "exact",
    *,
    workers: int | None = 1,
    batch_size: int = 64,
) -> xr.Dataset:
    """Simulate ``scene`` under every realization of ``motions``.

    Parameters
    ----------
    scene : Scene
        The buildings and contacts; its motion is replaced by each realization
        (with the scene's interpolation if its motion is sampled, else linear).
    motions : xarray.DataArray
        Ground acceleration, m/s², dims ``(realization, time)``, uniformly
        sampled from t = 0 (the ``time`` coordinate in s, or ``attrs["dt"]``).
        May be dask-backed: batches are computed in this process (dask's
        synchronous scheduler) as they are handed out, at most two per
        worker ahead.
    keep : {"summary", "histories"}
        ``summary``: per-realization scalars only. ``histories``: also
        ``total_displacement``, ``relative_displacement`` (realization,
        building, floor, time), ``sliding_displacement`` (realization,
        building, time) and ``impact_force`` (realization, contact, time).
    method : {"exact", "ivp"}
        The solver (``ivp`` with DOP853 at its default tolerances).
    workers : int or None
        Worker processes (``None``: one per CPU). 1 runs in this process.
    batch_size : int
        Realizations per batch (the unit of work of a worker).

    Returns
    -------
    xarray.Dataset
        The summaries (and histories) with a ``realization`` dimension, in
        the order of ``motions``.
    """
    if keep not in KEEP:
        raise ValueError(f"keep must be one of {', '.join(KEEP)}, got {keep!r}")
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    if batch_size < 1:
        raise ValueError(f"batch_size must be >= 1, got {batch_size}")
    motions = motions.transpose("realization", "time")
    dt = _sample_spacing(motions)
    labels = motions["realization"].values
    starts = range(0, len(labels), batch_size)
    workers = (os.cpu_count() or 1) if workers is None else workers
    _check_memory(scene, motions.shape, keep, min(max(workers, 1), len(starts)), batch_size)
    tasks = ((scene, _load(motions, a, batch_size), labels[a : a + batch_size], dt, keep, method) for a in starts)
    if workers <= 1 or len(starts) <= 1:
        batches = [_simulate_batch(*task) for task in tasks]
    else:
        batches = _in_workers(tasks, min(workers, len(starts)))
    result = xr.concat(batches, dim="realization", data_vars="all", coords="minimal", compat="override", join="override")
    result = with_aliases(result, ENSEMBLE_ALIASES)
    result.attrs.update(
        title="stochpound ensemble", stochpound_version=__version__, solver=method, keep=keep,
        scene_source=scene.source, g=scene.g, study_compat=int(scene.study_compat), dt=dt,
        **{f"motion_{name}": value for name, value in motions.attrs.items() if isinstance(value, (int, float, str))},
    )
    return result


def _check_memory(scene: Scene, shape: tuple[int, int], keep: str, parallel: int, batch_size: int) -> None:
    """Refuse an ensemble whose batches in flight (two per worker) or kept histories would exceed the memory limit."""
    n_realizations, n_times = shape
    n_dof = sum(b.n_floors + (b.base is not None) for b in scene.buildings)
    sizes = (n_dof, len(scene.buildings), scene.max_floors, len(scene.contacts))
    in_flight = 2 * parallel * min(batch_size, n_realizations)
    check_memory(in_flight * n_times * sample_bytes(*sizes), f"batch_size: {in_flight} runs of {n_times} samples at a time ({parallel} workers)")
    if keep == "histories":
        per_sample = 8 * (2 * len(scene.buildings) * scene.max_floors + len(scene.buildings) + len(scene.contacts))
        check_memory(n_realizations * n_times * per_sample, f"motions: {n_realizations} realizations of {n_times} samples kept as histories")


def _load(motions: xr.DataArray, start: int, size: int) -> np.ndarray:
    """Samples (m/s²) of realizations ``start`` to ``start + size``, computed in this process.

    Dask-backed motions are computed with the synchronous scheduler: workers
    get plain arrays and never run dask (a forked worker would block on the
    locks of the parent's scheduler threads), and the parent starts no threads.
    """
    batch = motions.isel(realization=slice(start, start + size))
    return np.asarray(batch.compute(scheduler="synchronous").values, float)


def _in_workers(tasks: Iterator[tuple], workers: int) -> list[xr.Dataset]:
    """Batch results of ``tasks`` computed by ``workers`` processes, in order.

    At most two batches per worker are loaded and queued at a time, so a lazy
    ensemble is generated batch by batch while the workers simulate.
    """
    results, queued = [], deque()
    with ProcessPoolExecutor(max_workers=workers, mp_context=_context()) as pool:
        for task in tasks:
            queued.append(pool.submit(_simulate_batch, *task))
            if len(queued) >= 2 * workers:
                results.append(queued.popleft().result())
        results.extend(future.result() for future in queued)
    return results


def _context() -> multiprocessing.context.BaseContext:
    """Fork where available (workers inherit compiled kernels and caches), else spawn."""
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("fork" if "fork" in methods else "spawn")


def _sample_spacing(motions: xr.DataArray) -> float:
    """dt (s) of the ensemble's uniformly spaced samples."""
    if "time" in motions.coords:
        times = np.asarray(motions["time"].values, float)
        dt = float(times[1] - times[0])
        if abs(times[0]) > 1e-9 * dt or not np.allclose(np.diff(times), dt, rtol=1e-9, atol=0.0):
            raise ValueError("motions: the time coordinate must start at 0 and be uniformly spaced")
        return dt
    if "dt" in motions.attrs:
        return float(motions.attrs["dt"])
    raise ValueError("motions: give a time coordinate (s) or attrs['dt']")


# ---------------------------------------------------------------- one batch


def _simulate_batch(scene: Scene, values: np.ndarray, labels: np.ndarray, dt: float, keep: str, method: str) -> xr.Dataset:
    """Simulate and summarise one batch of realizations (``values``: realization × time, m/s²).

    Each realization's result is the dataset of :func:`stochpound.simulate`
    (the toolkit's one result builder); the batch stacks what it needs of them.
    """
    interpolation = scene.motion.interpolation if isinstance(scene.motion, SampledMotion) else "linear"
    with threadpool_limits(limits=1):
        runs = [simulate(dataclasses.replace(scene, motion=SampledMotion(dt, samples, interpolation, f"realization {label}")), method)
                for label, samples in zip(labels, values)]
    histories = xr.concat([run[list(HISTORIES)] for run in runs], "realization", coords="minimal", compat="override", join="override")
    summary = xr.merge([peak_response(histories), _top_floor_moments(scene, histories), impact_statistics(_impact_tables(runs)), _final_values(runs)])
    if keep == "histories":
        summary = summary.merge(histories)
    return summary.assign_coords(realization=labels)


def _top_floor_moments(scene: Scene, histories: xr.Dataset) -> xr.Dataset:
    """Moments over time of every building's top-floor total displacement."""
    tops = xr.DataArray([b.n_floors for b in scene.buildings], dims="building", coords={"building": scene.building_names})
    top_floor = histories["total_displacement"].sel(floor=tops).drop_vars("floor")
    return response_moments(top_floor.assign_attrs(units="m"))


def _impact_tables(runs: list[xr.Dataset]) -> xr.Dataset:
    """The batch's impact tables (the columns :func:`~stochpound.analysis.impact_statistics` reads), padded with NaN to (realization, impact)."""
    longest = max(run.sizes.get("impact", 0) for run in runs)
    tables = {}
    for name in TABLE_COLUMNS:
        table = np.full((len(runs), longest), np.nan)
        for row, run in zip(table, runs):
            row[: run.sizes.get("impact", 0)] = run[name].values
        tables[name] = (("realization", "impact"), table)
    return xr.Dataset(tables)


def _final_values(runs: list[xr.Dataset]) -> xr.Dataset:
    """The final energy terms (J) and the event counts of each realization."""
    variables = {name: ("realization", [run[name].values[-1] for run in runs], runs[0][name].attrs) for name in FINAL_ENERGIES}
    for name in EVENT_COUNTS:
        variables[name] = ("realization", [run.attrs[name] for run in runs])
    return xr.Dataset(variables)
