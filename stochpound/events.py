"""Event logic shared by every solver: finding guard crossings and settling the mode.

Two questions are answered here, for any solver that advances the state
step by step and can evaluate it anywhere inside a step (``dense``):

* :func:`first_crossing`: does any guard of the current mode cross zero inside
  a step, and when first? End-point sign checks miss contacts shorter than a
  step, so every guard is also checked for interior extrema with the cubic
  Hermite interpolant of its values and rates at the step ends, and
  candidates are confirmed and located on the solver's own dense output.
* :func:`settle`: at an event time, which mode is consistent with the state?
  A guard that sits at zero (within round-off) is judged by the sign of its
  first non-vanishing time derivative up to the third (the slip-onset trap of
  MODEL.md §6), transitions are applied until no guard wants to fire, and a
  cycle (a chattering instant) is broken by keeping the last mode and
  disarming the guards that still want to fire.

A disarmed guard (one that started at zero, or was left unresolved by a
cycle) fires only after it has gone below zero and come back, or once it
exceeds a small positive threshold: this guarantees progress (no
zero-length event loops) while keeping the exact crossing time of ordinary
events.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from stochpound.modes import FREE, STUCK, Guard, Mode, ModeDynamics, ModeLibrary
from stochpound.motion import GroundMotion
from stochpound.system import System

ROUND_OFF = 1e-10
"""Relative size under which a guard value or derivative counts as zero."""
FIRE_THRESHOLD = 1e-7
"""Relative level at which a disarmed guard fires anyway (progress guarantee)."""
TIME_TOLERANCE = 1e-13
"""Absolute tolerance of event times, s."""
MAX_SETTLE_ITERATIONS = 64

Dense = Callable[[np.ndarray | float], np.ndarray]


@dataclass
class EventCounters:
    """Counts of what the event logic did, stored in the result's attributes.

    Attributes
    ----------
    total : int
        Guard crossings located and settled.
    chatter_cycles : int
        Instants at which settling found a cycle of modes (chattering) and
        kept the last mode, disarming the guards that still wanted to fire.
    grazing_checks : int
        Near-grazing guard maxima that were checked on the dense state.
    """

    total: int = 0
    chatter_cycles: int = 0
    grazing_checks: int = 0

    def as_attrs(self) -> dict[str, int]:
        """The counters as netCDF attributes (``events_*``)."""
        return {f"events_{name}": value for name, value in self.__dict__.items()}


@dataclass
class GuardStates:
    """Per-guard arming state for the current mode span.

    ``threshold[j]`` is 0 for an armed guard, a small positive value for a
    disarmed one, and +inf for a guard that may not fire at all for now.
    A disarmed guard is armed again once its value goes below −tolerance,
    unless it is not ``rearmable`` (a RECLOSE guard of a contact that is not
    penetrated stays off until the next mode change).
    """

    threshold: np.ndarray
    tolerance: np.ndarray
    rearmable: np.ndarray
    disarmed: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.disarmed = self.threshold != 0.0

    def arm_where_negative(self, values: np.ndarray) -> None:
        """Arm the disarmed guards whose value has gone clearly below zero."""
        rearm = self.disarmed & self.rearmable & (values < -self.tolerance)
        self.threshold[rearm] = 0.0
        self.disarmed[rearm] = False


@dataclass
class Step:
    """One accepted solver step inside a mode span and a motion interval."""

    t0: float
    t1: float
    x0: np.ndarray
    x1: np.ndarray
    dense: Dense


# ---------------------------------------------------------------- derivatives


def state_derivatives(dynamics: ModeDynamics, x: np.ndarray, ground: np.ndarray) -> list[np.ndarray]:
    """[x, ẋ, ẍ, x⃛] in a mode, with ``ground`` = [a_g, ȧ_g, ä_g, a⃛_g]."""
    A, B = dynamics.A, dynamics.B
    rate = A @ x + B * ground[0] + dynamics.c
    acceleration = A @ rate + B * ground[1]
    jerk = A @ acceleration + B * ground[2]
    return [x, rate, acceleration, jerk]


def _guard_scales(dynamics: ModeDynamics, x: np.ndarray, ground: np.ndarray) -> np.ndarray:
    """Round-off scale of each guard and of its first three derivatives (4 × n_guards)."""
    A, B = np.abs(dynamics.A), np.abs(dynamics.B)
    magnitude = np.abs(x)
    scales = []
    G, h = np.abs(dynamics.guard_matrix), np.abs(dynamics.guard_ground)
    floor = 1e-4 * (G.sum(axis=1) + h)
    for order in range(4):
        extra = np.abs(dynamics.guard_constant) if order == 0 else 0.0
        scales.append(G @ magnitude + h * abs(ground[order]) + extra + floor)
        magnitude = A @ magnitude + B * abs(ground[order]) + (np.abs(dynamics.c) if order == 0 else 0.0)
    return np.array(scales)


def guard_leaving_sign(dynamics: ModeDynamics, x: np.ndarray, ground: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Guard values, tolerances, and the side each guard heads to from where it is.

    Returns
    -------
    values : np.ndarray
        Guard values at x.
    tolerance : np.ndarray
        Round-off tolerance of each value.
    heading : np.ndarray of int
        +1 where the guard is above tolerance or sits at zero and leaves it
        upwards (first non-vanishing derivative > 0), −1 where it is below or
        leaves downwards, 0 where it and three derivatives vanish.
    """
    derivatives = state_derivatives(dynamics, x, ground)
    scales = _guard_scales(dynamics, x, ground)
    G, h = dynamics.guard_matrix, dynamics.guard_ground
    series = [G @ derivatives[order] + h * ground[order] for order in range(4)]
    series[0] = series[0] + dynamics.guard_constant
    tolerances = ROUND_OFF * scales
    heading = np.zeros(len(series[0]), dtype=int)
    undecided = np.ones(len(series[0]), dtype=bool)
    for value, tolerance in zip(series, tolerances):
        decided = undecided & (np.abs(value) > tolerance)
        heading[decided] = np.sign(value[decided]).astype(int)
        undecided &= ~decided
    return series[0], tolerances[0], heading


