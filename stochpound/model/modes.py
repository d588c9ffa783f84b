"""Modes of the hybrid system and their linear dynamics and guards (docs/model.md, "Modes and events").

A mode fixes which contacts are closed and, for every sliding base, whether it
sticks, slips right, slips left or is free (frictionless). Inside a mode the
state x = [q, v] obeys the linear time-invariant equation

    ẋ = A x + B a_g(t) + c

and every event is the upward zero crossing of a guard that is affine in x
and a_g:

    guard_j(t) = G_j · x + h_j a_g(t) + g0_j      (fires when it becomes > 0)

A mode is assembled from the system's linear part and the contributions of
the laws (:mod:`stochpound.model.contact`, :mod:`stochpound.model.friction`):
their terms of the mode's matrices, their guards and their force read-outs.
Matrices are built lazily, only for the modes a run visits, and cached per
system within a memory budget (:class:`ModeLibrary`), so a contact that never
closes or a base that never slips costs nothing.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Generic, TypeVar

import numpy as np

from stochpound.model import contact, friction, yielding
from stochpound.model.demands import DEMANDS, demand_rows
from stochpound.model.friction import STUCK
from stochpound.model.system import System

MODE_BUDGET = 256 * 2**20
"""Largest size of the cached :class:`ModeDynamics` of one system, bytes (large scenes visit thousands of modes)."""

Key = TypeVar("Key")
Value = TypeVar("Value")


@dataclass(frozen=True)
class Mode:
    """Discrete state: ``closed[p]`` per contact, ``base[i]`` (STUCK, ±1 or FREE) per sliding base (``System.bases``), ``storey[j]`` (ELASTIC or ±1) per yielding storey (``System.storeys``)."""

    closed: tuple[bool, ...]
    base: tuple[int, ...]
    storey: tuple[int, ...] = ()

    def with_contact(self, p: int, closed: bool) -> "Mode":
        """The same mode with contact p opened or closed."""
        flags = list(self.closed)
        flags[p] = closed
        return Mode(tuple(flags), self.base, self.storey)

    def with_base(self, b: int, state: int) -> "Mode":
        """The same mode with sliding base b in ``state``."""
        states = list(self.base)
        states[b] = state
        return Mode(self.closed, tuple(states), self.storey)


@dataclass(frozen=True)
class ModeDynamics:
    """Linear dynamics, guards and force read-outs of one mode.

    Attributes
    ----------
    mode : Mode
    A, B, c : np.ndarray
        ẋ = A x + B a_g + c.
    guard_matrix, guard_ground, guard_constant : np.ndarray
        G (n_guards × 2N), h, g0 of every guard of this mode.
    guard_kind, guard_target, guard_direction : np.ndarray of int
        Guard kind (:class:`~stochpound.model.guards.Guard`), its contact or
        sliding base, and the slip direction of a SLIP guard (0 otherwise).
    force_matrix, force_constant : np.ndarray
        Contact forces F = force_matrix · x + force_constant, N (rows of open contacts are 0).
    friction_matrix, friction_ground, friction_constant : np.ndarray
        Force of the foundation on each sliding base, N, positive to the right
        (−F_req when stuck, −σ μ W when slipping, 0 for a free base).
    monitor_matrix, monitor_ground, monitor_constant : np.ndarray
        The monitors (:func:`monitor_rows`): read-outs whose largest value over
        a run is located on the solution.
    stuck_dofs : np.ndarray of int
        DOFs held fixed in this mode (stuck bases, the plastic DOFs of elastic
        storeys); s and ṡ are re-imposed on them.
    """

    mode: Mode
    A: np.ndarray
    B: np.ndarray
    c: np.ndarray
    guard_matrix: np.ndarray
    guard_ground: np.ndarray
    guard_constant: np.ndarray
    guard_kind: np.ndarray
    guard_target: np.ndarray
    guard_direction: np.ndarray
    force_matrix: np.ndarray
    force_constant: np.ndarray
    friction_matrix: np.ndarray
    friction_ground: np.ndarray
    friction_constant: np.ndarray
    monitor_matrix: np.ndarray
    monitor_ground: np.ndarray
    monitor_constant: np.ndarray
    stuck_dofs: np.ndarray

    def rate(self, x: np.ndarray, ground: float) -> np.ndarray:
        """ẋ at state x and ground acceleration ``ground`` (m/s²)."""
        return self.A @ x + self.B * ground + self.c

    def guards(self, x: np.ndarray, ground: float) -> np.ndarray:
        """Guard values at state x and ground acceleration."""
        return self.guard_matrix @ x + self.guard_ground * ground + self.guard_constant


class BoundedCache(Generic[Key, Value]):
    """Least recently used cache holding at most ``budget`` bytes of values (and at least one value).

    Parameters
    ----------
    budget : int
        Largest total size of the cached values, bytes.
    size : callable
        Size of a value, bytes.
    """

    def __init__(self, budget: int, size: Callable[[Value], int]) -> None:
        self._budget = budget
        self._size = size
        self._items: OrderedDict[Key, tuple[Value, int]] = OrderedDict()
        self._bytes = 0

    def get(self, key: Key) -> Value | None:
        """The cached value of ``key`` (now the most recently used), or None."""
        item = self._items.get(key)
        if item is None:
            return None
        self._items.move_to_end(key)
        return item[0]

    def put(self, key: Key, value: Value) -> None:
        """Cache ``value``, dropping the least recently used values beyond the budget."""
        size = self._size(value)
        self._items[key] = (value, size)
        self._bytes += size
        while self._bytes > self._budget and len(self._items) > 1:
            _, (_, dropped) = self._items.popitem(last=False)
            self._bytes -= dropped


def array_bytes(value: object) -> int:
    """Total size of the numpy arrays among the fields of a dataclass instance, bytes."""
    return sum(getattr(value, f.name).nbytes for f in fields(value) if isinstance(getattr(value, f.name), np.ndarray))


class ModeLibrary:
    """Lazily built :class:`ModeDynamics` of one :class:`~stochpound.model.system.System`, cached within :data:`MODE_BUDGET`.

    Dynamics dropped from the cache are rebuilt when asked for again;
    ``len`` counts the distinct modes built.
    """

    def __init__(self, system: System) -> None:
        self.system = system
        self._cache: BoundedCache[Mode, ModeDynamics] = BoundedCache(MODE_BUDGET, array_bytes)
        self._built: set[Mode] = set()
        self._inverse_mass: dict[tuple[int, ...], np.ndarray] = {}
        self._contact_rows = contact.contact_rows(system.element_geometry, system.element_stiffness, system.element_damping)

    def __getitem__(self, mode: Mode) -> ModeDynamics:
        dynamics = self._cache.get(mode)
        if dynamics is None:
            dynamics = _build(self.system, mode, self._free_inverse_mass(mode), self._contact_rows)
            self._cache.put(mode, dynamics)
            self._built.add(mode)
        return dynamics

    def __len__(self) -> int:
        return len(self._built)

    def _free_inverse_mass(self, mode: Mode) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Held DOFs, free DOFs (with mass) and the inverse of the free DOFs' mass matrix of ``mode``.

        Held: the stuck bases and the plastic DOFs of elastic storeys; the
        plastic DOFs have no mass and are never free (their rates are the
        law's, :func:`stochpound.model.yielding.flow_rates`).
        """
        system = self.system
        stuck = np.array([base.dof for base, state in zip(system.bases, mode.base) if state == STUCK], dtype=int)
        plastic = [dof for storey in system.storeys for dof in (storey.plastic_dof, storey.accumulated_dof)]
        free = np.setdiff1d(np.arange(system.n_dof), np.concatenate([stuck, plastic]).astype(int))
        key = tuple(stuck)
        inverse = self._inverse_mass.get(key)
        if inverse is None:
            inverse = self._inverse_mass[key] = np.linalg.inv(system.mass[np.ix_(free, free)])
        if system.storeys:
            held = [dof for storey, state in zip(system.storeys, mode.storey) if state == yielding.ELASTIC
                    for dof in (storey.plastic_dof, storey.accumulated_dof)]
            stuck = np.sort(np.concatenate([stuck, held]).astype(int))
        return stuck, free, inverse


