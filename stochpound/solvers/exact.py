"""The exact event-driven solver: matrix-exponential propagation of every mode.

Between events each mode is linear and time-invariant and the ground motion is
a polynomial (sampled motions) or a sine (harmonic motions) inside every
sample interval, so the state is advanced exactly by the propagators of
:mod:`stochpound.propagators`. Two event paths give the same run:

* ``events="compiled"`` (default): the whole run happens in the compiled
  engine :mod:`stochpound.solvers.exact_engine`, a port of the shared event
  and recording logic; Python only builds the modes the run reaches.
* ``events="python"``: the compiled loop
  :func:`stochpound.solvers.exact_kernel.advance_quiet` advances the sample
  intervals in which nothing happens, and every other interval is advanced
  sub-step by sub-step by the shared Python code itself
  (:func:`stochpound.events.first_crossing` on the exact flow,
  :func:`stochpound.events.settle`, :class:`stochpound.recorder.Recorder`),
  as the ``ivp`` path does with its integrator steps. It is the reference
  the compiled engine is tested against, and ~50× slower on event-rich runs.

Outputs, impact table and energy balance are those of the ``ivp`` path.
"""

from __future__ import annotations

import math
import weakref

import numpy as np
from threadpoolctl import ThreadpoolController

from stochpound.events import MAX_SETTLE_ITERATIONS, EventCounters, GuardStates, Step, first_crossing, initial_mode, settle
from stochpound.modes import FREE, Mode, ModeDynamics, ModeLibrary
from stochpound.propagators import (
    CHEBYSHEV_DEGREE,
    GAUSS_NODES,
    GAUSS_WEIGHTS,
    ModePropagator,
    PropagatorLibrary,
    interval_forcing,
    propagator_library,
    sample_ground,
)
from stochpound.motion import HarmonicMotion
from stochpound.recorder import ENERGY_TERMS, Impact, Recorder
from stochpound.scene import Scene
from stochpound.solvers import exact_engine as engine
from stochpound.solvers.exact_kernel import NEEDS_EVENTS, advance_quiet, work_arrays
from stochpound.solvers.ivp import _Run as IvpRun
from stochpound.system import System, build_system

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
        Run with one BLAS thread (small-matrix kernels are much slower threaded,
        MODEL.md §6); batch callers may limit threads once themselves instead.
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
    run = _CompiledRun if events == "compiled" else _PythonRun
    if not limit_threads:
        return run(scene).execute()
    with _thread_controller().limit(limits=1):
        return run(scene).execute()


_CONTROLLER: list[ThreadpoolController] = []


def _thread_controller() -> ThreadpoolController:
    """One :class:`ThreadpoolController` per process (finding the BLAS libraries takes ~1 ms)."""
    if not _CONTROLLER:
        _CONTROLLER.append(ThreadpoolController())
    return _CONTROLLER[0]


class KernelRecorder(Recorder):
    """A :class:`Recorder` that also exchanges its running totals with the compiled loop.

    The energy histories are rows of one (4, n_times) array, ``energy_block``,
    which the compiled loop writes directly.
    """

    def __post_init__(self) -> None:
        super().__post_init__()
        self.energy_block = np.zeros((len(ENERGY_TERMS), len(self.motion.times)))
        self.energy = dict(zip(ENERGY_TERMS, self.energy_block))

    def running_energy(self) -> np.ndarray:
        """Cumulative energy terms (input, damping, friction, impact), J."""
        return np.array([self._running[term] for term in ENERGY_TERMS])

    def set_running_energy(self, values: np.ndarray) -> None:
        """Replace the cumulative energy terms, J."""
        self._running.update(zip(ENERGY_TERMS, (float(v) for v in values)))

    def impact_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Per contact: impact open?, impulse (N·s), peak force (N) and its time (s)."""
        n_contacts = self.system.n_contacts
        is_open = np.zeros(n_contacts, dtype=bool)
        impulse, peak, peak_time = np.zeros(n_contacts), np.zeros(n_contacts), np.full(n_contacts, np.nan)
        for p, impact in self._open_impacts.items():
            is_open[p] = True
            impulse[p], peak[p], peak_time[p] = impact.impulse, impact.peak_force, impact.peak_time
        return is_open, impulse, peak, peak_time

    def store_impact_arrays(self, impulse: np.ndarray, peak: np.ndarray, peak_time: np.ndarray) -> None:
        """Write impulses and peaks back into the open impact records."""
        for p, impact in self._open_impacts.items():
            impact.impulse, impact.peak_force, impact.peak_time = float(impulse[p]), float(peak[p]), float(peak_time[p])

    def load_impacts(self, rows: np.ndarray, still_open: list[Impact], t_end: float) -> None:
        """Impacts from the engine's table (columns ``exact_engine.IMPACT_COLUMNS``) and those still open at t_end."""
        for row in rows:
            contact, start, end, onset, in_phase, peak, peak_time, impulse, complete = row
            self.impacts.append(Impact(int(contact), start, onset, bool(in_phase), peak, peak_time, impulse, end, bool(complete)))
        self._open_impacts.update({impact.contact: impact for impact in still_open})
        self.finish(t_end)

    def sample_at(self, indices: np.ndarray, dynamics: ModeDynamics, ground: np.ndarray) -> None:
        """Read-outs at samples ``indices`` whose states are stored, all in one mode (as :meth:`sample`).

        Parameters
        ----------
        indices : np.ndarray of int
            Sample indices.
        dynamics : ModeDynamics
            The mode at those samples.
        ground : np.ndarray
            a_g at every output time, m/s².
        """
        x = self.states[indices]
        self.forces[indices] = x @ dynamics.force_matrix.T + dynamics.force_constant
        self.friction[indices] = (
            x @ dynamics.friction_matrix.T + np.outer(ground[indices], dynamics.friction_ground) + dynamics.friction_constant
        )
        for b, state in enumerate(dynamics.mode.base):
            if state == FREE:
                state = np.sign(x[:, self.system.n_dof + self.system.base_dofs[b]])
            self.base_states[indices, b] = state


