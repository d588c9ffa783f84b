"""Compiled (numba) loop of the exact solver over event-free sample intervals.

:func:`advance_quiet` advances the state of one mode interval after interval
with the exact sub-step propagator of :mod:`stochpound.propagators`, and does
for every sub-step what the shared Python code does for a step:

* the guard screen of :func:`stochpound.events.first_crossing` (end values,
  and interior maxima of the cubic Hermite interpolants, with the same margin),
  and the re-arming of disarmed guards that have gone below zero
  (:meth:`stochpound.events.GuardStates.arm_where_negative`);
* the energy terms, impulses and end-point peak forces of
  :meth:`stochpound.recorder.Recorder.on_step`, by 5-point Gauss–Legendre
  quadrature on the exact states at the nodes.

It stops, with the state and guard arming rolled back to the start of the
interval, at the first interval in which a guard is suspected to cross or an
impact force has an interior maximum: that interval is left to the shared
Python event code, which is the only judge of events. So this loop decides
nothing the Python code would decide differently; it only skips it where
nothing happens.
"""

from __future__ import annotations

import numpy as np
from numba import njit

FINISHED = 0
"""Status: every interval up to the end of the motion was advanced."""
NEEDS_EVENTS = 1
"""Status: the returned interval must be advanced by the Python event code."""

_INPUT, _DAMPING, _FRICTION, _IMPACT = 0, 1, 2, 3


@njit(cache=True, inline="always")
def _matvec(matrix, vector, out):
    """out = matrix @ vector for the first len(out) rows."""
    for i in range(out.shape[0]):
        total = 0.0
        for j in range(vector.shape[0]):
            total += matrix[i, j] * vector[j]
        out[i] = total


@njit(cache=True, inline="always")
def _guards_and_rates(G, gh, g0, A, B, c, x, ground, ground_rate, values, rates, work):
    """Guard values G x + h a_g + g0 and rates G (A x + B a_g + c) + h ȧ_g."""
    for i in range(A.shape[0]):
        total = B[i] * ground + c[i]
        for j in range(A.shape[1]):
            total += A[i, j] * x[j]
        work[i] = total
    for g in range(G.shape[0]):
        value = gh[g] * ground + g0[g]
        rate = gh[g] * ground_rate
        for j in range(G.shape[1]):
            value += G[g, j] * x[j]
            rate += G[g, j] * work[j]
        values[g] = value
        rates[g] = rate


@njit(cache=True, inline="always")
def _cubic_value(a0, a1, a2, a3, tau):
    return a0 + tau * (a1 + tau * (a2 + tau * a3))


@njit(cache=True, inline="always")
def _interior_maximum(a0, a1, a2, a3):
    """Largest value of the cubic at its critical points inside (0, 1), −inf if none."""
    best = -np.inf
    if a3 != 0.0:
        discriminant = 4.0 * a2 * a2 - 12.0 * a3 * a1
        if discriminant >= 0.0:
            root = np.sqrt(discriminant)
            for tau in ((-2.0 * a2 + root) / (6.0 * a3), (-2.0 * a2 - root) / (6.0 * a3)):
                if 0.0 < tau < 1.0:
                    best = max(best, _cubic_value(a0, a1, a2, a3, tau))
    elif a2 != 0.0:
        tau = -a1 / (2.0 * a2)
        if 0.0 < tau < 1.0:
            best = max(best, _cubic_value(a0, a1, a2, a3, tau))
    return best


@njit(cache=True, inline="always")
def _suspect(values0, values1, rates0, rates1, h, threshold, tolerance):
    """True when first_crossing would examine some guard of this sub-step."""
    for g in range(values0.shape[0]):
        if not abs(threshold[g]) < np.inf:
            continue
        if values1[g] >= 0.0:
            return True
        a0, a1 = values0[g], rates0[g] * h
        a2 = 3.0 * (values1[g] - values0[g]) - (2.0 * rates0[g] + rates1[g]) * h
        a3 = 2.0 * (values0[g] - values1[g]) + (rates0[g] + rates1[g]) * h
        margin = 1e-3 * (abs(values0[g]) + abs(values1[g]) + abs(a1) + abs(rates1[g] * h)) + tolerance[g]
        if _interior_maximum(a0, a1, a2, a3) >= -margin:
            return True
    return False


@njit(cache=True, inline="always")
def arm_where_negative(values, threshold, tolerance, rearmable, disarmed):
    """``GuardStates.arm_where_negative``: arm the disarmed guards that went below −tolerance."""
    for g in range(values.shape[0]):
        if disarmed[g] and rearmable[g] and values[g] < -tolerance[g]:
            threshold[g] = 0.0
            disarmed[g] = False