def _build(system: System, mode: Mode, masses: tuple[np.ndarray, np.ndarray, np.ndarray], rows: contact.ContactRows) -> ModeDynamics:
    """The dynamics of ``mode`` from its stuck and free DOFs and free mass inverse (``masses``).

    Every map acts on ξ = [x, f] (the read-outs f of the nonlinear laws enter
    as inputs: their columns of A are E, :func:`_readout_loads`).
    """
    n, size = system.n_dof, system.xi_size
    stuck, free, inverse_mass = masses
    closed = np.array(mode.closed, bool)
    k, c_imp, d = system.element_stiffness, system.element_damping, system.element_gap
    linear = closed & ~system.nonlinear  # the closed Kelvin–Voigt elements, folded into K, C and the load
    extra_stiffness, extra_damping, load = contact.closed_terms(system.element_geometry, system.element_load, k, c_imp, d, linear)
    stiffness, damping = system.stiffness + extra_stiffness, system.damping + extra_damping
    for base, state in zip(system.bases, mode.base):
        load[base.dof] += friction.slip_force(base, state)
    for storey, state in zip(system.storeys, mode.storey):
        if yielding.flowing(state):
            spring, flow_load = yielding.flow_terms(storey, state, n)
            stiffness, load = stiffness + spring, load + flow_load
    inputs = _readout_loads(system, mode)
    A = np.zeros((2 * n, size))
    A[free, n + free] = 1.0
    A[n + free, :n] = -inverse_mass @ stiffness[free]
    A[n + free, n : 2 * n] = -inverse_mass @ damping[free]
    A[n + free, 2 * n :] = inverse_mass @ inputs[free]
    B = np.zeros(2 * n)
    B[n + free] = -inverse_mass @ system.influence[free]
    c = np.zeros(2 * n)
    c[n + free] = inverse_mass @ load[free]
    for storey, state in zip(system.storeys, mode.storey):
        if yielding.flowing(state):
            yielding.flow_rates(storey, state, A, n)
    foundation = [_foundation_force(system, i, state, (stiffness, damping, load, inputs), (A, B, c), free) for i, state in enumerate(mode.base)]
    matrix, *rest = contact.guards(rows, k, d, system.element_tensile, closed)
    contact_guards = (_over_xi(matrix, size), *rest)
    base_guards = [guard for i, (base, state) in enumerate(zip(system.bases, mode.base))
                   for guard in friction.guards(base, i, state, foundation[i], n)]
    base_guards += [guard for j, (storey, state) in enumerate(zip(system.storeys, mode.storey))
                    for guard in yielding.guards(storey, len(system.bases) + j, state, size, n)]
    force_matrix, force_constant = contact.force_rows(rows, k, d, linear)
    force_matrix = _over_xi(force_matrix, size)
    readout = 2 * n + np.arange(len(system.readout_elements))
    force_matrix[system.readout_elements, readout] = closed[system.readout_elements]  # a nonlinear element's force is its read-out
    return ModeDynamics(mode, A, B, c, *_stack_guards(contact_guards, base_guards, size), force_matrix, force_constant,
                        *_stack_foundation(foundation, size), *monitor_rows(system, rows, (A, B, c), mode.storey), stuck)