class _PythonRun:
    """One exact run with the shared Python event code (``events="python"``)."""

    def __init__(self, scene: Scene) -> None:
        self.motion = scene.motion
        self.propagators: PropagatorLibrary = propagator_library(build_system(scene), self.motion)
        self.system = self.propagators.system
        self.library = self.propagators.modes
        self.recorder = KernelRecorder(self.system, self.motion)
        self.counters = EventCounters()
        self.forcing = interval_forcing(self.motion)
        self.ground = sample_ground(self.motion)
        self.visited: set[Mode] = set()
        self.work = work_arrays(2 * self.system.n_dof + 5, _max_guards(self.system), self.system.n_contacts)

    def execute(self) -> tuple[Recorder, EventCounters, ModeLibrary]:
        times = self.motion.times
        x = self.system.initial_state.copy()
        mode, x, states, transitions = settle(self.library, self.motion, 0, float(times[0]), x, initial_mode(self.system), self.counters)
        self.recorder.on_transitions(float(times[0]), x, transitions, mode)
        self.recorder.on_contact_force(float(times[0]), mode, self.library[mode], x)
        self.recorder.sample(0, x, self.library[mode])
        k = 0
        while k < len(self.forcing):
            stop, status = self._quiet(k, x, mode, states)
            if status != NEEDS_EVENTS:
                break
            x, mode, states = self._interval(stop, x, mode, states)
            self.recorder.sample(stop + 1, x, self.library[mode])
            k = stop + 1
        self.recorder.finish(float(times[-1]))
        return self.recorder, self.counters, _VisitedModes(self.library, self.visited)

    def _propagator(self, mode: Mode) -> ModePropagator:
        self.visited.add(mode)
        return self.propagators[mode]

    def _quiet(self, k: int, x: np.ndarray, mode: Mode, states: GuardStates) -> tuple[int, int]:
        """Advance event-free intervals from k in the compiled loop; x becomes the state where it stopped."""
        propagator = self._propagator(mode)
        dynamics, system, recorder = propagator.dynamics, self.system, self.recorder
        is_open, impulse, peak, peak_time = recorder.impact_arrays()
        running = recorder.running_energy()
        stop, status = advance_quiet(
            k, x, self.forcing, self.motion.times, propagator.substeps, propagator.transition, propagator.nodes,
            0.5 * propagator.step * GAUSS_WEIGHTS,
            dynamics.A, dynamics.B, dynamics.c, dynamics.guard_matrix, dynamics.guard_ground, dynamics.guard_constant,
            states.threshold, states.tolerance, states.rearmable, states.disarmed,
            dynamics.force_matrix, dynamics.force_constant, dynamics.friction_matrix, dynamics.friction_ground,
            dynamics.friction_constant, system.contact_load, system.damping, system.influence,
            np.asarray(system.base_dofs, dtype=np.int64),
            is_open, impulse, peak, peak_time, running, recorder.states, recorder.energy_block, *self.work,
        )
        recorder.set_running_energy(running)
        recorder.store_impact_arrays(impulse, peak, peak_time)
        recorder.sample_at(np.arange(k + 1, stop + 1), dynamics, self.ground)
        return stop, status

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
        for t0, t1 in zip(edges[:-1], edges[1:]):
            dense = propagator.dense(t0, x, self.motion.derivatives(t0, k))
            x1 = dense(t1)
            crossing = first_crossing(dynamics, self.motion, k, Step(t0, t1, x, x1, dense), states, self.counters)
            if crossing is None:
                self.recorder.on_step(dynamics, k, t0, t1, dense)
                x = x1
                continue
            t_event, guard = crossing
            self.recorder.on_step(dynamics, k, t0, t_event, dense)
            return self._event(k, t_event, dense(t_event), mode, dynamics, guard)
        return t_end, x, mode, states

    # settle the event and record it exactly as the ivp path does (same attributes: library, motion, recorder, counters)
    _event = IvpRun._event


