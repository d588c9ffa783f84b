"""The exact solver: every mode advanced by its matrix-exponential propagators.

Between events each mode is linear and time-invariant and the ground motion is
a polynomial (sampled motions) or a sine (harmonic motions) inside every
sample interval, so the state is advanced exactly by the propagators of
:mod:`stochpound.solvers.propagators`. The whole run, events included,
happens in the event engine (:mod:`stochpound.solvers.engine`); Python only
builds the modes the run reaches (:class:`stochpound.solvers.driver.EngineRun`).
"""

from __future__ import annotations

import contextlib

from threadpoolctl import ThreadpoolController

from stochpound.model.scene import Scene
from stochpound.model.system import build_system
from stochpound.results.record import EventCounters, Recorder
from stochpound.solvers.driver import EngineRun, VisitedModes
from stochpound.solvers.propagators import propagator_library


def run_exact(scene: Scene, limit_threads: bool = True, demands: bool = False) -> tuple[Recorder, EventCounters, VisitedModes]:
    """Simulate ``scene`` with exact propagation between events.

    Parameters
    ----------
    scene : Scene
        Its motion must be a :class:`~stochpound.motions.ground.SampledMotion`
        (linear or spline interpolation) or a
        :class:`~stochpound.motions.ground.HarmonicMotion` with uniformly
        spaced output times.
    limit_threads : bool
        Build propagators with one BLAS thread (small-matrix kernels are much
        slower threaded); batch callers may limit threads once themselves
        instead. A run that builds no new mode leaves them alone.
    demands : bool
        Also record the demand parameters and locate their peaks (:mod:`stochpound.model.demands`).

    Returns
    -------
    recorder, counters, visited
        The recorded outputs, the event counters and the modes visited (of
        the cached library shared by runs of the same system).

    Raises
    ------
    stochpound.solvers.propagators.UnsupportedMotionError
        For other ground motions (use ``method="ivp"``).
    """
    library = propagator_library(build_system(scene, demands), scene.motion)
    return EngineRun(library.system, scene.motion, library, building=lambda: _one_thread(limit_threads)).execute()


WARM_UP_SCENE = {
    "building": [
        {"name": "B1", "mass": [2.0e5], "stiffness": [4.0e7], "damping": [1.0e5], "base": {"mass": 1.0e5, "mu": 0.1}},
        {"name": "B2", "mass": [2.0e5], "stiffness": [4.0e7], "damping": [1.0e5]},
    ],
    "contact": [{"between": [["B1", 1], ["B2", 1]], "gap": 0.0, "stiffness": 1.0e8, "restitution": 0.5}],
    "motion": {"type": "harmonic", "amplitude": 3.0, "omega": 9.0, "duration": 0.2, "dt": 0.01},
}
"""A tiny scene (an isolated and a fixed one-storey building in contact, 0.2 s) for :func:`compile_engine`."""


def compile_engine() -> None:
    """Compile the event engine, or load it from numba's cache, by running :data:`WARM_UP_SCENE`.

    numba compiles the whole engine on its first call (seconds, once per
    machine: ``cache=True``); processes that start afterwards load it from
    the cache. The experiment runner calls this before its local workers
    start, so that they do not all compile it at once.
    """
    from stochpound.model.scene_file import scene_from_dict

    run_exact(scene_from_dict(WARM_UP_SCENE, source="compile_engine"))


def _one_thread(limit_threads: bool) -> contextlib.AbstractContextManager:
    """One BLAS thread inside the block if ``limit_threads`` (setting it costs ~0.2 ms), else no change."""
    return _thread_controller().limit(limits=1) if limit_threads else contextlib.nullcontext()


_CONTROLLER: list[ThreadpoolController] = []


def _thread_controller() -> ThreadpoolController:
    """One :class:`ThreadpoolController` per process (finding the BLAS libraries takes ~1 ms)."""
    if not _CONTROLLER:
        _CONTROLLER.append(ThreadpoolController())
    return _CONTROLLER[0]