def _over_xi(matrix: np.ndarray, size: int) -> np.ndarray:
    """Rows over x (… × 2N) as rows over ξ = [x, f] (… × ``size``), zero on the read-outs."""
    out = np.zeros(matrix.shape[:-1] + (size,))
    out[..., : matrix.shape[-1]] = matrix
    return out


def _readout_loads(system: System, mode: Mode) -> np.ndarray:
    """The generalised load of each read-out per unit (N × n_f): −h_p for a closed nonlinear element p, the base DOF for a slipping velocity-dependent base."""
    inputs = np.zeros((system.n_dof, system.n_readouts))
    for j, p in enumerate(system.readout_elements):
        if mode.closed[p]:
            inputs[:, j] = -system.element_load[p]
    for j, b in enumerate(system.readout_bases, start=len(system.readout_elements)):
        if friction.slipping(mode.base[b]):
            inputs[system.bases[b].dof, j] = 1.0
    return inputs


def _foundation_force(system: System, b: int, state: int, terms: tuple[np.ndarray, ...], rate: tuple[np.ndarray, ...],
                      free: np.ndarray) -> tuple[np.ndarray, float, float]:
    """The foundation's force on sliding base b in ``state`` as a map over ξ: (row, a_g coefficient, constant).

    Stuck: −F_req (:func:`stochpound.model.friction.stuck_foundation_force`);
    slipping: −σ μ W, or its read-out with velocity-dependent friction; free: 0.
    ``terms``: the mode's K, C, constant load and read-out loads.
    """
    base, size = system.bases[b], system.xi_size
    if state == STUCK:
        stiffness, damping, load, inputs = terms
        return friction.stuck_foundation_force(base.dof, system.mass, stiffness, damping, load, inputs, system.influence, rate, free)
    row = np.zeros(size)
    if b in system.readout_bases and friction.slipping(state):
        row[2 * system.n_dof + len(system.readout_elements) + list(system.readout_bases).index(b)] = 1.0
    return row, 0.0, friction.slip_force(base, state)