# ---------------------------------------------------------------- settling


def settle(
    library: ModeLibrary,
    motion: GroundMotion,
    interval: int,
    t: float,
    x: np.ndarray,
    mode: Mode,
    counters: EventCounters,
    fired: tuple[int, int, int] | None = None,
) -> tuple[Mode, np.ndarray, GuardStates, list[tuple[int, int, int]]]:
    """Find the mode consistent with state x at time t, starting from ``mode``.

    Parameters
    ----------
    library : ModeLibrary
    motion : GroundMotion
    interval : int
        Motion interval whose right-hand derivatives apply at t.
    t : float
        Event time, s.
    x : np.ndarray
        State at t (a stopping base's velocity is zeroed in the returned copy).
    mode : Mode
        Mode before the event.
    counters : EventCounters
    fired : (kind, target, direction) or None
        The guard whose crossing triggered the event, if any.

    Returns
    -------
    mode, x, guard_states, transitions
        The settled mode, the (possibly adjusted) state, the arming state of
        its guards, and every transition applied as (kind, target, direction).
    """
    system = library.system
    x = x.copy()
    ground = motion.derivatives(t, interval)
    transitions = []
    if fired is not None:
        mode = _apply(system, mode, x, fired)
        transitions.append(fired)
    visited = {mode}
    for _ in range(MAX_SETTLE_ITERATIONS):
        dynamics = library[mode]
        values, tolerance, heading = guard_leaving_sign(dynamics, x, ground)
        candidates = _wanting_to_fire(system, dynamics, x, values, tolerance, heading)
        if len(candidates) == 0:
            return mode, x, _initial_guard_states(system, dynamics, x, values, tolerance), transitions
        j = candidates[0]
        transition = (int(dynamics.guard_kind[j]), int(dynamics.guard_target[j]), int(dynamics.guard_direction[j]))
        next_mode = _apply(system, mode, x, transition)
        if next_mode in visited:
            break
        transitions.append(transition)
        visited.add(next_mode)
        mode = next_mode
    counters.chatter_cycles += 1
    dynamics = library[mode]
    values, tolerance, _ = guard_leaving_sign(dynamics, x, ground)
    return mode, x, _initial_guard_states(system, dynamics, x, values, tolerance), transitions


