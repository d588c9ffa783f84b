"""One run of the event engine: the loop both solvers share.

:func:`stochpound.solvers.engine.run_engine` runs a whole simulation and
stops only for what compiled code cannot do: build a mode it reaches for
the first time (``NEED_MODE``), grow its impact table (``NEED_SPACE``) or,
when the flow is supplied from outside, take the next step of an
integrator (``NEED_STEP``). :class:`EngineRun` answers those requests and
turns the engine's arrays into a :class:`~stochpound.results.record.Recorder`.

* ``method="exact"`` (:mod:`stochpound.solvers.exact`): the engine advances
  every mode with its exact propagators; no step is supplied.
* ``method="ivp"`` (:mod:`stochpound.solvers.ivp`): a scipy integrator
  supplies the steps (a :class:`Stepper`); the engine locates and settles
  every event on the integrator's dense output and records the run, with
  the same code as for the exact flow.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from typing import Protocol

import numpy as np

from stochpound.model.modes import Mode, ModeDynamics, ModeLibrary, initial_mode
from stochpound.model.readouts import Readouts
from stochpound.model.system import System
from stochpound.motions.ground import GroundMotion
from stochpound.results.record import EventCounters, Impact, Recorder
from stochpound.solvers import engine, first_call, tables
from stochpound.solvers.propagators import PropagatorLibrary, sample_ground


class Stepper(Protocol):
    """Supplies the engine's flow step by step (an integrator)."""

    degree: int
    """Chebyshev degree of the supplied dense output."""

    def step(self, dynamics: ModeDynamics, k: int, t: float, x: np.ndarray, t_end: float, supplied: engine.Supplied, onsets: np.ndarray) -> None:
        """Fill ``supplied`` with the next step from (t, ξ = x) in mode ``dynamics`` inside motion interval k, ending by ``t_end``.

        ``onsets``: each impact element's current impact approach velocity (m/s).
        """


