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
This module also lays out the engine's arrays (:class:`_Slots`, :func:`_plant`,
:func:`_state`).
"""

from __future__ import annotations

import itertools
import math
import weakref
from collections import namedtuple

import numpy as np
from threadpoolctl import ThreadpoolController

from stochpound.events import (
    MAX_SETTLE_ITERATIONS,
    EventCounters,
    GuardStates,
    Step,
    first_crossing,
    initial_mode,
)
from stochpound.modes import BoundedCache, Mode, ModeDynamics, ModeLibrary
from stochpound.motion import GroundMotion, HarmonicMotion
from stochpound.propagators import (
    CHEBYSHEV_DEGREE,
    GAUSS_WEIGHTS,
    ModePropagator,
    PropagatorLibrary,
    interval_forcing,
    propagator_library,
    sample_ground,
)
from stochpound.recorder import ENERGY_TERMS, Impact, Recorder, settle_and_record
from stochpound.scene import Scene
from stochpound.solvers import exact_engine as engine
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


Built = namedtuple("Built", "table dynamics propagators")
"""The engine's arrays of the modes in a library's slots (:class:`_Slots`)."""
Plant = namedtuple("Plant", "motion layout")
"""The engine's arrays of a system and motion (:func:`_plant`)."""
State = namedtuple("State", "run arming impacts outputs")
"""The engine's arrays of one run (:func:`_state`)."""


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
        self.plant = _plant(self.system, self.motion)
        state = _state(self.system, len(self.motion.times))
        outputs = state.outputs._replace(running=self.recorder.running, states=self.recorder.states, energy=self.recorder.energy_history)
        self.state = state._replace(outputs=outputs)
        self.work = _work_arrays(self.system, _slots(self.propagators))  # the quiet loop uses no Chebyshev rows: never too narrow

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
        slots = _slots(self.propagators)
        run.ints[engine.K], run.ints[engine.MODE], run.clock[0] = k, slots.slot(mode), self.motion.times[k]
        run.x[:] = x
        arming.threshold[:n], arming.tolerance[:n], arming.rearmable[:n], arming.disarmed[:n] = (
            states.threshold, states.tolerance, states.rearmable, states.disarmed
        )
        _put_open_impacts(self.recorder.open_impacts, impacts)
        status = engine.run_engine(*slots.tables, *self.plant, *self.state, *self.work, False)
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

    def __init__(self, scene: Scene) -> None:
        self.motion = scene.motion
        self.propagators: PropagatorLibrary = propagator_library(build_system(scene), self.motion)
        self.system = self.propagators.system
        self.plant = _plant(self.system, self.motion)
        self.state = _state(self.system, len(self.motion.times))

    def execute(self) -> tuple[Recorder, EventCounters, ModeLibrary]:
        run, system = self.state.run, self.system
        run.pending_mode[:] = mode_vector(initial_mode(system))
        run.pending_x[:] = system.initial_state
        run.clock[0] = self.motion.times[0]
        run.ints[engine.PENDING] = engine.INITIAL
        slots = _slots(self.propagators)
        while True:
            if len(self.state.run.visited) < len(slots.modes):
                visited = np.resize(self.state.run.visited, 2 * len(slots.modes))
                self.state = self.state._replace(run=self.state.run._replace(visited=visited))
            status = engine.run_engine(*slots.tables, *self.plant, *self.state, *_work_arrays(system, slots), True)
            if status == engine.FINISHED:
                break
            if status == engine.NEED_MODE:
                slots.load(vector_mode(run.missing_mode, system.n_contacts))
            else:  # NEED_SPACE
                table = self.state.impacts.table
                self.state = self.state._replace(impacts=self.state.impacts._replace(table=np.concatenate([table, np.zeros_like(table)])))
        return self._recorder(slots), self._counters(), self._visited(slots)

    def _recorder(self, slots: "_Slots") -> Recorder:
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

    def _visited(self, slots: "_Slots") -> "_VisitedModes":
        modes = {slots.modes[i] for i in np.flatnonzero(self.state.run.visited[: len(slots.modes)])}
        return _VisitedModes(self.propagators.modes, modes)