class _CompiledRun:
    """One exact run in the compiled engine (``events="compiled"``)."""

    def __init__(self, scene: Scene) -> None:
        self.motion = scene.motion
        self.propagators: PropagatorLibrary = propagator_library(build_system(scene), self.motion)
        self.system = self.propagators.system
        self.plant = _plant(self.system, self.motion)
        self.state = _run_state(self.system, len(self.motion.times))
        self.work = work_arrays(2 * self.system.n_dof + 5, _max_guards(self.system), self.system.n_contacts)

    def execute(self) -> tuple[Recorder, EventCounters, ModeLibrary]:
        state, system = self.state, self.system
        state.pending_mode[:] = mode_vector(initial_mode(system))
        state.pending_x[:] = system.initial_state
        state.clock[0] = self.motion.times[0]
        state.ints[engine.PENDING] = engine.INITIAL
        slots = _slots(self.propagators)
        while True:
            if len(state.visited) < len(slots.modes):
                state = self.state = state._replace(visited=np.resize(state.visited, 2 * len(slots.modes)))
            status = engine.run_engine(slots.tables, self.plant, state, *self.work)
            if status == engine.FINISHED:
                break
            if status == engine.NEED_MODE:
                slots.load(vector_mode(state.missing_mode, system.n_contacts))
            else:  # NEED_SPACE
                state = self.state = state._replace(impacts=np.concatenate([state.impacts, np.zeros_like(state.impacts)]))
        return self._recorder(slots), self._counters(), self._visited(slots)

    def _recorder(self, slots: "_Slots") -> Recorder:
        state = self.state
        recorder = KernelRecorder(self.system, self.motion)
        recorder.states[:] = state.states
        recorder.energy_block[:] = state.energy
        ground = sample_ground(self.motion)
        for i in np.unique(state.sample_modes):
            recorder.sample_at(np.flatnonzero(state.sample_modes == i), self.propagators.modes[slots.modes[i]], ground)
        recorder.load_impacts(state.impacts[: state.ints[engine.N_IMPACTS]], _open_impacts(state), float(self.motion.times[-1]))
        return recorder

    def _counters(self) -> EventCounters:
        ints = self.state.ints
        return EventCounters(total=int(ints[engine.TOTAL]), chatter_cycles=int(ints[engine.CHATTER]), grazing_checks=int(ints[engine.GRAZING]))

    def _visited(self, slots: "_Slots") -> "_VisitedModes":
        modes = {slots.modes[i] for i in np.flatnonzero(self.state.visited[: len(slots.modes)])}
        return _VisitedModes(self.propagators.modes, modes)


def mode_vector(mode: Mode) -> np.ndarray:
    """The engine's int64 vector of a mode: closed flags, then base states."""
    return np.array([int(flag) for flag in mode.closed] + list(mode.base), dtype=np.int64)


def vector_mode(vector: np.ndarray, n_contacts: int) -> Mode:
    """The :class:`Mode` of an engine mode vector."""
    return Mode(tuple(bool(v) for v in vector[:n_contacts]), tuple(int(v) for v in vector[n_contacts:]))


def _open_impacts(state) -> list[Impact]:
    """The impacts still open at the end of the run."""
    return [
        Impact(int(p), float(state.impact_start[p]), float(state.impact_onset[p]), bool(state.impact_in_phase[p]),
               float(state.impact_peak[p]), float(state.impact_peak_time[p]), float(state.impact_impulse[p]))
        for p in np.flatnonzero(state.is_open)
    ]