class EngineRun:
    """One simulation in the event engine.

    Parameters
    ----------
    system : System
    motion : GroundMotion
    library : PropagatorLibrary or ModeLibrary
        The exact propagators of the modes (exact flow) or their dynamics
        only (flow supplied by ``stepper``).
    stepper : Stepper, optional
        Supplies the flow; required with a :class:`~stochpound.model.modes.ModeLibrary`.
    building : callable, optional
        Context manager entered while a mode is built (e.g. one BLAS thread).
    """

    def __init__(self, system: System, motion: GroundMotion, library: PropagatorLibrary | ModeLibrary, stepper: Stepper | None = None,
                 building: Callable[[], contextlib.AbstractContextManager] = contextlib.nullcontext) -> None:
        self.system, self.motion = system, motion
        self.stepper, self.building = stepper, building
        self.readouts = Readouts(system)
        self.slots = tables.slots_of(library)
        self.plant = tables.plant_arrays(system, motion)
        self.state = tables.run_state(system, len(motion.times), stepper.degree if stepper else 0)

    def execute(self) -> tuple[Recorder, EventCounters, VisitedModes]:
        """Run the simulation; return what it recorded, its event counts and the modes it visited."""
        run, system, slots = self.state.run, self.system, self.slots
        run.pending_mode[:] = tables.mode_vector(initial_mode(system))
        run.pending_x[: 2 * system.n_dof] = system.initial_state
        run.clock[0] = self.motion.times[0]
        run.ints[engine.PENDING] = engine.INITIAL
        while True:
            if len(self.state.run.visited) < len(slots.modes):
                self.state = self.state._replace(run=self.state.run._replace(visited=np.resize(self.state.run.visited, 2 * len(slots.modes))))
            status = first_call.run(*slots.tables, *self.plant, *self.state, *tables.work_arrays_for(system, slots), self.stepper is not None)
            if status == engine.FINISHED:
                break
            if status == engine.NEED_MODE:  # the only step that builds propagators (matrix exponentials)
                with self.building():
                    slots.load(tables.vector_mode(run.missing_mode, system.n_elements, len(system.bases)))
            elif status == engine.NEED_SPACE:
                table = self.state.impacts.table
                self.state = self.state._replace(impacts=self.state.impacts._replace(table=np.concatenate([table, np.zeros_like(table)])))
            elif status == engine.NEED_STEP:
                self._supply_step()
            else:  # NEED_READOUTS
                self._supply_readouts()
        return self.record(), self.counters(), self.visited()

    def _supply_step(self) -> None:
        """Have the stepper fill the supplied step from the engine's current time, state and mode."""
        run = self.state.run
        k = int(run.ints[engine.K])
        mode = self.slots.modes[int(self.slots.arrays["ids"][run.ints[engine.MODE]])]
        self.stepper.step(self.slots.dynamics(mode), k, float(run.clock[0]), run.x, float(self.motion.times[k + 1]), self.state.supplied,
                          self.state.impacts.impact[engine.ONSET])
        run.ints[engine.READY] = 1

    def _supply_readouts(self) -> None:
        """Append the read-outs (f, ḟ) the engine asked for while settling: a mode's slot, at ``readouts.x``."""
        run, readouts = self.state.run, self.state.readouts
        slot, row = int(run.ints[engine.READOUT_SLOT]), int(run.ints[engine.N_READOUTS])
        mode = self.slots.modes[int(self.slots.arrays["ids"][slot])]
        k, t = int(run.ints[engine.K]), float(run.clock[0])
        readouts.values[row] = self.readouts.at_instant(self.slots.dynamics(mode), readouts.x[: 2 * self.system.n_dof], self.motion.derivatives(t, k)[:2],
                                                        self.state.impacts.impact[engine.ONSET])
        readouts.slots[row] = slot
        run.ints[engine.N_READOUTS] = row + 1

    def record(self) -> Recorder:
        """The run's :class:`~stochpound.results.record.Recorder` from the engine's outputs (after :meth:`execute`)."""
        outputs, impacts, run = self.state.outputs, self.state.impacts, self.state.run
        recorder = Recorder(self.system, self.motion)
        recorder.states[:] = outputs.states
        recorder.energy_history[:] = outputs.energy
        recorder.peaks[:] = outputs.peaks
        ground = sample_ground(self.motion)
        for i in np.flatnonzero(run.visited[: len(self.slots.modes)]):
            indices = np.flatnonzero(outputs.sample_modes == i)
            recorder.sample_at(indices, self.slots.dynamics(self.slots.modes[i]), ground[indices])
        finished = [_impact(row) for row in impacts.table[: run.ints[engine.N_IMPACTS]]]
        recorder.impacts = sorted(finished + _open_impacts(impacts, float(self.motion.times[-1])), key=lambda i: (i.start, i.contact))
        return recorder

    def counters(self) -> EventCounters:
        """The run's event counts (after :meth:`execute`)."""
        ints = self.state.run.ints
        return EventCounters(total=int(ints[engine.TOTAL]), chatter_cycles=int(ints[engine.CHATTER]), grazing_checks=int(ints[engine.GRAZING]))

    def visited(self) -> VisitedModes:
        """The modes the run visited (after :meth:`execute`)."""
        run = self.state.run
        return VisitedModes(self.slots, {self.slots.modes[i] for i in np.flatnonzero(run.visited[: len(self.slots.modes)])})


def _impact(row: np.ndarray) -> Impact:
    """The finished :class:`Impact` of a row of the engine's impact table (columns ``engine.IMPACT_COLUMNS``)."""
    contact, end, start, onset, in_phase, peak, peak_time, impulse = row.tolist()
    return Impact(int(contact), start, onset, bool(in_phase), peak, peak_time, impulse, end, True)


def _open_impacts(impacts: engine.Impacts, t_end: float) -> list[Impact]:
    """The impacts still open at the end of the motion (``t_end``, s): not complete."""
    found = []
    for p in np.flatnonzero(impacts.is_open).tolist():
        start, onset, in_phase, peak, peak_time, impulse = impacts.impact[:, p].tolist()
        found.append(Impact(p, start, onset, bool(in_phase), peak, peak_time, impulse, t_end))
    return found


class VisitedModes:
    """The modes one run visited (``len``) and their dynamics (indexing), from the shared slots.

    Attributes
    ----------
    system : System
    """

    def __init__(self, slots: tables.Slots, visited: set[Mode]) -> None:
        self.system = slots.system
        self._slots = slots
        self._visited = visited

    def __getitem__(self, mode: Mode) -> ModeDynamics:
        return self._slots.dynamics(mode)

    def __len__(self) -> int:
        return len(self._visited)
