"""What a run records while a solver advances: samples, impacts and the energy balance.

The solver hands over every accepted (possibly truncated) step together with
a dense representation of the state inside it, every event, and the state at
every output time. From those the recorder keeps

* the state, contact forces, base friction forces and base states at the
  motion's sample times;
* one row per impact: contact, start, end, peak force (located on the dense
  state, not sampled), impulse, relative velocity at onset, in-phase flag;
* the cumulative energy terms, integrated step by step with 5-point
  Gauss–Legendre quadrature of the power of every force (relative-motion
  energy balance, see docs/model.md).

:func:`settle_and_record` is the event step of the Python event paths.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from stochpound.analysis.impacts import in_phase
from stochpound.events import TIME_TOLERANCE, Dense, EventCounters, GuardStates, settle
from stochpound.modes import FREE, Guard, Mode, ModeDynamics, ModeLibrary
from stochpound.motion import GroundMotion
from stochpound.system import System

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(5)
ENERGY_TERMS = ("input", "damping", "friction", "impact")


@dataclass
class Impact:
    """One impact (a closed phase of one contact)."""

    contact: int
    start: float
    onset_velocity: float
    in_phase: bool
    peak_force: float = 0.0
    peak_time: float = float("nan")
    impulse: float = 0.0
    end: float = float("nan")
    complete: bool = False


@dataclass
class Recorder:
    """Collects the outputs of one run (see module docstring).

    Attributes
    ----------
    states, forces, friction, base_states : np.ndarray
        x, contact forces (N), base friction forces (N) and base states at every output time.
    energy_history : np.ndarray
        The energy terms (rows in :data:`ENERGY_TERMS` order, J) at every output time;
        ``energy`` maps each term's name to its row.
    running : np.ndarray
        The energy terms accumulated so far, J.
    impacts : list of Impact
        Finished impacts (and, after :meth:`finish`, every impact).
    open_impacts : dict of int to Impact
        The impacts running now, by contact.
    """

    system: System
    motion: GroundMotion
    states: np.ndarray = field(init=False)
    forces: np.ndarray = field(init=False)
    friction: np.ndarray = field(init=False)
    base_states: np.ndarray = field(init=False)
    energy: dict[str, np.ndarray] = field(init=False)
    energy_history: np.ndarray = field(init=False)
    running: np.ndarray = field(init=False)
    impacts: list[Impact] = field(default_factory=list)
    open_impacts: dict[int, Impact] = field(default_factory=dict)

    def __post_init__(self) -> None:
        n_times, n = len(self.motion.times), self.system.n_dof
        self.states = np.zeros((n_times, 2 * n))
        self.forces = np.zeros((n_times, self.system.n_contacts))
        self.friction = np.zeros((n_times, len(self.system.base_dofs)))
        self.base_states = np.zeros((n_times, len(self.system.base_dofs)), dtype=np.int8)
        self.energy_history = np.zeros((len(ENERGY_TERMS), n_times))
        self.energy = dict(zip(ENERGY_TERMS, self.energy_history))
        self.running = np.zeros(len(ENERGY_TERMS))

    # ------------------------------------------------------------ samples

    def sample(self, index: int, x: np.ndarray, dynamics: ModeDynamics) -> None:
        """Store the state, the energy terms so far and the read-outs at output time ``motion.times[index]``."""
        t = self.motion.times[index]
        ground = self.motion.acceleration(t, min(index, len(self.motion.times) - 2))
        self.states[index] = x
        self.energy_history[:, index] = self.running
        self.sample_at(np.array([index]), dynamics, np.array([ground]))

    def sample_at(self, indices: np.ndarray, dynamics: ModeDynamics, ground: np.ndarray) -> None:
        """Contact forces, friction forces and base states at samples ``indices`` from their stored states.

        Parameters
        ----------
        indices : np.ndarray of int
            Sample indices, all in the mode of ``dynamics``.
        dynamics : ModeDynamics
            The mode at those samples.
        ground : np.ndarray
            a_g at those samples, m/s².
        """
        x = self.states[indices]
        self.forces[indices] = x @ dynamics.force_matrix.T + dynamics.force_constant
        self.friction[indices] = x @ dynamics.friction_matrix.T + np.outer(ground, dynamics.friction_ground) + dynamics.friction_constant
        for b, state in enumerate(dynamics.mode.base):
            if state == FREE:
                state = np.sign(x[:, self.system.n_dof + self.system.base_dofs[b]])
            self.base_states[indices, b] = state

    # ------------------------------------------------------------ steps

    def on_step(self, dynamics: ModeDynamics, interval: int, t0: float, t1: float, dense: Dense) -> None:
        """Integrate energy and impulses over [t0, t1] and track peak impact forces."""
        if t1 <= t0:
            return
        half = 0.5 * (t1 - t0)
        times = t0 + half * (_NODES + 1.0)
        weights = half * _WEIGHTS
        x = np.atleast_2d(dense(times))
        n = self.system.n_dof
        q_dot = x[n:]
        ground = self.motion.acceleration(times, interval)
        forces = dynamics.force_matrix @ x + dynamics.force_constant[:, None]
        friction = dynamics.friction_matrix @ x + np.outer(dynamics.friction_ground, ground) + dynamics.friction_constant[:, None]
        base_velocity = self._base_velocities(q_dot)
        power = {
            "input": -ground * (self.system.influence @ q_dot),
            "damping": np.einsum("it,ij,jt->t", q_dot, self.system.damping, q_dot),
            "friction": -np.einsum("bt,bt->t", friction, base_velocity),
            "impact": np.einsum("pt,pt->t", forces, self.system.contact_load @ q_dot),
        }
        for i, values in enumerate(power[term] for term in ENERGY_TERMS):
            self.running[i] += float(weights @ values)
        for p, impact in self.open_impacts.items():
            impact.impulse += float(weights @ forces[p])
            self._track_peak(dynamics, interval, p, impact, t0, t1, dense)

    def _base_velocities(self, q_dot: np.ndarray) -> np.ndarray:
        velocities = np.zeros((len(self.system.base_dofs), q_dot.shape[1]))
        for b, dof in enumerate(self.system.base_dofs):
            if dof >= 0:
                velocities[b] = q_dot[dof]
        return velocities

    def _track_peak(self, dynamics: ModeDynamics, interval: int, p: int, impact: Impact, t0: float, t1: float, dense: Dense) -> None:
        row, constant = dynamics.force_matrix[p], dynamics.force_constant[p]

        def force(t: float) -> float:
            return float(row @ dense(t) + constant)

        def force_rate(t: float) -> float:
            return float(row @ dynamics.rate(dense(t), float(self.motion.acceleration(t, interval))))

        for t in (t0, t1):
            self._offer_peak(impact, t, force(t))
        if force_rate(t0) > 0.0 > force_rate(t1):  # a maximum inside the step
            t_peak = brentq(force_rate, t0, t1, xtol=TIME_TOLERANCE)
            self._offer_peak(impact, t_peak, force(t_peak))

    @staticmethod
    def _offer_peak(impact: Impact, t: float, value: float) -> None:
        if value > impact.peak_force:
            impact.peak_force, impact.peak_time = value, t

    # ------------------------------------------------------------ events

    def on_transitions(self, t: float, x: np.ndarray, transitions: list[tuple[int, int, int]], mode: Mode) -> None:
        """Open or close impact records for the contact transitions applied at time t."""
        n = self.system.n_dof
        for kind, target, _ in transitions:
            if kind in (Guard.CLOSE, Guard.RECLOSE) and target not in self.open_impacts and mode.closed[target]:
                velocities = self.system.contact_floor_velocity @ x
                left, right = velocities[2 * target], velocities[2 * target + 1]
                onset = float(self.system.contact_geometry[target] @ x[n:])
                self.open_impacts[target] = Impact(target, t, onset, bool(in_phase(left, right)))
            elif kind == Guard.OPEN and target in self.open_impacts and not mode.closed[target]:
                impact = self.open_impacts.pop(target)
                impact.end, impact.complete = t, True
                self.impacts.append(impact)

    def on_contact_force(self, t: float, mode: Mode, dynamics: ModeDynamics, x: np.ndarray) -> None:
        """Offer the (possibly jumping) contact forces at an event time as peaks."""
        forces = dynamics.force_matrix @ x + dynamics.force_constant
        for p, impact in self.open_impacts.items():
            self._offer_peak(impact, t, float(forces[p]))

    def finish(self, t_end: float) -> None:
        """Close the impacts still running at the end of the motion (``complete`` stays False)."""
        for impact in self.open_impacts.values():
            impact.end = t_end
            self.impacts.append(impact)
        self.open_impacts.clear()
        self.impacts.sort(key=lambda impact: (impact.start, impact.contact))

    def kinetic_and_strain(self) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic energy ½ vᵀMv and storey/restoring strain energy ½ qᵀKq at the samples, J."""
        n = self.system.n_dof
        q, v = self.states[:, :n], self.states[:, n:]
        kinetic = 0.5 * np.einsum("ti,ti->t", v @ self.system.mass, v)
        strain = 0.5 * np.einsum("ti,ti->t", q @ self.system.stiffness, q)
        return kinetic, strain