def mode_vector(mode: Mode) -> np.ndarray:
    """The engine's int64 vector of a mode: closed flags, then base states."""
    return np.array([int(flag) for flag in mode.closed] + list(mode.base), dtype=np.int64)


def vector_mode(vector: np.ndarray, n_contacts: int) -> Mode:
    """The :class:`Mode` of an engine mode vector."""
    return Mode(tuple(bool(v) for v in vector[:n_contacts]), tuple(int(v) for v in vector[n_contacts:]))


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


def _plant(system: System, motion: GroundMotion) -> Plant:
    """System and motion arrays of the engine."""
    rows = system.total_displacement
    if isinstance(motion, HarmonicMotion):
        coefficients, harmonic = np.zeros((1, 4)), np.array([motion.amplitude, motion.omega, motion.phase], float)
    else:
        coefficients, harmonic = np.ascontiguousarray(motion.coefficients, float), np.zeros(0)
    floor_rows = [np.ascontiguousarray(rows[system.contact_rows[:, side]]).reshape(system.n_contacts, system.n_dof) for side in (0, 1)]
    return Plant(
        engine.Motion(np.asarray(motion.times, float), np.ascontiguousarray(interval_forcing(motion)), coefficients, harmonic),
        engine.Layout(system.contact_geometry, system.contact_gap, system.contact_tensile.astype(np.bool_), *floor_rows,
                      np.asarray(system.base_dofs, dtype=np.int64)),
    )


def _max_guards(system: System) -> int:
    return 2 * system.n_contacts + 2 * len(system.base_dofs)


def _work_arrays(system: System, slots: "_Slots") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The engine's work arrays for ``system`` and the current Chebyshev width of ``slots`` (:func:`exact_engine.work_arrays`)."""
    mode_size = system.n_contacts + len(system.base_dofs)
    return engine.work_arrays(2 * system.n_dof, _max_guards(system), system.n_contacts, mode_size, slots.arrays["chebyshev"].shape[2])


def _state(system: System, n_times: int) -> State:
    """Fresh arrays of everything a run changes."""
    size, n_contacts, n_guards = 2 * system.n_dof, system.n_contacts, _max_guards(system)
    length = n_contacts + len(system.base_dofs)
    return State(
        engine.Run(np.zeros(1), np.zeros(engine.N_INTS, dtype=np.int64), np.zeros(size), np.zeros(size),
                   np.zeros(length, dtype=np.int64), np.zeros(length, dtype=np.int64), np.zeros(64, dtype=np.bool_)),
        engine.Arming(np.zeros(n_guards), np.zeros(n_guards), np.zeros(n_guards, dtype=np.bool_), np.zeros(n_guards, dtype=np.bool_)),
        engine.Impacts(np.zeros(n_contacts, dtype=np.bool_), np.zeros((6, n_contacts)),
                       np.zeros((max(64, 4 * n_contacts), len(engine.IMPACT_COLUMNS)))),
        engine.Outputs(np.zeros(len(ENERGY_TERMS)), np.zeros((n_times, size)), np.zeros((len(ENERGY_TERMS), n_times)),
                       np.zeros(n_times, dtype=np.int64)),
    )


TABLE_BUDGET = 256 * 2**20
"""Largest size of the engine arrays of one library, bytes: beyond it modes take turns in the slots."""

ENERGY_BUDGET = 256 * 2**20
"""Largest size of the cached :func:`_energy_rows` of one library's modes, bytes (they outlive their slots)."""

INITIAL_SLOTS = 128
"""Slots allocated at first (doubled when full, up to the budget)."""

_SLOTS: "weakref.WeakKeyDictionary[PropagatorLibrary, _Slots]" = weakref.WeakKeyDictionary()