def _plant(system: System, motion) -> engine.Plant:
    """System and motion arrays of the engine."""
    rows = system.total_displacement
    if isinstance(motion, HarmonicMotion):
        coefficients, harmonic = np.zeros((1, 4)), np.array([motion.amplitude, motion.omega, motion.phase], float)
    else:
        coefficients, harmonic = np.ascontiguousarray(motion.coefficients, float), np.zeros(0)
    return engine.Plant(
        n_dof=system.n_dof,
        geometry=system.contact_geometry,
        gap=system.contact_gap,
        load=system.contact_load,
        tensile=system.contact_tensile.astype(np.bool_),
        damping=system.damping,
        influence=system.influence,
        base_dofs=np.asarray(system.base_dofs, dtype=np.int64),
        left_rows=np.ascontiguousarray(rows[system.contact_rows[:, 0]]).reshape(system.n_contacts, system.n_dof),
        right_rows=np.ascontiguousarray(rows[system.contact_rows[:, 1]]).reshape(system.n_contacts, system.n_dof),
        times=np.asarray(motion.times, float),
        forcing=np.ascontiguousarray(interval_forcing(motion)),
        coefficients=coefficients,
        harmonic=harmonic,
        gauss_nodes=GAUSS_NODES,
        gauss_weights=GAUSS_WEIGHTS,
    )


def _max_guards(system: System) -> int:
    return 2 * system.n_contacts + 2 * len(system.base_dofs)


def _run_state(system: System, n_times: int) -> engine.RunState:
    """Fresh arrays of everything a run changes."""
    size, n_contacts, n_guards = 2 * system.n_dof, system.n_contacts, _max_guards(system)
    length = n_contacts + len(system.base_dofs)
    floats = lambda n: np.zeros(n)  # noqa: E731
    return engine.RunState(
        clock=floats(1), ints=np.zeros(engine.N_INTS, dtype=np.int64), x=floats(size), pending_x=floats(size),
        pending_mode=np.zeros(length, dtype=np.int64), missing_mode=np.zeros(length, dtype=np.int64),
        threshold=floats(n_guards), tolerance=floats(n_guards), rearmable=np.zeros(n_guards, dtype=np.bool_),
        disarmed=np.zeros(n_guards, dtype=np.bool_), is_open=np.zeros(n_contacts, dtype=np.bool_),
        impact_start=floats(n_contacts), impact_onset=floats(n_contacts), impact_in_phase=np.zeros(n_contacts, dtype=np.bool_),
        impact_peak=floats(n_contacts), impact_peak_time=floats(n_contacts), impact_impulse=floats(n_contacts),
        impacts=np.zeros((max(64, 4 * n_contacts), len(engine.IMPACT_COLUMNS))), running=floats(4),
        states=np.zeros((n_times, size)), energy=np.zeros((len(ENERGY_TERMS), n_times)),
        sample_modes=np.zeros(n_times, dtype=np.int64), visited=np.zeros(64, dtype=np.bool_),
    )


TABLE_BUDGET = 256 * 2**20
"""Largest size of the engine tables of one library, bytes: beyond it modes take turns in the slots."""

_SLOTS: "weakref.WeakKeyDictionary[PropagatorLibrary, _Slots]" = weakref.WeakKeyDictionary()


def _slots(library: PropagatorLibrary) -> "_Slots":
    """The engine tables of ``library``, shared by its runs."""
    slots = _SLOTS.get(library)
    if slots is None:
        slots = _SLOTS[library] = _Slots(library)
    return slots