def _wanting_to_fire(system: System, dynamics: ModeDynamics, x: np.ndarray, values: np.ndarray, tolerance: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """Guards that fire at this instant, in index order.

    A non-tensile contact that separated with residual penetration (δ > 0,
    F = 0) recloses only through its RECLOSE guard (trial force > 0 while
    δ > 0), never because δ is positive.
    """
    wanting = heading > 0
    for j in np.flatnonzero(wanting):
        kind, p = dynamics.guard_kind[j], dynamics.guard_target[j]
        if kind == Guard.RECLOSE and _penetration(system, p, x) <= 0.0:
            wanting[j] = False
        elif kind == Guard.CLOSE and not system.contact_tensile[p] and values[j] > tolerance[j]:
            wanting[j] = False
    return np.flatnonzero(wanting)


def _penetration(system: System, p: int, x: np.ndarray) -> float:
    return float(system.contact_geometry[p] @ x[: system.n_dof] - system.contact_gap[p])


def _apply(system: System, mode: Mode, x: np.ndarray, transition: tuple[int, int, int]) -> Mode:
    kind, target, direction = transition
    if kind == Guard.CLOSE or (kind == Guard.RECLOSE and _penetration(system, target, x) > 0.0):
        return mode.with_contact(target, True)
    if kind == Guard.OPEN:
        return mode.with_contact(target, False)
    if kind == Guard.SLIP:
        return mode.with_base(target, direction)
    if kind == Guard.STOP:
        x[system.n_dof + system.base_dofs[target]] = 0.0  # the sliding velocity has reached zero
        return mode.with_base(target, STUCK)
    return mode  # a RECLOSE crossing while not penetrated changes nothing


def _initial_guard_states(system: System, dynamics: ModeDynamics, x: np.ndarray, values: np.ndarray, tolerance: np.ndarray) -> GuardStates:
    threshold = np.where(values < -tolerance, 0.0, FIRE_THRESHOLD / ROUND_OFF * tolerance)
    rearmable = np.ones(len(values), dtype=bool)
    for j, (kind, p) in enumerate(zip(dynamics.guard_kind, dynamics.guard_target)):
        if kind == Guard.RECLOSE and _penetration(system, p, x) <= 0.0:
            threshold[j], rearmable[j] = np.inf, False
        elif kind == Guard.CLOSE and not system.contact_tensile[p] and values[j] > tolerance[j]:
            threshold[j] = np.inf  # residual penetration: wait until δ < 0 again
    return GuardStates(threshold, tolerance, rearmable)


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


# ---------------------------------------------------------------- crossings


def _hermite(g0, g1, d0, d1, h):
    """Coefficients (a0..a3, in τ ∈ [0, 1]) of the cubic Hermite interpolants."""
    return g0, d0 * h, 3.0 * (g1 - g0) - (2.0 * d0 + d1) * h, 2.0 * (g0 - g1) + (d0 + d1) * h


def _critical_points(a1: float, a2: float, a3: float) -> list[float]:
    """Zeros of the cubic's derivative a1 + 2 a2 τ + 3 a3 τ² inside (0, 1), sorted."""
    if a3 == 0.0 and a2 == 0.0:
        return []
    roots = np.roots([3.0 * a3, 2.0 * a2, a1])
    return sorted(float(r.real) for r in roots if abs(r.imag) <= 1e-12 * max(1.0, abs(r.real)) and 0.0 < r.real < 1.0)


def _interior_maximum(a0: np.ndarray, a1: np.ndarray, a2: np.ndarray, a3: np.ndarray) -> np.ndarray:
    """Largest value of each cubic at its critical points inside (0, 1) (−inf if none), vectorised."""
    best = np.full(np.shape(a0), -np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        discriminant = 4.0 * a2**2 - 12.0 * a3 * a1
        root = np.sqrt(np.where(discriminant >= 0.0, discriminant, np.nan))
        candidates = [(-2.0 * a2 + root) / (6.0 * a3), (-2.0 * a2 - root) / (6.0 * a3), -a1 / (2.0 * a2)]
        candidates[2] = np.where(a3 == 0.0, candidates[2], np.nan)
        for tau in candidates:
            inside = (tau > 0.0) & (tau < 1.0)
            value = a0 + tau * (a1 + tau * (a2 + tau * a3))
            best = np.where(inside & (value > best), value, best)
    return best


def first_crossing(
    dynamics: ModeDynamics,
    motion: GroundMotion,
    interval: int,
    step: Step,
    states: GuardStates,
    counters: EventCounters,
) -> tuple[float, int] | None:
    """Earliest guard crossing inside ``step``, as (time, guard index), or None.

    Guards are screened with their cubic Hermite interpolants; candidates are
    confirmed and located to :data:`TIME_TOLERANCE` on ``step.dense``.
    """
    if len(dynamics.guard_kind) == 0:
        return None
    h = step.t1 - step.t0
    ground0 = motion.derivatives(step.t0, interval)
    ground1 = motion.derivatives(step.t1, interval)
    G, gh, g0c = dynamics.guard_matrix, dynamics.guard_ground, dynamics.guard_constant
    values0 = G @ step.x0 + gh * ground0[0] + g0c
    values1 = G @ step.x1 + gh * ground1[0] + g0c
    rates0 = G @ dynamics.rate(step.x0, ground0[0]) + gh * ground0[1]
    rates1 = G @ dynamics.rate(step.x1, ground1[0]) + gh * ground1[1]
    a0, a1, a2, a3 = _hermite(values0, values1, rates0, rates1, h)
    margin = 1e-3 * (np.abs(values0) + np.abs(values1) + np.abs(a1) + np.abs(rates1 * h)) + states.tolerance
    # screen at level 0 for every guard: an armed guard fires at 0, and a disarmed one may too after a dip
    suspects = np.isfinite(states.threshold) & ((values1 >= 0.0) | (_interior_maximum(a0, a1, a2, a3) >= -margin))
    best: tuple[float, int] | None = None
    for j in np.flatnonzero(suspects):

        def guard(t, j=j):
            return float(G[j] @ step.dense(t) + gh[j] * motion.acceleration(t, interval) + g0c[j])

        time = _locate(guard, step, (a0[j], a1[j], a2[j], a3[j]), states, int(j), margin[j], counters)
        if time is not None and (best is None or time < best[0]):
            best = (time, int(j))
    if best is None:
        states.arm_where_negative(values1)
    return best


def _locate(guard, step: Step, coefficients, states: GuardStates, j: int, margin: float, counters: EventCounters) -> float | None:
    """First time ``guard`` crosses its firing level upwards inside the step, or None.

    The step is cut at the critical points of the guard's Hermite cubic, so a
    crossing hidden between two end points of the same sign is bracketed. An
    armed guard fires at 0. A disarmed guard fires at 0 once it has dipped
    below −tolerance (seen at a cut point, or found by :func:`_after_dip`
    before the time it reached its threshold), else at its positive
    threshold. Cubic maxima that come close to the level without confirming
    are checked by maximising the true guard (grazing contacts).
    """
    a0, a1, a2, a3 = coefficients
    h = step.t1 - step.t0
    taus = [0.0, *_critical_points(a1, a2, a3), 1.0]
    times = [step.t0 + tau * h for tau in taus]
    raw = [a0] + [guard(t) for t in times[1:]]
    armed = not states.disarmed[j]
    level = 0.0 if armed else states.threshold[j]
    previous = min(raw[0], -states.tolerance[j]) if armed else raw[0] - level
    crossing = None
    for i in range(1, len(times)):
        if not armed and raw[i] < -states.tolerance[j]:  # a dip: armed from here on, fires at 0
            armed, level, previous = True, 0.0, raw[i]
            continue
        current = raw[i] - level
        if previous < 0.0 <= current:
            crossing = brentq(lambda t: guard(t) - level, times[i - 1], times[i], xtol=TIME_TOLERANCE, rtol=4 * np.finfo(float).eps)
            break
        cubic_here = a0 + taus[i] * (a1 + taus[i] * (a2 + taus[i] * a3)) - level
        if 0 < i < len(times) - 1 and current < 0.0 and cubic_here >= -margin:
            crossing = _grazing(guard, level, times[i - 1], times[min(i + 1, len(times) - 1)], counters)
            if crossing is not None:
                break
        previous = current
    if crossing is None or armed:
        return crossing
    return _after_dip(guard, states.tolerance[j], step.t0, crossing)


def _after_dip(guard, tolerance: float, start: float, crossing: float) -> float:
    """Where a disarmed guard that reached its threshold at ``crossing`` really fires.

    If the guard went below −``tolerance`` between ``start`` and ``crossing``
    (a dip between the points ``_locate`` samples, e.g. a contact that opens
    and closes again within one step), it was armed again there and fires at
    its first zero after the dip; otherwise at ``crossing``. The dip is found
    by minimising the true guard (bounded Brent, as ``_grazing``).
    """
    found = minimize_scalar(guard, bounds=(start, crossing), method="bounded", options={"xatol": 1e-12})
    if found.fun < -tolerance:
        return brentq(guard, found.x, crossing, xtol=TIME_TOLERANCE, rtol=4 * np.finfo(float).eps)
    return crossing


def _grazing(guard, level: float, start: float, end: float, counters: EventCounters) -> float | None:
    """Maximise the true guard over [start, end]; the first crossing if its maximum reaches the level."""
    counters.grazing_checks += 1
    found = minimize_scalar(lambda t: level - guard(t), bounds=(start, end), method="bounded", options={"xatol": 1e-12})
    if -found.fun >= 0.0 and guard(start) - level < 0.0:
        return brentq(lambda t: guard(t) - level, start, found.x, xtol=TIME_TOLERANCE, rtol=4 * np.finfo(float).eps)
    return None
