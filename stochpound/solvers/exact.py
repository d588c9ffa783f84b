"""The exact event-driven solver: matrix-exponential propagation of every mode.

Between events each mode is linear and time-invariant and the ground motion is
a polynomial (sampled motions) or a sine (harmonic motions) inside every
sample interval, so the state is advanced exactly by the propagators of
:mod:`stochpound.propagators`. Two event paths give the same run:

* ``events="compiled"`` (default): the whole run happens in the compiled
  engine :mod:`stochpound.solvers.exact_engine`, a port of the shared event
  and recording logic; Python only builds the modes the run reaches.
* ``events="python"``: the engine's quiet loop (``run_engine`` with
  ``events=False``) advances the sample intervals in which nothing happens,
  and every other interval is advanced sub-step by sub-step by the shared
  Python code itself (:func:`stochpound.events.first_crossing` on the exact
  flow, :func:`stochpound.recorder.settle_and_record`,
  :class:`stochpound.recorder.Recorder`), as the ``ivp`` path does with its
  integrator steps. It is the reference the compiled engine is tested
  against, and ~50× slower on event-rich runs.

Outputs, impact table and energy balance are those of the ``ivp`` path.
The engine's arrays are laid out by :mod:`stochpound.solvers.exact_tables`.
"""

from __future__ import annotations

import contextlib
import itertools
import math

import numpy as np
from threadpoolctl import ThreadpoolController

from stochpound.events import (
    EventCounters,
    GuardStates,
    Step,
    first_crossing,
    initial_mode,
)
from stochpound.modes import Mode, ModeDynamics, ModeLibrary
from stochpound.propagators import (
    ModePropagator,
    PropagatorLibrary,
    propagator_library,
    sample_ground,
)
from stochpound.recorder import Impact, Recorder, settle_and_record
from stochpound.scene import Scene
from stochpound.solvers import exact_engine as engine
from stochpound.solvers import exact_tables
from stochpound.system import build_system

EVENT_PATHS = ("compiled", "python")


def run_exact(scene: Scene, limit_threads: bool = True, events: str = "compiled") -> tuple[Recorder, EventCounters, ModeLibrary]:
    """Simulate ``scene`` with exact propagation between events.

    Parameters
    ----------
    scene : Scene
        Its motion must be a :class:`~stochpound.motion.SampledMotion` (linear
        or spline interpolation) or a :class:`~stochpound.motion.HarmonicMotion`
        with uniformly spaced output times.
    limit_threads : bool
        Build propagators with one BLAS thread (small-matrix kernels are much
        slower threaded, MODEL.md §6); batch callers may limit threads once
        themselves instead. A run that builds no new mode leaves them alone.
    events : {"compiled", "python"}
        Where events are located and settled (see the module docstring).

    Returns
    -------
    recorder, counters, library
        The recorded outputs, the event counters and the modes visited (of
        the cached library shared by runs of the same system).

    Raises
    ------
    stochpound.propagators.UnsupportedMotionError
        For other ground motions (use ``method="ivp"``).
    """
    if events not in EVENT_PATHS:
        raise ValueError(f"events must be one of {', '.join(EVENT_PATHS)}, got {events!r}")
    if events == "compiled":
        return _CompiledRun(scene, limit_threads).execute()
    with _one_thread(limit_threads):
        return _PythonRun(scene).execute()


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
    """Compile the compiled event engine, or load it from numba's cache, by running :data:`WARM_UP_SCENE`.

    numba compiles the whole engine on its first call (seconds, once per
    machine: ``cache=True``); processes that start afterwards load it from
    the cache. The experiment runner calls this before its local workers
    start, so that they do not all compile it at once.
    """
    from stochpound.scene_file import scene_from_dict

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