def settle_and_record(
    library: ModeLibrary,
    motion: GroundMotion,
    recorder: Recorder,
    counters: EventCounters,
    interval: int,
    t: float,
    x: np.ndarray,
    mode: Mode,
    guard: int | None = None,
) -> tuple[Mode, np.ndarray, GuardStates]:
    """Settle the mode at an event (or at the start) and record its transitions and contact forces.

    The one event step of the Python event paths (``ivp``, and ``exact`` with
    ``events="python"``): :func:`stochpound.events.settle`, then
    :meth:`Recorder.on_transitions` and :meth:`Recorder.on_contact_force`.

    Parameters
    ----------
    library, motion : ModeLibrary, GroundMotion
    recorder : Recorder
    counters : EventCounters
        ``total`` counts the event when ``guard`` is given.
    interval : int
        Motion interval whose right-hand derivatives apply at t.
    t : float
        Event time, s.
    x : np.ndarray
        State at t.
    mode : Mode
        Mode before the event.
    guard : int or None
        Index (in ``mode``) of the guard that fired, or None at the start of the run.

    Returns
    -------
    mode, x, guard_states
        The settled mode, the state and the arming of its guards (see :func:`~stochpound.events.settle`).
    """
    fired = None
    if guard is not None:
        dynamics = library[mode]
        fired = (int(dynamics.guard_kind[guard]), int(dynamics.guard_target[guard]), int(dynamics.guard_direction[guard]))
        counters.total += 1
    mode, x, states, transitions = settle(library, motion, interval, t, x, mode, counters, fired)
    recorder.on_transitions(t, x, transitions, mode)
    recorder.on_contact_force(t, mode, library[mode], x)
    return mode, x, states