def _slots(library: PropagatorLibrary) -> "_Slots":
    """The engine arrays of ``library``'s modes, shared by its runs."""
    slots = _SLOTS.get(library)
    if slots is None:
        slots = _SLOTS[library] = _Slots(library)
    return slots


class _Slots:
    """The engine's arrays (:class:`Built`) of a library's modes, one mode per slot.

    The arrays grow to :data:`TABLE_BUDGET` bytes (and at least to a settling
    chain's length); beyond that a new mode takes the slot filled longest ago,
    and the mode it held is loaded again when the engine asks for it. Every
    mode keeps one id (``modes[id]``), which the engine records per sample.
    Empty slots never match a mode (their mode vector is invalid).
    """

    def __init__(self, library: PropagatorLibrary) -> None:
        self.library = library
        self.modes: list[Mode] = []
        self._ids: dict[Mode, int] = {}
        self._slot: dict[Mode, int] = {}
        self._held: list[Mode] = []
        self._oldest = 0
        self._energy: BoundedCache[Mode, tuple[np.ndarray, np.ndarray]] = BoundedCache(ENERGY_BUDGET, _total_bytes)
        self.arrays: dict[str, np.ndarray] = {}
        width = (CHEBYSHEV_DEGREE + 1) * 2 * library.system.n_dof  # the usual Chebyshev rows (grown if a mode's are wider)
        self._grow(1, width)
        self._capacity = max(MAX_SETTLE_ITERATIONS + 2, TABLE_BUDGET // sum(array[0].nbytes for array in self.arrays.values()))
        self._grow(min(self._capacity, INITIAL_SLOTS), width)

    @property
    def tables(self) -> Built:
        """The arrays, grouped as the engine takes them."""
        return Built(*(group(**{name: self.arrays[name] for name in group._fields}) for group in (engine.ModeTable, engine.Dynamics, engine.Propagators)))

    def slot(self, mode: Mode) -> int:
        """The slot of ``mode`` (loaded if it holds none)."""
        slot = self._slot.get(mode)
        return self.load(mode) if slot is None else slot

    def load(self, mode: Mode) -> int:
        """Put ``mode`` into a free slot, or else the one filled longest ago; return the slot."""
        propagator = self.library[mode]
        energy = self._energy.get(mode)
        if energy is None:  # worth keeping: their products cost more than building the propagator
            energy = _energy_rows(self.library.system, propagator)
            self._energy.put(mode, energy)
        row = _mode_rows(self.library.system, mode, propagator, energy)
        row["ids"] = np.int64(self._ids.setdefault(mode, len(self._ids)))
        if row["ids"] == len(self.modes):
            self.modes.append(mode)
        slot, size = self._take_slot(mode), len(self.arrays["modes"])
        if slot == size or row["chebyshev"].shape[1] > self.arrays["chebyshev"].shape[2]:
            self._grow(min(self._capacity, 2 * size) if slot == size else size, row["chebyshev"].shape[1])
        if row["chebyshev"].shape[1] < self.arrays["chebyshev"].shape[2]:
            self.arrays["chebyshev"][slot] = 0  # zero padded
        for name, value in row.items():
            self.arrays[name][(slot, ...) + tuple(slice(0, n) for n in np.shape(value))] = value
        return slot

    def _take_slot(self, mode: Mode) -> int:
        """The next free slot, or else the one filled longest ago, now held by ``mode``."""
        slot = len(self._held)
        if slot < self._capacity:
            self._held.append(mode)
        else:
            slot, self._oldest = self._oldest, (self._oldest + 1) % self._capacity
            del self._slot[self._held[slot]]
            self._held[slot] = mode
        self._slot[mode] = slot
        return slot

    def _grow(self, capacity: int, width: int) -> None:
        """Reallocate for ``capacity`` slots and Chebyshev rows of ``width`` (at least the current), keeping the filled slots."""
        old = self.arrays
        width = max(width, old["chebyshev"].shape[2]) if old else width
        self.arrays = {}
        for name, value in _placeholder(self.library.system, width).items():
            self.arrays[name] = np.zeros((capacity,) + np.shape(value), np.asarray(value).dtype)  # untouched pages stay unallocated
            if np.any(value):
                self.arrays[name][:] = value
        for name, array in old.items():
            self.arrays[name][(slice(0, len(array)), ...) + tuple(slice(0, n) for n in array.shape[1:])] = array


def _mode_rows(system: System, mode: Mode, propagator: ModePropagator, energy: tuple[np.ndarray, np.ndarray]) -> dict[str, np.ndarray]:
    """One mode's entries of the :class:`Built` arrays but its id (guards padded to the system's largest count).

    ``energy`` is the mode's :func:`_energy_rows`.
    """
    d = propagator.dynamics
    count, n_guards = len(d.guard_kind), _max_guards(system)
    codes = np.zeros((3, n_guards), dtype=np.int64)
    codes[:, :count] = d.guard_kind, d.guard_target, d.guard_direction
    guard = np.zeros((n_guards, d.A.shape[1] + 2))
    guard[:count] = _affine(d.guard_matrix, d.guard_ground, d.guard_constant)
    power, forms = energy
    return {
        "modes": mode_vector(mode), "codes": codes, "n_guards": np.int64(count), "substeps": np.int64(propagator.substeps),
        "rate": _affine(d.A, d.B, d.c), "guard": guard, "force": _affine(d.force_matrix, 0.0, d.force_constant), "power": power,
        "propagate": np.concatenate([propagator.transition.T, forms], axis=1), "step": np.float64(propagator.step),
        "chebyshev": propagator.chebyshev.reshape(-1, propagator.transition.shape[0]).T,
    }


def _energy_rows(system: System, propagator: ModePropagator) -> tuple[np.ndarray, np.ndarray]:
    """A mode's power forms and its sub-step forms and impulses (:func:`_sub_step_forms`), stacked and transposed (Z × 4Z, Z × (4Z + n_contacts))."""
    d, width = propagator.dynamics, propagator.transition.shape[0]
    force = _in_z(_affine(d.force_matrix, 0.0, d.force_constant), width)
    friction = _in_z(_affine(d.friction_matrix, d.friction_ground, d.friction_constant), width)
    power = _power_forms(system, force, friction).reshape(-1, width).T
    return np.ascontiguousarray(power), np.concatenate([form.T for form in _sub_step_forms(system, propagator, force, friction)], axis=1)


def _total_bytes(arrays: tuple[np.ndarray, ...]) -> int:
    return sum(array.nbytes for array in arrays)


def _affine(matrix: np.ndarray, ground: np.ndarray | float, constant: np.ndarray) -> np.ndarray:
    """The engine's affine map [matrix | ground | constant] of ``matrix · x + ground a_g + constant``."""
    return np.column_stack([matrix, np.broadcast_to(ground, len(matrix)), constant])


def _power_forms(system: System, force: np.ndarray, friction: np.ndarray) -> np.ndarray:
    """Quadratic forms P (4 × Z × Z) of the input, damping, friction and impact powers (``Recorder.on_step``).

    The power of each force is zᵀ P z for the augmented state z = [x, w, 1]
    (only a_g = w[0] and the constant 1 enter), W: −a_g (ι · v), vᵀ C v,
    −Σ (friction force) ṡ over sliding bases, Σ F (load · v) over contacts.
    ``force`` and ``friction`` are the mode's contact and friction forces
    (rows acting on z).
    """
    n, size = system.n_dof, 2 * system.n_dof
    velocity = slice(n, size)
    power = np.zeros((4,) + (force.shape[1],) * 2)
    power[0, size, velocity] = -system.influence
    power[1, velocity, velocity] = system.damping
    sliding_rows, sliding_bases = _sliding(system)
    power[2, sliding_rows] = -friction[sliding_bases]
    power[3, velocity] = system.contact_load.T @ force
    return power


def _sub_step_forms(system: System, propagator: ModePropagator, force: np.ndarray, friction: np.ndarray) -> list[np.ndarray]:
    """Energy terms and impulses of one sub-step as functions of z(t0) (``Recorder.on_step``'s quadrature, combined).

    The 5-point Gauss–Legendre integral of a power zᵀ P z (:func:`_power_forms`)
    over a sub-step is z(t0)ᵀ Q z(t0) with Q = Σᵢ wᵢ Nᵢᵀ P Nᵢ (Nᵢ the node
    propagators, wᵢ the weights), computed from the factors P = Lᵀ R of each
    power as Σᵢ (wᵢ L Nᵢ)ᵀ (R Nᵢ); the impulses are linear, r · z(t0).

    Returns
    -------
    list of np.ndarray
        Q of the four powers (Z × Z each, J) and the impulse rows of every
        contact (n_contacts × Z, N·s).
    """
    n, size, width = system.n_dof, 2 * system.n_dof, force.shape[1]
    weights = 0.5 * propagator.step * GAUSS_WEIGHTS
    nodes = propagator.nodes
    velocity = nodes[:, n:size]
    weighted_velocity = weights[:, None, None] * velocity
    sliding_rows, sliding_bases = _sliding(system)
    loaded = np.flatnonzero(np.any(force, axis=1))  # the rows of open contacts are zero
    factors = [
        (weights[:, None] * nodes[:, size], -system.influence @ velocity),
        (weighted_velocity, system.damping @ velocity),
        (weights[:, None, None] * nodes[:, sliding_rows], -friction[sliding_bases] @ nodes),
        (system.contact_load[loaded] @ weighted_velocity, force[loaded] @ nodes),
    ]
    forms = [left.reshape(-1, width).T @ right.reshape(-1, width) for left, right in factors]
    impulses = np.zeros((len(force), width))
    impulses[loaded] = force[loaded] @ np.tensordot(weights, nodes, 1)
    return [*forms, impulses]


def _sliding(system: System) -> tuple[np.ndarray, np.ndarray]:
    """The state rows of the sliding bases' velocities, and those bases' indices."""
    bases = np.array([b for b, dof in enumerate(system.base_dofs) if dof >= 0], dtype=np.int64)
    return system.n_dof + np.asarray(system.base_dofs, dtype=np.int64)[bases], bases


def _in_z(rows: np.ndarray, width: int) -> np.ndarray:
    """Affine rows [x-coefficients | a_g coefficient | constant] as rows acting on z = [x, w, 1]."""
    size = rows.shape[1] - 2
    out = np.zeros((len(rows), width))
    out[:, :size], out[:, size], out[:, width - 1] = rows[:, :size], rows[:, size], rows[:, size + 1]
    return out


def _placeholder(system: System, chebyshev_width: int) -> dict[str, np.ndarray]:
    """An empty slot of the :class:`Built` arrays (it matches no mode: its mode vector is invalid)."""
    size, n_contacts, n_guards = 2 * system.n_dof, system.n_contacts, _max_guards(system)
    width = size + 5
    return {
        "modes": np.full(n_contacts + len(system.base_dofs), -9, dtype=np.int64), "ids": np.int64(0), "codes": np.zeros((3, n_guards), np.int64),
        "n_guards": np.int64(0), "substeps": np.int64(1), "rate": np.zeros((size, size + 2)),
        "guard": np.zeros((n_guards, size + 2)), "force": np.zeros((n_contacts, size + 2)), "power": np.zeros((width, 4 * width)),
        "propagate": np.zeros((width, 5 * width + n_contacts)), "chebyshev": np.zeros((width, chebyshev_width)),
        "step": np.float64(1.0),
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