class _PythonRun:
    """One exact run with the shared Python event code (``events="python"``)."""

    def __init__(self, scene: Scene) -> None:
        self.motion = scene.motion
        self.propagators: PropagatorLibrary = propagator_library(build_system(scene), self.motion)
        self.system = self.propagators.system
        self.library = self.propagators.modes
        self.recorder = Recorder(self.system, self.motion)
        self.counters = EventCounters()
        self.ground = sample_ground(self.motion)
        self.visited: set[Mode] = set()
        self.plant = exact_tables.plant_arrays(self.system, self.motion)
        state = exact_tables.run_state(self.system, len(self.motion.times))
        outputs = state.outputs._replace(running=self.recorder.running, states=self.recorder.states, energy=self.recorder.energy_history)
        self.state = state._replace(outputs=outputs)
        self.work = exact_tables.work_arrays_for(self.system, exact_tables.slots_of(self.propagators))  # the quiet loop uses no Chebyshev rows: never too narrow

    def execute(self) -> tuple[Recorder, EventCounters, ModeLibrary]:
        times = self.motion.times
        x = self.system.initial_state.copy()
        mode, x, states = settle_and_record(self.library, self.motion, self.recorder, self.counters, 0, float(times[0]), x, initial_mode(self.system))
        self.recorder.sample(0, x, self.library[mode])
        k = 0
        while k < len(times) - 1:
            k, x, status = self._quiet(k, x, mode, states)
            if status != engine.NEEDS_EVENTS:
                break
            x, mode, states = self._interval(k, x, mode, states)
            self.recorder.sample(k + 1, x, self.library[mode])
            k += 1
        self.recorder.finish(float(times[-1]))
        return self.recorder, self.counters, _VisitedModes(self.library, self.visited)

    def _propagator(self, mode: Mode) -> ModePropagator:
        self.visited.add(mode)
        return self.propagators[mode]

    def _quiet(self, k: int, x: np.ndarray, mode: Mode, states: GuardStates) -> tuple[int, np.ndarray, int]:
        """Advance event-free intervals from k in the engine's quiet loop; (interval where it stopped, state there, status)."""
        dynamics = self._propagator(mode).dynamics
        run, arming, impacts = self.state.run, self.state.arming, self.state.impacts
        n = len(states.threshold)
        slots = exact_tables.slots_of(self.propagators)
        run.ints[engine.K], run.ints[engine.MODE], run.clock[0] = k, slots.slot(mode), self.motion.times[k]
        run.x[:] = x
        arming.threshold[:n], arming.tolerance[:n], arming.rearmable[:n], arming.disarmed[:n] = (
            states.threshold, states.tolerance, states.rearmable, states.disarmed
        )
        _put_open_impacts(self.recorder.open_impacts, impacts)
        status = engine.run(*slots.tables, *self.plant, *self.state, *self.work, False)
        states.threshold[:], states.disarmed[:] = arming.threshold[:n], arming.disarmed[:n]
        _take_open_impacts(impacts, self.recorder.open_impacts)
        stop = int(run.ints[engine.K])
        self.recorder.sample_at(np.arange(k + 1, stop + 1), dynamics, self.ground[k + 1 : stop + 1])
        return stop, run.x.copy(), status

    def _interval(self, k: int, x: np.ndarray, mode: Mode, states: GuardStates) -> tuple[np.ndarray, Mode, GuardStates]:
        """Advance interval k with the shared event code, sub-step by sub-step; return the state at its end."""
        t, t_end = float(self.motion.times[k]), float(self.motion.times[k + 1])
        while t_end - t > 2 * np.finfo(float).eps * max(1.0, abs(t_end)):
            t, x, mode, states = self._until_event(k, t, x, t_end, mode, states)
        return x, mode, states

    def _until_event(self, k: int, t: float, x: np.ndarray, t_end: float, mode: Mode, states: GuardStates):
        """Sub-steps of one mode from t towards t_end; stop at the first event and settle it."""
        propagator = self._propagator(mode)
        dynamics = propagator.dynamics
        n_steps = max(1, math.ceil((t_end - t) / propagator.step - 1e-9))
        edges = np.linspace(t, t_end, n_steps + 1)
        for t0, t1 in itertools.pairwise(edges):
            dense = propagator.dense(t0, x, self.motion.derivatives(t0, k))
            x1 = dense(t1)
            crossing = first_crossing(dynamics, self.motion, k, Step(t0, t1, x, x1, dense), states, self.counters)
            if crossing is None:
                self.recorder.on_step(dynamics, k, t0, t1, dense)
                x = x1
                continue
            t_event, guard = crossing
            self.recorder.on_step(dynamics, k, t0, t_event, dense)
            mode, x, states = settle_and_record(self.library, self.motion, self.recorder, self.counters, k, t_event, dense(t_event), mode, guard)
            return t_event, x, mode, states
        return t_end, x, mode, states


_IMPACT_RECORD = [engine.PEAK, engine.PEAK_TIME, engine.IMPULSE]


def _put_open_impacts(open_impacts: dict[int, Impact], impacts: engine.Impacts) -> None:
    """Copy the open impacts of a recorder into the engine's open-impact arrays."""
    impacts.is_open[:] = False
    for p, impact in open_impacts.items():
        impacts.is_open[p] = True
        impacts.impact[_IMPACT_RECORD, p] = impact.peak_force, impact.peak_time, impact.impulse