def monitor_count(system: System) -> int:
    """Number of monitors of every mode of ``system`` (:func:`monitor_rows`)."""
    return storey_monitors_start(system) + 2 * len(system.storeys)


def monitored_contacts(system: System) -> np.ndarray:
    """The contacts whose floors' displacements are monitored (:func:`monitor_rows`): those with an infinite gap, in contact order.

    Their peaks are the separation rules' u1 and u2, which are evaluated on
    contact-free runs; a contact with a finite gap is not monitored (its
    closure is), which spares every run with contacts their cost (the
    engine's product columns and located maxima).
    """
    return np.array([c for c, gap in enumerate(system.element_gap[: system.n_contacts].tolist()) if gap == math.inf], dtype=np.int64)  # (numpy's calls cost more on every run)


def contact_displacement_monitors(system: System) -> slice:
    """The monitor rows of ± each monitored contact's left and right floor displacement (:func:`monitor_rows`, :func:`monitored_contacts`): 4 per contact, in the order +left, −left, +right, −right."""
    return slice(system.n_elements, demand_monitors_start(system))


def demand_monitors_start(system: System) -> int:
    """Index of the first demand monitor (:func:`monitor_rows`): they follow the closures and the monitored contacts' floor displacements."""
    return system.n_elements + 4 * len(monitored_contacts(system))


def storey_monitors_start(system: System) -> int:
    """Index of the first yielding storey's drift monitor (:func:`monitor_rows`): they follow the demands."""
    return demand_monitors_start(system) + (2 * len(DEMANDS) * len(system.total_displacement) if system.demands else 0)


