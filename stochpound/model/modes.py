"""Modes of the hybrid system and their linear dynamics and guards (MODEL.md §5).

A mode fixes which contacts are closed and, for every sliding base, whether it
sticks, slips right, slips left or is free (frictionless). Inside a mode the
state x = [q, v] obeys the linear time-invariant equation

    ẋ = A x + B a_g(t) + c

and every event of MODEL.md §5 is the upward zero crossing of a guard that is
affine in x and a_g:

    guard_j(t) = G_j · x + h_j a_g(t) + g0_j      (fires when it becomes > 0)

Matrices are built lazily, only for the modes a run visits, and cached per
system within a memory budget (:class:`ModeLibrary`), so a contact that never
closes or a base that never slips costs nothing.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, fields
from enum import IntEnum
from typing import Generic, TypeVar

import numpy as np

from stochpound.model.system import System

STUCK = 0
"""Base state: stuck to its foundation (also used for fixed bases)."""
FREE = 2
"""Base state: frictionless base, a free degree of freedom."""
SLIP_RIGHT, SLIP_LEFT = 1, -1
MODE_BUDGET = 256 * 2**20
"""Largest size of the cached :class:`ModeDynamics` of one system, bytes (large scenes visit thousands of modes)."""

Key = TypeVar("Key")
Value = TypeVar("Value")


class Guard(IntEnum):
    """What a guard's zero crossing means."""

    CLOSE = 0  # open contact: δ crosses 0 upwards
    RECLOSE = 1  # open non-tensile contact still penetrated: trial force crosses 0 upwards
    OPEN = 2  # closed contact: δ (tensile) or F (non-tensile) crosses 0 downwards
    SLIP = 3  # stuck base: ±F_req crosses μ_s W
    STOP = 4  # slipping base: sliding velocity crosses 0


@dataclass(frozen=True)
class Mode:
    """Discrete state: ``closed[p]`` per contact, ``base[b]`` (STUCK, ±1 or FREE) per building."""

    closed: tuple[bool, ...]
    base: tuple[int, ...]

    def with_contact(self, p: int, closed: bool) -> "Mode":
        """The same mode with contact p opened or closed."""
        flags = list(self.closed)
        flags[p] = closed
        return Mode(tuple(flags), self.base)

    def with_base(self, b: int, state: int) -> "Mode":
        """The same mode with the base of building b in ``state``."""
        states = list(self.base)
        states[b] = state
        return Mode(self.closed, tuple(states))


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
        Guard kind (:class:`Guard`), its contact or building index, and the
        slip direction of a SLIP guard (0 otherwise).
    force_matrix, force_constant : np.ndarray
        Contact forces F = force_matrix · x + force_constant, N (rows of open contacts are 0).
    friction_matrix, friction_ground, friction_constant : np.ndarray
        Force of the foundation on each base, N, positive to the right
        (−F_req when stuck, −σ μ W when slipping, 0 for fixed or free bases).
    stuck_dofs : np.ndarray of int
        DOFs held fixed in this mode (stuck bases); s and ṡ are re-imposed on them.
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
    """Lazily built :class:`ModeDynamics` of one :class:`System`, cached within :data:`MODE_BUDGET`.

    Dynamics dropped from the cache are rebuilt when asked for again;
    ``len`` counts the distinct modes built.
    """

    def __init__(self, system: System) -> None:
        self.system = system
        self._cache: BoundedCache[Mode, ModeDynamics] = BoundedCache(MODE_BUDGET, array_bytes)
        self._built: set[Mode] = set()
        self._inverse_mass: dict[tuple[int, ...], np.ndarray] = {}
        self._contact_rows = _contact_guard_rows(system)

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
        """Stuck DOFs, free DOFs and the inverse of the free DOFs' mass matrix of ``mode``."""
        system = self.system
        stuck = np.array([system.base_dofs[b] for b in system.isolated if mode.base[b] == STUCK], dtype=int)
        free = np.setdiff1d(np.arange(system.n_dof), stuck)
        key = tuple(stuck)
        inverse = self._inverse_mass.get(key)
        if inverse is None:
            inverse = self._inverse_mass[key] = np.linalg.inv(system.mass[np.ix_(free, free)])
        return stuck, free, inverse


@dataclass(frozen=True)
class _ContactRows:
    """Every contact's penetration row [g, 0] and force row [k g, c g] over the state (n_contacts × 2N)."""

    penetration: np.ndarray
    force: np.ndarray


def _contact_guard_rows(system: System) -> _ContactRows:
    """The guard rows of every contact, shared by all modes."""
    g = system.contact_geometry
    zeros = np.zeros_like(g)
    k, c = system.contact_stiffness[:, None], system.contact_damping[:, None]
    return _ContactRows(np.hstack([g, zeros]), np.hstack([k * g, c * g]))