class _Slots:
    """The engine's tables (:class:`engine.Tables`) of a library's modes, one mode per slot.

    The tables grow to :data:`TABLE_BUDGET` bytes (and at least to a settling
    chain's length); beyond that a new mode takes the slot filled longest ago,
    and the mode it held is loaded again if the engine asks for it. Every
    mode keeps one id (``modes[id]``): the engine records ids per sample.
    """

    def __init__(self, library: PropagatorLibrary) -> None:
        self.library = library
        self.modes: list[Mode] = []
        self._ids: dict[Mode, int] = {}
        self._resident: list[Mode] = []
        self._oldest = 0
        self._n_guards = _max_guards(library.system)
        self.tables = self._empty(1, 1)
        row_bytes = sum(np.asarray(value).nbytes for value in _empty_rows(library.system, self._n_guards, CHEBYSHEV_DEGREE + 1).values())
        self._capacity = max(MAX_SETTLE_ITERATIONS + 2, TABLE_BUDGET // row_bytes)

    def load(self, mode: Mode) -> None:
        """Put ``mode`` into a slot."""
        propagator = self.library[mode]
        mode_id = self._ids.setdefault(mode, len(self._ids))
        if mode_id == len(self.modes):
            self.modes.append(mode)
        filled = len(self._resident)
        if filled < self._capacity:
            slot = filled
            self._resident.append(mode)
        else:
            slot, self._oldest = self._oldest, (self._oldest + 1) % filled
            self._resident[slot] = mode
        degree = max(self.tables.chebyshev.shape[1], len(propagator.chebyshev))
        self._grow(slot + 1, degree)
        rows = _mode_rows(mode, propagator, self._n_guards, degree)
        rows["ids"] = np.int64(mode_id)
        for name in engine.Tables._fields:
            getattr(self.tables, name)[slot] = rows[name]

    def _grow(self, slots: int, degree: int) -> None:
        """Make room for ``slots`` slots and ``degree`` Chebyshev terms, keeping the filled slots."""
        tables = self.tables
        if slots <= len(tables.hashes) and degree <= tables.chebyshev.shape[1]:
            return
        grown = self._empty(max(len(tables.hashes), min(self._capacity, 2 * slots)), degree)
        for old, new in zip(tables, grown):
            if old.ndim > 1:
                new[: len(old), : old.shape[1]] = old
            else:
                new[: len(old)] = old
        self.tables = grown

    def _empty(self, size: int, degree: int) -> engine.Tables:
        """Tables of ``size`` empty slots (never matched: invalid mode vectors)."""
        rows = _empty_rows(self.library.system, self._n_guards, degree)
        tables = engine.Tables(**{name: np.zeros((size,) + np.shape(rows[name]), np.asarray(rows[name]).dtype) for name in engine.Tables._fields})
        tables.modes[:] = -9
        return tables


def _mode_rows(mode: Mode, propagator: ModePropagator, n_guards: int, degree: int) -> dict[str, np.ndarray]:
    """One mode's entries of :class:`engine.Tables` (guards and Chebyshev terms padded)."""
    d = propagator.dynamics
    count = len(d.guard_kind)

    def pad(values: np.ndarray, dtype=float) -> np.ndarray:
        out = np.zeros((n_guards,) + values.shape[1:], dtype=dtype)
        out[:count] = values
        return out

    chebyshev = np.zeros((degree,) + propagator.chebyshev.shape[1:])
    chebyshev[: len(propagator.chebyshev)] = propagator.chebyshev
    vector = mode_vector(mode)
    return {
        "hashes": np.int64(engine.mode_hash(vector)), "modes": vector, "A": d.A, "B": d.B, "c": d.c,
        "G": pad(d.guard_matrix), "gh": pad(d.guard_ground), "g0": pad(d.guard_constant),
        "kind": pad(d.guard_kind, np.int64), "target": pad(d.guard_target, np.int64), "direction": pad(d.guard_direction, np.int64),
        "n_guards": np.int64(count), "F": d.force_matrix, "f0": d.force_constant, "Fr": d.friction_matrix,
        "frg": d.friction_ground, "frc": d.friction_constant, "transition": propagator.transition, "nodes": propagator.nodes,
        "chebyshev": chebyshev, "substeps": np.int64(propagator.substeps), "step": np.float64(propagator.step),
    }


def _empty_rows(system: System, n_guards: int, degree: int) -> dict[str, np.ndarray]:
    """An empty slot's row (never matched: its hash and mode are invalid)."""
    size, width, n_contacts, n_buildings = 2 * system.n_dof, 2 * system.n_dof + 5, system.n_contacts, len(system.base_dofs)
    return {
        "hashes": np.int64(0), "modes": np.full(n_contacts + n_buildings, -9, dtype=np.int64), "ids": np.int64(0), "A": np.zeros((size, size)),
        "B": np.zeros(size), "c": np.zeros(size), "G": np.zeros((n_guards, size)), "gh": np.zeros(n_guards),
        "g0": np.zeros(n_guards), "kind": np.zeros(n_guards, np.int64), "target": np.zeros(n_guards, np.int64),
        "direction": np.zeros(n_guards, np.int64), "n_guards": np.int64(0), "F": np.zeros((n_contacts, size)),
        "f0": np.zeros(n_contacts), "Fr": np.zeros((n_buildings, size)), "frg": np.zeros(n_buildings),
        "frc": np.zeros(n_buildings), "transition": np.zeros((width, width)), "nodes": np.zeros((5, width, width)),
        "chebyshev": np.zeros((degree, size, width)), "substeps": np.int64(1), "step": np.float64(1.0),
    }


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