def monitor_rows(system: System, rows: contact.ContactRows, rate: tuple[np.ndarray, np.ndarray, np.ndarray],
                 storey_states: tuple[int, ...] = ()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The monitors of a mode as an affine map (matrix over x, a_g coefficients, constants).

    First each impact element's closure y_left − y_right = g_p · q (m, the
    penetration plus the gap): its largest value over a run, located on the
    solution, is the separation the run needed (``peak_contact_closure``).
    Then, per contact with an infinite gap (:func:`monitored_contacts`), +
    and − the displacement relative to the ground y = s + u of its left
    floor, then of its right floor
    (:func:`contact_displacement_monitors`): their peaks are the separation
    rules' u1 and u2 located the same way as the closure, so that
    u1 + u2 ≥ D holds on the solution. Then, when the system monitors
    demands, + and − every demand parameter of
    :func:`stochpound.model.demands.demand_rows` (whose peaks give the peak
    absolute values). Last, + and − the drift of every yielding storey
    (:func:`storey_monitors_start`): their peaks give its peak ductility.
    ``rate`` is the mode's (A, B, c), ``storey_states`` its yielding storeys' states.
    """
    monitored = monitored_contacts(system)
    left, right = system.element_left[monitored], system.element_right[monitored]
    sides = np.stack([left, -left, right, -right], axis=1).reshape(4 * len(monitored), system.n_dof)
    displacements = np.vstack([rows.penetration, np.hstack([sides, np.zeros((4 * len(monitored), system.n_dof))])])
    if system.storeys:
        drifts = np.array([storey.drift_row(system.n_dof) for storey in system.storeys])
        storey_rows = np.hstack([np.vstack([drifts, -drifts]), np.zeros((2 * len(drifts), system.n_dof))])
    n_rows = len(displacements)
    matrix, ground, constant = _over_xi(displacements, system.xi_size), np.zeros(n_rows), np.zeros(n_rows)
    if system.demands:
        demand = demand_rows(system.floor_dofs, system.building_base_dofs, system.storey_stiffness, system.storey_damping, rate)
        _yielding_shears(system, storey_states, demand)
        matrix, ground, constant = (np.vstack([matrix, demand[0], -demand[0]]), np.concatenate([ground, demand[1], -demand[1]]),
                                    np.concatenate([constant, demand[2], -demand[2]]))
    if not system.storeys:
        return matrix, ground, constant
    zeros = np.zeros(len(storey_rows))
    return np.vstack([matrix, _over_xi(storey_rows, system.xi_size)]), np.concatenate([ground, zeros]), np.concatenate([constant, zeros])


def _yielding_shears(system: System, storey_states: tuple[int, ...], demand: tuple[np.ndarray, np.ndarray, np.ndarray]) -> None:
    """Correct the storey shear rows of :func:`~stochpound.model.demands.demand_rows` (k d + c ḋ) for the yielding storeys, in place.

    Elastic: k d − (1 − α) k z; flowing: α k d + σ (1 − α) F_y (plus c ḋ either way).
    """
    matrix, _, constant = demand
    floors = len(system.total_displacement)
    first = np.cumsum([0] + [len(dofs) for dofs in system.floor_dofs])
    for storey, state in zip(system.storeys, storey_states):
        row = 2 * floors + first[storey.building] + storey.storey
        if yielding.flowing(state):
            matrix[row, : system.n_dof] -= storey.plastic_stiffness * storey.drift_row(system.n_dof)
            constant[row] += state * storey.plastic_strength
        else:
            matrix[row, storey.plastic_dof] -= storey.plastic_stiffness


def _stack_guards(contact_guards: tuple[np.ndarray, ...], base_guards: list[tuple], size: int) -> tuple[np.ndarray, ...]:
    """The guard arrays of a mode: the contacts' (in contact order), then the bases' rows (row, a_g, constant, kind, target, direction)."""
    columns = list(zip(*base_guards)) if base_guards else [[] for _ in range(6)]
    base_arrays = (np.array(columns[0], float).reshape(len(base_guards), size), *(np.array(column, dtype) for column, dtype in
                                                                                  zip(columns[1:], (float, float, int, int, int))))
    return tuple(np.concatenate([a, b]) for a, b in zip(contact_guards, base_arrays, strict=True))


def _stack_foundation(foundation: list[tuple[np.ndarray, float, float]], size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The foundation-force maps of the sliding bases as (matrix, a_g coefficients, constants)."""
    if not foundation:
        return np.zeros((0, size)), np.zeros(0), np.zeros(0)
    rows, ground, constant = zip(*foundation)
    return np.array(rows), np.array(ground, float), np.array(constant, float)


def initial_mode(system: System) -> Mode:
    """Mode before settling at t = 0: contacts open, bases stuck, free or sliding as x(0) says."""
    states = tuple(friction.initial_state(base, system.initial_state[system.n_dof + base.dof]) for base in system.bases)
    return Mode(tuple(False for _ in range(system.n_elements)), states, tuple(yielding.ELASTIC for _ in system.storeys))