def _build(system: System, mode: Mode, masses: tuple[np.ndarray, np.ndarray, np.ndarray], rows: _ContactRows) -> ModeDynamics:
    """The dynamics of ``mode`` from its stuck and free DOFs and free mass inverse (``masses``)."""
    n = system.n_dof
    stuck, free, inverse_mass = masses
    closed = np.flatnonzero(mode.closed)
    g, h = system.contact_geometry, system.contact_load
    k, c_imp, d = system.contact_stiffness, system.contact_damping, system.contact_gap
    stiffness = system.stiffness + (h[closed].T * k[closed]) @ g[closed]
    damping = system.damping + (h[closed].T * c_imp[closed]) @ g[closed]
    load = h[closed].T @ (k[closed] * d[closed])
    for b in system.isolated:
        if mode.base[b] in (SLIP_RIGHT, SLIP_LEFT):
            load[system.base_dofs[b]] -= mode.base[b] * system.base_mu[b] * system.base_weight[b]
    A = np.zeros((2 * n, 2 * n))
    A[free, n + free] = 1.0
    A[n + free, :n] = -inverse_mass @ stiffness[free]
    A[n + free, n:] = -inverse_mass @ damping[free]
    B = np.zeros(2 * n)
    B[n + free] = -inverse_mass @ system.influence[free]
    c = np.zeros(2 * n)
    c[n + free] = inverse_mass @ load[free]
    friction = _friction(system, mode, stiffness, damping, load, A, B, c, free)
    guards = _guards(system, mode, friction, rows)
    force_matrix = np.zeros((system.n_contacts, 2 * n))
    force_matrix[closed] = rows.force[closed]
    force_constant = np.zeros(system.n_contacts)
    force_constant[closed] = -k[closed] * d[closed]
    return ModeDynamics(mode, A, B, c, *guards, force_matrix, force_constant, *friction, stuck)


def _friction(system, mode, stiffness, damping, load, A, B, c, free):
    """Rows giving the foundation's force on each base (−F_req when stuck, −σμW slipping)."""
    n = system.n_dof
    n_buildings = len(system.base_dofs)
    matrix, ground, constant = np.zeros((n_buildings, 2 * n)), np.zeros(n_buildings), np.zeros(n_buildings)
    for b in system.isolated:
        s = system.base_dofs[b]
        if mode.base[b] == STUCK:
            coupling = system.mass[s, free]
            required_matrix = -np.concatenate([stiffness[s], damping[s]]) - coupling @ A[n + free]
            matrix[b] = -required_matrix
            ground[b] = system.influence[s] + coupling @ B[n + free]
            constant[b] = -(load[s] - coupling @ c[n + free])
        elif mode.base[b] in (SLIP_RIGHT, SLIP_LEFT):
            constant[b] = -mode.base[b] * system.base_mu[b] * system.base_weight[b]
    return matrix, ground, constant


def _guards(system: System, mode: Mode, friction: tuple, rows: _ContactRows) -> tuple[np.ndarray, ...]:
    """Guard rows of ``mode``: every contact's guards in contact order, then every base's."""
    contact = _contact_guards(system, np.array(mode.closed, bool), rows)
    base = _base_guards(system, mode, friction)
    return tuple(np.concatenate([a, b]) for a, b in zip(contact, base, strict=True))


def _contact_guards(system: System, closed: np.ndarray, rows: _ContactRows) -> tuple[np.ndarray, ...]:
    """CLOSE (and RECLOSE for non-tensile contacts) of open contacts, OPEN of closed ones, in contact order."""
    k, d, tensile = system.contact_stiffness, system.contact_gap, system.contact_tensile
    # first guard of each contact: CLOSE when open; OPEN (on δ when tensile, on F when not) when closed
    first = np.where(closed[:, None], -np.where(tensile[:, None], rows.penetration, rows.force), rows.penetration)
    first_constant = np.where(closed, np.where(tensile, d, k * d), -d)
    first_kind = np.where(closed, Guard.OPEN, Guard.CLOSE)
    reclose = np.flatnonzero(~closed & ~tensile)
    order = np.argsort(np.concatenate([2 * np.arange(system.n_contacts), 2 * reclose + 1]), kind="stable")
    matrix = np.concatenate([first, rows.force[reclose]])[order]
    constant = np.concatenate([first_constant, -k[reclose] * d[reclose]])[order]
    kind = np.concatenate([first_kind, np.full(len(reclose), Guard.RECLOSE)])[order]
    target = np.concatenate([np.arange(system.n_contacts), reclose])[order]
    return matrix, np.zeros(len(order)), constant, kind.astype(int), target, np.zeros(len(order), int)


def _base_guards(system: System, mode: Mode, friction: tuple) -> tuple[np.ndarray, ...]:
    """SLIP guards (both ways) of stuck bases and STOP guards of slipping ones."""
    n = system.n_dof
    rows, ground, constant, kind, target, direction = [], [], [], [], [], []

    def add(row, g0, what, index, sense=0, a_g=0.0):
        rows.append(row)
        ground.append(a_g)
        constant.append(g0)
        kind.append(what)
        target.append(index)
        direction.append(sense)

    friction_matrix, friction_ground, friction_constant = friction
    for b in system.isolated:
        state = mode.base[b]
        if state == STUCK:
            limit = system.base_mu_static[b] * system.base_weight[b]
            for sense in (SLIP_RIGHT, SLIP_LEFT):
                # F_req = −(foundation force); slip right when F_req > μ_s W
                add(-sense * friction_matrix[b], -sense * friction_constant[b] - limit, Guard.SLIP, b, sense, -sense * friction_ground[b])
        elif state in (SLIP_RIGHT, SLIP_LEFT):
            row = np.zeros(2 * n)
            row[n + system.base_dofs[b]] = -state
            add(row, 0.0, Guard.STOP, b)
    n_guards = len(rows)
    return (
        np.array(rows).reshape(n_guards, 2 * n),
        np.array(ground, float),
        np.array(constant, float),
        np.array(kind, int),
        np.array(target, int),
        np.array(direction, int),
    )


def initial_mode(system: System) -> Mode:
    """Mode before settling at t = 0: contacts open, bases stuck, free or sliding as x(0) says."""
    states = []
    for b, dof in enumerate(system.base_dofs):
        if dof < 0:
            states.append(STUCK)
        elif system.frictionless[b]:
            states.append(FREE)
        else:
            states.append(int(np.sign(system.initial_state[system.n_dof + dof])))
    return Mode(tuple(False for _ in range(system.n_contacts)), tuple(states))
