"""Modes of the hybrid system and their linear dynamics and guards (MODEL.md §5).

A mode fixes which contacts are closed and, for every sliding base, whether it
sticks, slips right, slips left or is free (frictionless). Inside a mode the
state x = [q, v] obeys the linear time-invariant equation

    ẋ = A x + B a_g(t) + c

and every event of MODEL.md §5 is the upward zero crossing of a guard that is
affine in x and a_g:

    guard_j(t) = G_j · x + h_j a_g(t) + g0_j      (fires when it becomes > 0)

Matrices are built lazily, only for the modes a run visits, and cached per
system, so a contact that never closes or a base that never slips costs nothing.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

import numpy as np

from stochpound.system import System

STUCK = 0
"""Base state: stuck to its foundation (also used for fixed bases)."""
FREE = 2
"""Base state: frictionless base, a free degree of freedom."""
SLIP_RIGHT, SLIP_LEFT = 1, -1


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


class ModeLibrary:
    """Lazily built, cached :class:`ModeDynamics` of one :class:`System`."""

    def __init__(self, system: System) -> None:
        self.system = system
        self._cache: dict[Mode, ModeDynamics] = {}

    def __getitem__(self, mode: Mode) -> ModeDynamics:
        dynamics = self._cache.get(mode)
        if dynamics is None:
            dynamics = self._cache[mode] = _build(self.system, mode)
        return dynamics

    def __len__(self) -> int:
        return len(self._cache)


def _build(system: System, mode: Mode) -> ModeDynamics:
    n = system.n_dof
    closed = np.flatnonzero(mode.closed)
    g, h = system.contact_geometry, system.contact_load
    k, c_imp, d = system.contact_stiffness, system.contact_damping, system.contact_gap
    stiffness = system.stiffness + (h[closed].T * k[closed]) @ g[closed]
    damping = system.damping + (h[closed].T * c_imp[closed]) @ g[closed]
    load = h[closed].T @ (k[closed] * d[closed])
    stuck = np.array([system.base_dofs[b] for b in system.isolated if mode.base[b] == STUCK], dtype=int)
    for b in system.isolated:
        if mode.base[b] in (SLIP_RIGHT, SLIP_LEFT):
            load[system.base_dofs[b]] -= mode.base[b] * system.base_mu[b] * system.base_weight[b]
    free = np.setdiff1d(np.arange(n), stuck)
    inverse_mass = np.linalg.inv(system.mass[np.ix_(free, free)])
    A = np.zeros((2 * n, 2 * n))
    A[free, n + free] = 1.0
    A[n + free, :n] = -inverse_mass @ stiffness[free]
    A[n + free, n:] = -inverse_mass @ damping[free]
    B = np.zeros(2 * n)
    B[n + free] = -inverse_mass @ system.influence[free]
    c = np.zeros(2 * n)
    c[n + free] = inverse_mass @ load[free]
    friction = _friction(system, mode, stiffness, damping, load, A, B, c, free)
    guards = _guards(system, mode, friction)
    force_matrix = np.zeros((system.n_contacts, 2 * n))
    force_matrix[closed, :n] = g[closed] * k[closed, None]
    force_matrix[closed, n:] = g[closed] * c_imp[closed, None]
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


def _guards(system, mode, friction):
    n = system.n_dof
    rows, ground, constant, kind, target, direction = [], [], [], [], [], []

    def add(row, g0, what, index, sense=0, a_g=0.0):
        rows.append(row)
        ground.append(a_g)
        constant.append(g0)
        kind.append(what)
        target.append(index)
        direction.append(sense)

    zeros = np.zeros(n)
    for p in range(system.n_contacts):
        geometry = system.contact_geometry[p]
        k, c, d = system.contact_stiffness[p], system.contact_damping[p], system.contact_gap[p]
        penetration = np.concatenate([geometry, zeros])
        force = np.concatenate([k * geometry, c * geometry])
        if not mode.closed[p]:
            add(penetration, -d, Guard.CLOSE, p)
            if not system.contact_tensile[p]:
                add(force, -k * d, Guard.RECLOSE, p)
        elif system.contact_tensile[p]:
            add(-penetration, d, Guard.OPEN, p)
        else:
            add(-force, k * d, Guard.OPEN, p)
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