@njit(cache=True, inline="always")
def _force_rate(row, A, B, c, x, ground):
    total = 0.0
    for i in range(A.shape[0]):
        rate = B[i] * ground + c[i]
        for j in range(A.shape[1]):
            rate += A[i, j] * x[j]
        total += row[i] * rate
    return total


@njit(cache=True, inline="always")
def _peaks(force_matrix, force_constant, A, B, c, open_impacts, peak_force, peak_time, x0, a0, t0, x1, a1, t1):
    """Offer the end-point forces as peaks; True if some open impact has a force maximum inside."""
    for p in range(open_impacts.shape[0]):
        if not open_impacts[p]:
            continue
        row = force_matrix[p]
        for x, t in ((x0, t0), (x1, t1)):
            force = force_constant[p]
            for j in range(x.shape[0]):
                force += row[j] * x[j]
            if force > peak_force[p]:
                peak_force[p], peak_time[p] = force, t
        if _force_rate(row, A, B, c, x0, a0) > 0.0 > _force_rate(row, A, B, c, x1, a1):
            return True
    return False


@njit(cache=True, inline="always")
def add_power(state, ground, weight, force_matrix, force_constant, friction_matrix, friction_ground, friction_constant,
              contact_load, damping, influence, base_dofs, open_impacts, impulse, running):
    """Add weight × the power of every force at one quadrature node (``Recorder.on_step``).

    ``state`` is x at the node and ``ground`` a_g there; ``running`` gets the
    input, damping, friction and impact terms (J), ``impulse`` the contact
    forces of open impacts (N·s).
    """
    size = force_matrix.shape[1]
    n = size // 2
    drive, dissipation = 0.0, 0.0
    for a in range(n):
        drive += influence[a] * state[n + a]
        row = 0.0
        for b in range(n):
            row += damping[a, b] * state[n + b]
        dissipation += state[n + a] * row
    running[_INPUT] -= weight * ground * drive
    running[_DAMPING] += weight * dissipation
    for b in range(base_dofs.shape[0]):
        if base_dofs[b] < 0:
            continue
        friction = friction_ground[b] * ground + friction_constant[b]
        for j in range(size):
            friction += friction_matrix[b, j] * state[j]
        running[_FRICTION] -= weight * friction * state[n + base_dofs[b]]
    for p in range(force_matrix.shape[0]):
        force = force_constant[p]
        for j in range(size):
            force += force_matrix[p, j] * state[j]
        if force == 0.0:
            continue
        load_rate = 0.0
        for j in range(n):
            load_rate += contact_load[p, j] * state[n + j]
        running[_IMPACT] += weight * force * load_rate
        if open_impacts[p]:
            impulse[p] += weight * force


@njit(cache=True, inline="always")
def _quadrature(nodes, weights, z0, node_state, force_matrix, force_constant, friction_matrix, friction_ground,
                friction_constant, contact_load, damping, influence, base_dofs, open_impacts, impulse, running):
    """Add a full sub-step's energy terms and impulses (5-point Gauss–Legendre on the exact node states)."""
    size = force_matrix.shape[1]
    for i in range(nodes.shape[0]):
        _matvec(nodes[i], z0, node_state)
        add_power(node_state[:size], node_state[size], weights[i], force_matrix, force_constant, friction_matrix,
                  friction_ground, friction_constant, contact_load, damping, influence, base_dofs, open_impacts, impulse, running)


@njit(cache=True, inline="always")
def _save(saved, running, impulse, peak_force, peak_time, threshold, disarmed):
    """Copy the running totals and guard arming into ``saved``."""
    i = 0
    for array in (running, impulse, peak_force, peak_time, threshold):
        saved[i : i + array.shape[0]] = array
        i += array.shape[0]
    for g in range(disarmed.shape[0]):
        saved[i + g] = 1.0 if disarmed[g] else 0.0


@njit(cache=True, inline="always")
def _restore(saved, running, impulse, peak_force, peak_time, threshold, disarmed):
    """Undo everything since :func:`_save`."""
    i = 0
    for array in (running, impulse, peak_force, peak_time, threshold):
        array[:] = saved[i : i + array.shape[0]]
        i += array.shape[0]
    for g in range(disarmed.shape[0]):
        disarmed[g] = saved[i + g] != 0.0