def _take_open_impacts(impacts: engine.Impacts, open_impacts: dict[int, Impact]) -> None:
    """Copy the engine's peaks and impulses back into the open impacts of a recorder."""
    for p, impact in open_impacts.items():
        impact.peak_force, impact.peak_time, impact.impulse = impacts.impact[_IMPACT_RECORD, p].tolist()


class _CompiledRun:
    """One exact run in the compiled engine (``events="compiled"``)."""

    def __init__(self, scene: Scene, limit_threads: bool) -> None:
        self.motion = scene.motion
        self.limit_threads = limit_threads
        self.propagators: PropagatorLibrary = propagator_library(build_system(scene), self.motion)
        self.system = self.propagators.system
        self.plant = exact_tables.plant_arrays(self.system, self.motion)
        self.state = exact_tables.run_state(self.system, len(self.motion.times))

    def execute(self) -> tuple[Recorder, EventCounters, ModeLibrary]:
        run, system = self.state.run, self.system
        run.pending_mode[:] = exact_tables.mode_vector(initial_mode(system))
        run.pending_x[:] = system.initial_state
        run.clock[0] = self.motion.times[0]
        run.ints[engine.PENDING] = engine.INITIAL
        slots = exact_tables.slots_of(self.propagators)
        while True:
            if len(self.state.run.visited) < len(slots.modes):
                visited = np.resize(self.state.run.visited, 2 * len(slots.modes))
                self.state = self.state._replace(run=self.state.run._replace(visited=visited))
            status = engine.run(*slots.tables, *self.plant, *self.state, *exact_tables.work_arrays_for(system, slots), True)
            if status == engine.FINISHED:
                break
            if status == engine.NEED_MODE:  # the only step that builds propagators (matrix exponentials)
                with _one_thread(self.limit_threads):
                    slots.load(exact_tables.vector_mode(run.missing_mode, system.n_contacts))
            else:  # NEED_SPACE
                table = self.state.impacts.table
                self.state = self.state._replace(impacts=self.state.impacts._replace(table=np.concatenate([table, np.zeros_like(table)])))
        return self._recorder(slots), self._counters(), self._visited(slots)

    def _recorder(self, slots: "exact_tables.Slots") -> Recorder:
        outputs, impacts = self.state.outputs, self.state.impacts
        recorder = Recorder(self.system, self.motion)
        recorder.states[:] = outputs.states
        recorder.energy_history[:] = outputs.energy
        recorder.running[:] = outputs.running
        ground = sample_ground(self.motion)
        for i in np.flatnonzero(self.state.run.visited[: len(slots.modes)]):
            indices = np.flatnonzero(outputs.sample_modes == i)
            recorder.sample_at(indices, self.propagators.modes[slots.modes[i]], ground[indices])
        recorder.impacts = [_impact(row) for row in impacts.table[: self.state.run.ints[engine.N_IMPACTS]]]
        recorder.open_impacts = _open_impacts(impacts)
        recorder.finish(float(self.motion.times[-1]))
        return recorder

    def _counters(self) -> EventCounters:
        ints = self.state.run.ints
        return EventCounters(total=int(ints[engine.TOTAL]), chatter_cycles=int(ints[engine.CHATTER]), grazing_checks=int(ints[engine.GRAZING]))

    def _visited(self, slots: "exact_tables.Slots") -> "_VisitedModes":
        modes = {slots.modes[i] for i in np.flatnonzero(self.state.run.visited[: len(slots.modes)])}
        return _VisitedModes(self.propagators.modes, modes)


def _impact(row: np.ndarray) -> Impact:
    """The finished :class:`Impact` of a row of the engine's impact table (columns ``exact_engine.IMPACT_COLUMNS``)."""
    contact, end, start, onset, in_phase, peak, peak_time, impulse = row.tolist()
    return Impact(int(contact), start, onset, bool(in_phase), peak, peak_time, impulse, end, True)


def _open_impacts(impacts: engine.Impacts) -> dict[int, Impact]:
    """The impacts still open at the end of the run, by contact."""
    found = {}
    for p in np.flatnonzero(impacts.is_open).tolist():
        start, onset, in_phase, peak, peak_time, impulse = impacts.impact[:, p].tolist()
        found[p] = Impact(p, start, onset, bool(in_phase), peak, peak_time, impulse)
    return found


class _VisitedModes:
    """The modes one run visited (``len``) and their dynamics (indexing), from the shared library."""

    def __init__(self, library: ModeLibrary, visited: set[Mode]) -> None:
        self.system = library.system
        self._library = library
        self._visited = visited

    def __getitem__(self, mode: Mode) -> ModeDynamics:
        return self._library[mode]

    def __len__(self) -> int:
        return len(self._visited)