def work_arrays(width: int, n_guards: int, n_contacts: int) -> tuple[np.ndarray, np.ndarray]:
    """``scratch`` and ``saved`` work arrays of :func:`advance_quiet` for augmented size ``width``."""
    return np.zeros((8, max(width, n_guards, 1))), np.zeros(4 + 3 * n_contacts + 2 * n_guards)


@njit(cache=True, nogil=True)
def advance_quiet(
    first, x, forcing, times, substeps, transition, nodes, node_weights,
    A, B, c, G, gh, g0, threshold, tolerance, rearmable, disarmed,
    force_matrix, force_constant, friction_matrix, friction_ground, friction_constant,
    contact_load, damping, influence, base_dofs,
    open_impacts, impulse, peak_force, peak_time, running, states_out, energy_out, scratch, saved,
):
    """Advance one mode from interval ``first`` until an interval needs the event code.

    Parameters
    ----------
    first : int
        First interval k; ``x`` is the state at ``times[k]`` (updated in place).
    forcing : (n_intervals, 4) array
        Exosystem state [a_g, ȧ_g, ä_g, a⃛_g] at the start of every interval.
    times : array
        Output times, s.
    substeps, transition, nodes : int, (Z, Z), (5, Z, Z)
        Sub-steps per interval and the exact sub-step and node propagators.
    node_weights : (5,) array
        Gauss–Legendre weights times h / 2, s.
    A, B, c, G, gh, g0 : arrays
        The mode's dynamics and guards.
    threshold, tolerance, rearmable, disarmed : arrays
        Guard arming state (:class:`~stochpound.events.GuardStates`, updated in place).
    force_matrix ... base_dofs : arrays
        Read-outs of the mode and of the system for the energy terms.
    open_impacts, impulse, peak_force, peak_time : arrays per contact
        Running impact records (updated in place).
    running : (4,) array
        Cumulative energy terms input, damping, friction, impact, J (updated in place).
    states_out, energy_out : (n_times, 2N), (4, n_times) arrays
        Samples written at ``times[k + 1]`` for every interval completed.
    scratch, saved : arrays
        Work arrays from :func:`work_arrays`.

    Returns
    -------
    (int, int)
        The interval where the loop stopped and :data:`FINISHED` or :data:`NEEDS_EVENTS`.
    """
    size = x.shape[0]
    n_guards = G.shape[0]
    n_contacts = impulse.shape[0]
    width = transition.shape[0]
    z0, z1, node_state, work = scratch[0, :width], scratch[1, :width], scratch[2, :width], scratch[3, :size]
    values0, values1, rates0, rates1 = scratch[4, :n_guards], scratch[5, :n_guards], scratch[6, :n_guards], scratch[7, :n_guards]
    for k in range(first, forcing.shape[0]):
        h = (times[k + 1] - times[k]) / substeps
        _save(saved, running, impulse, peak_force, peak_time, threshold, disarmed)
        z0[:size] = x
        z0[size : size + 4] = forcing[k]
        z0[width - 1] = 1.0
        if n_guards > 0:
            _guards_and_rates(G, gh, g0, A, B, c, z0[:size], z0[size], z0[size + 1], values0, rates0, work)
        for j in range(substeps):
            _matvec(transition, z0, z1)
            t0 = times[k] + j * h
            t1 = times[k + 1] if j == substeps - 1 else t0 + h
            quiet = True
            if n_guards > 0:
                _guards_and_rates(G, gh, g0, A, B, c, z1[:size], z1[size], z1[size + 1], values1, rates1, work)
                quiet = not _suspect(values0, values1, rates0, rates1, h, threshold, tolerance)
            if quiet and n_contacts > 0:
                quiet = not _peaks(force_matrix, force_constant, A, B, c, open_impacts, peak_force, peak_time,
                                   z0[:size], z0[size], t0, z1[:size], z1[size], t1)
            if not quiet:
                _restore(saved, running, impulse, peak_force, peak_time, threshold, disarmed)
                return k, NEEDS_EVENTS
            _quadrature(nodes, node_weights, z0, node_state, force_matrix, force_constant, friction_matrix,
                        friction_ground, friction_constant, contact_load, damping, influence, base_dofs,
                        open_impacts, impulse, running)
            if n_guards > 0:
                arm_where_negative(values1, threshold, tolerance, rearmable, disarmed)
                values0[:], rates0[:] = values1, rates1
            z0[:] = z1
        x[:] = z0[:size]
        states_out[k + 1] = x
        energy_out[:, k + 1] = running
    return forcing.shape[0], FINISHED
