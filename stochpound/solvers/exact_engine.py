"""Compiled (numba) event-driven run of the exact solver.

This is the fast path of ``method="exact"``: the whole run, events included,
happens in compiled code, and Python is called back only to build the
matrices and propagators of a mode the run reaches for the first time (and
to grow the impact table). It is a line-by-line port of the shared Python
logic, which stays the specification:

* guard crossings: :func:`stochpound.events.first_crossing` (Hermite screen,
  ``_locate``, ``_grazing``), with scipy's ``brentq`` and bounded Brent
  minimiser ported below;
* settling: :func:`stochpound.events.settle` (``guard_leaving_sign``,
  ``_wanting_to_fire``, ``_apply``, ``_initial_guard_states``) with the same
  constants (imported from :mod:`stochpound.events`);
* recording: :meth:`stochpound.recorder.Recorder.on_step` (energy terms by
  5-point Gauss–Legendre quadrature, impulses, located peak forces),
  ``on_transitions`` and ``on_contact_force``.

``tests/test_exact.py`` checks that this path and the Python event path
(``run_exact(..., events="python")``, which calls the shared code itself)
give the same events and the same answer on the hard cases.

Modes are int64 vectors [closed flags of every contact, state of every base]
and are found in the table of built modes by hash. All arrays are grouped in
three named tuples: :class:`Tables` (one row per built mode),
:class:`Plant` (system and motion) and :class:`RunState` (everything the run
changes, so that a call can stop for a missing mode and resume). Only the
top-level functions take them; helpers take the few arrays they use, or a
:class:`Flow` (one mode's dense flow inside one step), which keeps numba's
compile time down (a named tuple of arrays is flattened into every signature).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit

from stochpound.events import FIRE_THRESHOLD, MAX_SETTLE_ITERATIONS, ROUND_OFF, TIME_TOLERANCE
from stochpound.modes import STUCK, Guard
from stochpound.solvers.exact_kernel import (
    _force_rate,
    _guards_and_rates,
    _interior_maximum,
    _matvec,
    _quadrature,
    _suspect,
    add_power,
    advance_quiet,
    arm_where_negative,
)

Tables = namedtuple(
    "Tables",
    "hashes modes ids A B c G gh g0 kind target direction n_guards F f0 Fr frg frc transition nodes chebyshev substeps step",
)
Plant = namedtuple(
    "Plant",
    "n_dof geometry gap load tensile damping influence base_dofs left_rows right_rows times forcing coefficients harmonic "
    "gauss_nodes gauss_weights",
)
RunState = namedtuple(
    "RunState",
    "clock ints x pending_x pending_mode missing_mode threshold tolerance rearmable disarmed "
    "is_open impact_start impact_onset impact_in_phase impact_peak impact_peak_time impact_impulse "
    "impacts running states energy sample_modes visited",
)

Flow = namedtuple("Flow", "A B c G gh g0 F f0 coefficients t0 scale k times motion harmonic")

# ints of RunState
K, MODE, PENDING, FIRED_KIND, FIRED_TARGET, FIRED_DIRECTION, N_IMPACTS, TOTAL, CHATTER, GRAZING = range(10)
N_INTS = 10
# pending settles
NONE, INITIAL, EVENT = 0, 1, 2
# statuses returned to Python
FINISHED, NEED_MODE, NEED_SPACE = 0, 1, 2
# impact table columns
IMPACT_COLUMNS = ("contact", "start", "end", "onset_velocity", "in_phase", "peak_force", "peak_time", "impulse", "complete")

_CLOSE, _RECLOSE, _OPEN, _SLIP, _STOP = int(Guard.CLOSE), int(Guard.RECLOSE), int(Guard.OPEN), int(Guard.SLIP), int(Guard.STOP)
_STUCK = STUCK
_ROUND_OFF, _FIRE_RATIO, _XTOL, _MAX_SETTLE = ROUND_OFF, FIRE_THRESHOLD / ROUND_OFF, TIME_TOLERANCE, MAX_SETTLE_ITERATIONS
_RTOL = 4 * np.finfo(float).eps
_INPUT, _DAMPING, _FRICTION, _IMPACT = 0, 1, 2, 3
_GUARD, _FORCE_RATE = 0, 1


# ---------------------------------------------------------------- modes


@njit(cache=True)
def mode_hash(mode):
    """64-bit FNV-1a hash of a mode vector."""
    value = np.uint64(14695981039346656037)
    for entry in mode:
        value = (value ^ np.uint64(entry + 3)) * np.uint64(1099511628211)
    return np.int64(value)


@njit(cache=True)
def _lookup(hashes, modes, mode):
    """Index of ``mode`` among the built modes, or −1."""
    key = mode_hash(mode)
    for i in range(hashes.shape[0]):
        if hashes[i] == key and _same(modes[i], mode):
            return i
    return -1


@njit(cache=True, inline="always")
def _same(a, b):
    """Element-wise equality of two mode vectors."""
    for i in range(a.shape[0]):
        if a[i] != b[i]:
            return False
    return True


# ---------------------------------------------------------------- ground and dense state


@njit(cache=True, inline="always")
def _ground(times, motion, harmonic, t, k, out):
    """[a_g, ȧ_g, ä_g, a⃛_g] at t in interval k (as ``GroundMotion.derivatives``)."""
    if harmonic.shape[0] == 0:
        c0, c1, c2, c3 = motion[k, 0], motion[k, 1], motion[k, 2], motion[k, 3]
        tau = t - times[k]
        out[0] = c0 + tau * (c1 + tau * (c2 + tau * c3))
        out[1] = c1 + tau * (2.0 * c2 + 3.0 * tau * c3)
        out[2] = 2.0 * c2 + 6.0 * tau * c3
        out[3] = 6.0 * c3
    else:
        a, w, phase = harmonic[0], harmonic[1], harmonic[2]
        angle = w * t + phase
        out[0] = a * np.sin(angle)
        out[1] = a * w * np.cos(angle)
        out[2] = -a * w * w * np.sin(angle)
        out[3] = -a * w * w * w * np.cos(angle)


@njit(cache=True, inline="always")
def _ground_value(flow, t):
    """a_g at t in the flow's interval (as ``GroundMotion.acceleration``)."""
    if flow.harmonic.shape[0] == 0:
        tau = t - flow.times[flow.k]
        c = flow.motion[flow.k]
        return c[0] + tau * (c[1] + tau * (c[2] + tau * c[3]))
    return flow.harmonic[0] * np.sin(flow.harmonic[1] * t + flow.harmonic[2])


@njit(cache=True, inline="always")
def _dense(flow, t, out):
    """x(t) from the step's Chebyshev coefficients (as ``ModePropagator.dense``)."""
    s = min(max((t - flow.t0) * flow.scale - 1.0, -1.0), 1.0)
    theta = np.arccos(s)
    out[:] = 0.0
    coefficients = flow.coefficients
    for n in range(coefficients.shape[0]):
        weight = np.cos(n * theta)
        for i in range(out.shape[0]):
            out[i] += weight * coefficients[n, i]


@njit(cache=True)
def _evaluate(flow, what, index, level, t, work):
    """Guard ``index`` minus ``level`` (what = _GUARD), or the rate of contact force ``index``, at t."""
    _dense(flow, t, work)
    ground = _ground_value(flow, t)
    if what == _GUARD:
        row = flow.G[index]
        value = flow.gh[index] * ground + flow.g0[index]
        for j in range(work.shape[0]):
            value += row[j] * work[j]
        return value - level
    return _force_rate(flow.F[index], flow.A, flow.B, flow.c, work, ground)


@njit(cache=True, inline="always")
def _force(F, f0, p, x):
    value = f0[p]
    for j in range(x.shape[0]):
        value += F[p, j] * x[j]
    return value


# ---------------------------------------------------------------- scipy's brentq and bounded Brent, ported


@njit(cache=True)
def _brentq(flow, what, index, level, xa, xb, work):
    """Root of _evaluate in [xa, xb] (scipy.optimize.brentq, xtol = TIME_TOLERANCE, rtol = 4 eps)."""
    xpre, xcur = xa, xb
    xblk, fblk, spre, scur = 0.0, 0.0, 0.0, 0.0
    fpre = _evaluate(flow, what, index, level, xpre, work)
    fcur = _evaluate(flow, what, index, level, xcur, work)
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    if (fpre > 0.0) == (fcur > 0.0):
        raise ValueError("f(a) and f(b) must have different signs")
    for _ in range(100):
        if fpre != 0.0 and fcur != 0.0 and (fpre < 0.0) != (fcur < 0.0):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (_XTOL + _RTOL * abs(xcur)) / 2.0
        sbis = (xblk - xcur) / 2.0
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
                spre, scur = scur, stry
            else:
                spre, scur = sbis, sbis
        else:
            spre, scur = sbis, sbis
        xpre, fpre = xcur, fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0.0 else -delta
        fcur = _evaluate(flow, what, index, level, xcur, work)
    return xcur


@njit(cache=True)
def _maximise_guard(flow, j, level, a, b, work):
    """(t, level − guard(t)) minimising level − guard on [a, b] (scipy's bounded Brent, xatol = 1e-12)."""
    xatol, sqrt_eps, golden_mean = 1e-12, np.sqrt(2.2e-16), 0.5 * (3.0 - np.sqrt(5.0))
    fulc = a + golden_mean * (b - a)
    nfc, xf = fulc, fulc
    rat = e = 0.0
    fx = -_evaluate(flow, _GUARD, j, level, xf, work)
    num = 1
    ffulc = fnfc = fx
    xm = 0.5 * (a + b)
    tol1 = sqrt_eps * abs(xf) + xatol / 3.0
    tol2 = 2.0 * tol1
    while abs(xf - xm) > (tol2 - 0.5 * (b - a)):
        golden = True
        if abs(e) > tol1:
            golden = False
            r = (xf - nfc) * (fx - ffulc)
            q = (xf - fulc) * (fx - fnfc)
            p = (xf - fulc) * q - (xf - nfc) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            r = e
            e = rat
            if abs(p) < abs(0.5 * q * r) and p > q * (a - xf) and p < q * (b - xf):
                rat = (p + 0.0) / q
                x = xf + rat
                if (x - a) < tol2 or (b - x) < tol2:
                    rat = tol1 * (1.0 if xm >= xf else -1.0)
            else:
                golden = True
        if golden:
            e = a - xf if xf >= xm else b - xf
            rat = golden_mean * e
        x = xf + (1.0 if rat >= 0.0 else -1.0) * max(abs(rat), tol1)
        fu = -_evaluate(flow, _GUARD, j, level, x, work)
        num += 1
        if fu <= fx:
            if x >= xf:
                a = xf
            else:
                b = xf
            fulc, ffulc = nfc, fnfc
            nfc, fnfc = xf, fx
            xf, fx = x, fu
        else:
            if x < xf:
                a = x
            else:
                b = x
            if fu <= fnfc or nfc == xf:
                fulc, ffulc = nfc, fnfc
                nfc, fnfc = x, fu
            elif fu <= ffulc or fulc == xf or fulc == nfc:
                fulc, ffulc = x, fu
        xm = 0.5 * (a + b)
        tol1 = sqrt_eps * abs(xf) + xatol / 3.0
        tol2 = 2.0 * tol1
        if num >= 500:
            break
    return xf, fx


# ---------------------------------------------------------------- first_crossing


@njit(cache=True)
def _critical_points(a1, a2, a3, out):
    """Zeros of a1 + 2 a2 τ + 3 a3 τ² inside (0, 1), sorted, into out; returns their number."""
    count = 0
    if a3 == 0.0 and a2 == 0.0:
        return 0
    if a3 == 0.0:
        root = -a1 / (2.0 * a2)
        if 0.0 < root < 1.0:
            out[0] = root
            count = 1
        return count
    qa, qb, qc = 3.0 * a3, 2.0 * a2, a1
    discriminant = qb * qb - 4.0 * qa * qc
    if discriminant >= 0.0:
        half = -0.5 * (qb + np.sqrt(discriminant)) if qb >= 0.0 else -0.5 * (qb - np.sqrt(discriminant))
        r1 = half / qa
        r2 = qc / half if half != 0.0 else r1
        low, high = min(r1, r2), max(r1, r2)
    else:
        low = high = -qb / (2.0 * qa)
        if np.sqrt(-discriminant) / (2.0 * abs(qa)) > 1e-12 * max(1.0, abs(low)):
            return 0
    if 0.0 < low < 1.0:
        out[count] = low
        count += 1
    if 0.0 < high < 1.0:
        out[count] = high
        count += 1
    return count


@njit(cache=True)
def _locate(flow, j, armed, threshold, tolerance, counters, a0, a1, a2, a3, margin, t1, work):
    """First time guard j crosses its firing level upwards in [t0, t1], or NaN (``events._locate``)."""
    t0 = flow.t0
    h = t1 - t0
    taus = np.zeros(4)
    n = _critical_points(a1, a2, a3, taus[1:3]) + 2
    taus[n - 1] = 1.0
    times = t0 + taus[:n] * h
    raw = np.empty(n)
    raw[0] = a0
    for i in range(1, n):
        raw[i] = _evaluate(flow, _GUARD, j, 0.0, times[i], work)
    level = 0.0 if armed else threshold
    previous = min(raw[0], -tolerance) if armed else raw[0] - level
    for i in range(1, n):
        current = raw[i] - level
        if previous < 0.0 <= current:
            return _brentq(flow, _GUARD, j, level, times[i - 1], times[i], work)
        tau = taus[i]
        cubic_here = a0 + tau * (a1 + tau * (a2 + tau * a3)) - level
        if 0 < i < n - 1 and current < 0.0 and cubic_here >= -margin:
            found = _grazing(flow, j, level, counters, times[i - 1], times[min(i + 1, n - 1)], work)
            if found == found:  # not NaN
                return found
        if not armed and raw[i] < -tolerance:
            armed, level = True, 0.0
            current = raw[i]
        previous = current
    return np.nan


@njit(cache=True)
def _grazing(flow, j, level, counters, start, end, work):
    """``events._grazing``: maximise the true guard; its first crossing if the maximum reaches the level."""
    counters[GRAZING] += 1
    t_max, value = _maximise_guard(flow, j, level, start, end, work)
    if -value >= 0.0 and _evaluate(flow, _GUARD, j, level, start, work) < 0.0:
        return _brentq(flow, _GUARD, j, level, start, t_max, work)
    return np.nan


@njit(cache=True)
def _first_crossing(flow, threshold, tolerance, rearmable, disarmed, counters, t1, values0, values1, rates0, rates1, work):
    """(time, guard) of the earliest crossing in [t0, t1], or (NaN, −1) (``events.first_crossing``)."""
    h = t1 - flow.t0
    best_time, best_guard = np.nan, -1
    for j in range(values0.shape[0]):
        if not abs(threshold[j]) < np.inf:
            continue
        a0, a1 = values0[j], rates0[j] * h
        a2 = 3.0 * (values1[j] - values0[j]) - (2.0 * rates0[j] + rates1[j]) * h
        a3 = 2.0 * (values0[j] - values1[j]) + (rates0[j] + rates1[j]) * h
        margin = 1e-3 * (abs(values0[j]) + abs(values1[j]) + abs(a1) + abs(rates1[j] * h)) + tolerance[j]
        level = 0.0 if disarmed[j] else threshold[j]
        if not (values1[j] >= level or _interior_maximum(a0, a1, a2, a3) >= level - margin):
            continue
        time = _locate(flow, j, not disarmed[j], threshold[j], tolerance[j], counters, a0, a1, a2, a3, margin, t1, work)
        if time == time and (best_guard < 0 or time < best_time):
            best_time, best_guard = time, j
    if best_guard < 0:
        arm_where_negative(values1, threshold, tolerance, rearmable, disarmed)
    return best_time, best_guard


# ---------------------------------------------------------------- settle


@njit(cache=True, inline="always")
def _penetration(geometry, gap, p, x):
    value = -gap[p]
    for j in range(geometry.shape[1]):
        value += geometry[p, j] * x[j]
    return value


@njit(cache=True)
def _apply(geometry, gap, base_dofs, mode, x, kind, target, direction):
    """``events._apply`` on a mode vector (changed in place); a STOP zeroes the base velocity in x."""
    n_contacts = gap.shape[0]
    if kind == _CLOSE or (kind == _RECLOSE and _penetration(geometry, gap, target, x) > 0.0):
        mode[target] = 1
    elif kind == _OPEN:
        mode[target] = 0
    elif kind == _SLIP:
        mode[n_contacts + target] = direction
    elif kind == _STOP:
        x[geometry.shape[1] + base_dofs[target]] = 0.0
        mode[n_contacts + target] = _STUCK


@njit(cache=True)
def _leaving_sign(A, B, c, G, gh, g0, x, ground, values, tolerance, heading):
    """``events.guard_leaving_sign``: values, tolerances and heading of the guards G, gh, g0."""
    n_guards = G.shape[0]
    size = x.shape[0]
    derivative = x.copy()
    magnitude = np.empty(size)
    for i in range(size):
        magnitude[i] = abs(x[i])
    heading[:n_guards] = 0
    undecided = np.empty(n_guards, dtype=np.bool_)
    undecided[:] = True
    for order in range(4):
        for g in range(n_guards):
            value = gh[g] * ground[order] + (g0[g] if order == 0 else 0.0)
            scale = abs(gh[g]) * abs(ground[order]) + (abs(g0[g]) if order == 0 else 0.0)
            floor = abs(gh[g])
            for j in range(size):
                value += G[g, j] * derivative[j]
                scale += abs(G[g, j]) * magnitude[j]
                floor += abs(G[g, j])
            limit = _ROUND_OFF * (scale + 1e-4 * floor)
            if order == 0:
                values[g], tolerance[g] = value, limit
            if undecided[g] and abs(value) > limit:
                heading[g] = 1 if value > 0.0 else -1
                undecided[g] = False
        next_derivative = np.empty(size)
        next_magnitude = np.empty(size)
        for i in range(size):
            rate = B[i] * ground[order] + (c[i] if order == 0 else 0.0)
            bound = abs(B[i]) * abs(ground[order]) + (abs(c[i]) if order == 0 else 0.0)
            for j in range(size):
                rate += A[i, j] * derivative[j]
                bound += abs(A[i, j]) * magnitude[j]
            next_derivative[i], next_magnitude[i] = rate, bound
        derivative, magnitude = next_derivative, next_magnitude


@njit(cache=True, inline="always")
def _ignored(kind, p, geometry, gap, tensile, x, value, tolerance):
    """A guard that may not fire now: RECLOSE while not penetrated, CLOSE of a non-tensile contact still penetrated."""
    if kind == _RECLOSE and _penetration(geometry, gap, p, x) <= 0.0:
        return True
    return kind == _CLOSE and not tensile[p] and value > tolerance


@njit(cache=True)
def _first_wanting(kinds, targets, geometry, gap, tensile, x, values, tolerance, heading):
    """Index of the first guard that fires at this instant (``events._wanting_to_fire``), or −1."""
    for j in range(kinds.shape[0]):
        if heading[j] > 0 and not _ignored(kinds[j], targets[j], geometry, gap, tensile, x, values[j], tolerance[j]):
            return j
    return -1


@njit(cache=True)
def _initial_guard_states(kinds, targets, geometry, gap, tensile, x, values, tolerance, threshold_out, tolerance_out, rearmable, disarmed):
    """``events._initial_guard_states`` into the run's guard arrays."""
    for j in range(kinds.shape[0]):
        tolerance_out[j] = tolerance[j]
        threshold_out[j] = 0.0 if values[j] < -tolerance[j] else _FIRE_RATIO * tolerance[j]
        rearmable[j] = True
        kind, p = kinds[j], targets[j]
        if kind == _RECLOSE and _penetration(geometry, gap, p, x) <= 0.0:
            threshold_out[j], rearmable[j] = np.inf, False
        elif kind == _CLOSE and not tensile[p] and values[j] > tolerance[j]:
            threshold_out[j] = np.inf
        disarmed[j] = threshold_out[j] != 0.0


@njit(cache=True)
def _settle(tables, plant, run, transitions):
    """``events.settle`` of the pending (t, x, mode, fired); returns (mode index, x, number of transitions).

    Returns mode index −1 (and the missing mode in ``run.missing_mode``) when a
    mode is not built yet: nothing in ``run`` has changed then.
    """
    t, k = run.clock[0], run.ints[K]
    x = run.pending_x.copy()
    mode = run.pending_mode.copy()
    ground = np.empty(4)
    _ground(plant.times, plant.coefficients, plant.harmonic, t, k, ground)
    n_guards_max = tables.G.shape[1]
    values, tolerance = np.empty(n_guards_max), np.empty(n_guards_max)
    heading = np.zeros(n_guards_max, dtype=np.int64)
    geometry, gap, tensile = plant.geometry, plant.gap, plant.tensile
    n_transitions = 0
    if run.ints[PENDING] == EVENT:
        kind, target, direction = run.ints[FIRED_KIND], run.ints[FIRED_TARGET], run.ints[FIRED_DIRECTION]
        _apply(geometry, gap, plant.base_dofs, mode, x, kind, target, direction)
        transitions[0, 0], transitions[0, 1], transitions[0, 2] = kind, target, direction
        n_transitions = 1
    visited = np.empty((_MAX_SETTLE + 1, mode.shape[0]), dtype=np.int64)
    visited[0] = mode
    n_visited = 1
    settled = False
    for _ in range(_MAX_SETTLE):
        m = _lookup(tables.hashes, tables.modes, mode)
        if m < 0:
            run.missing_mode[:] = mode
            return -1, x, 0
        n = tables.n_guards[m]
        _leaving_sign(tables.A[m], tables.B[m], tables.c[m], tables.G[m, :n], tables.gh[m, :n], tables.g0[m, :n], x, ground, values, tolerance, heading)
        j = _first_wanting(tables.kind[m, :n], tables.target[m, :n], geometry, gap, tensile, x, values, tolerance, heading)
        if j < 0:
            settled = True
            break
        kind, target, direction = tables.kind[m, j], tables.target[m, j], tables.direction[m, j]
        following = mode.copy()
        _apply(geometry, gap, plant.base_dofs, following, x, kind, target, direction)
        cycle = False
        for v in range(n_visited):
            if _same(visited[v], following):
                cycle = True
        if cycle:
            break
        transitions[n_transitions, 0], transitions[n_transitions, 1], transitions[n_transitions, 2] = kind, target, direction
        n_transitions += 1
        visited[n_visited] = following
        n_visited += 1
        mode = following
    m = _lookup(tables.hashes, tables.modes, mode)
    if m < 0:
        run.missing_mode[:] = mode
        return -1, x, 0
    n = tables.n_guards[m]
    if not settled:
        run.ints[CHATTER] += 1
        _leaving_sign(tables.A[m], tables.B[m], tables.c[m], tables.G[m, :n], tables.gh[m, :n], tables.g0[m, :n], x, ground, values, tolerance, heading)
    _initial_guard_states(tables.kind[m, :n], tables.target[m, :n], geometry, gap, tensile, x, values, tolerance,
                          run.threshold, run.tolerance, run.rearmable, run.disarmed)
    return m, x, n_transitions


# ---------------------------------------------------------------- recording


@njit(cache=True, inline="always")
def _offer_peak(peak, peak_time, p, t, value):
    if value > peak[p]:
        peak[p], peak_time[p] = value, t


@njit(cache=True)
def _on_transitions(tables, plant, run, m, t, x, transitions, n_transitions):
    """``Recorder.on_transitions`` and ``on_contact_force`` at an event."""
    n = plant.n_dof
    for i in range(n_transitions):
        kind, p = transitions[i, 0], transitions[i, 1]
        if (kind == _CLOSE or kind == _RECLOSE) and not run.is_open[p] and tables.modes[m, p] == 1:
            left, right, onset = 0.0, 0.0, 0.0
            for j in range(n):
                left += plant.left_rows[p, j] * x[n + j]
                right += plant.right_rows[p, j] * x[n + j]
                onset += plant.geometry[p, j] * x[n + j]
            run.is_open[p] = True
            run.impact_start[p], run.impact_onset[p], run.impact_in_phase[p] = t, onset, left * right > 0.0
            run.impact_peak[p], run.impact_peak_time[p], run.impact_impulse[p] = 0.0, np.nan, 0.0
        elif kind == _OPEN and run.is_open[p] and tables.modes[m, p] == 0:
            row = run.impacts[run.ints[N_IMPACTS]]
            row[0], row[1], row[2], row[3] = p, run.impact_start[p], t, run.impact_onset[p]
            row[4], row[5], row[6], row[7], row[8] = run.impact_in_phase[p], run.impact_peak[p], run.impact_peak_time[p], run.impact_impulse[p], 1.0
            run.ints[N_IMPACTS] += 1
            run.is_open[p] = False
    for p in range(plant.gap.shape[0]):
        if run.is_open[p]:
            _offer_peak(run.impact_peak, run.impact_peak_time, p, t, _force(tables.F[m], tables.f0[m], p, x))


@njit(cache=True)
def _track_peaks(flow, is_open, peak, peak_time, t1, x0, x1, work):
    """``Recorder._track_peak`` for every open impact (ends, and an interior maximum located by brentq)."""
    t0 = flow.t0
    for p in range(is_open.shape[0]):
        if not is_open[p]:
            continue
        _offer_peak(peak, peak_time, p, t0, _force(flow.F, flow.f0, p, x0))
        _offer_peak(peak, peak_time, p, t1, _force(flow.F, flow.f0, p, x1))
        rate0 = _evaluate(flow, _FORCE_RATE, p, 0.0, t0, work)
        rate1 = _evaluate(flow, _FORCE_RATE, p, 0.0, t1, work)
        if rate0 > 0.0 > rate1:
            t_peak = _brentq(flow, _FORCE_RATE, p, 0.0, t0, t1, work)
            _dense(flow, t_peak, work)
            _offer_peak(peak, peak_time, p, t_peak, _force(flow.F, flow.f0, p, work))


# ---------------------------------------------------------------- the run


@njit(cache=True)
def _advance_span(tables, plant, run, k, t, t_end):
    """Sub-steps of the current mode from t to t_end (``_until_event`` of exact.py).

    Returns True when it stopped at an event (now pending), False at t_end.
    """
    m = run.ints[MODE]
    size = run.x.shape[0]
    width = size + 5
    full = t == plant.times[k] and t_end == plant.times[k + 1]
    n_steps = tables.substeps[m] if full else max(1, int(math.ceil((t_end - t) / tables.step[m] - 1e-9)))
    spacing = (t_end - t) / n_steps
    n = tables.n_guards[m]
    values0, values1, rates0, rates1 = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    z0, z1, node, work, rate_work, ground1 = np.empty(width), np.empty(width), np.empty(width), np.empty(size), np.empty(size), np.empty(4)
    coefficients = np.empty((tables.chebyshev.shape[1], size))
    A, B, c, G, gh, g0 = tables.A[m], tables.B[m], tables.c[m], tables.G[m, :n], tables.gh[m, :n], tables.g0[m, :n]
    F, f0, Fr, frg, frc = tables.F[m], tables.f0[m], tables.Fr[m], tables.frg[m], tables.frc[m]
    threshold, tolerance, rearmable, disarmed = run.threshold[:n], run.tolerance[:n], run.rearmable[:n], run.disarmed[:n]
    weights = 0.5 * tables.step[m] * plant.gauss_weights
    for i in range(n_steps):
        t0 = t + i * spacing  # as np.linspace(t, t_end, n_steps + 1)
        t1 = t_end if i == n_steps - 1 else t + (i + 1) * spacing
        z0[:size] = run.x
        _ground(plant.times, plant.coefficients, plant.harmonic, t0, k, z0[size : size + 4])
        z0[width - 1] = 1.0
        flow = Flow(A, B, c, G, gh, g0, F, f0, coefficients, t0, 2.0 / tables.step[m], k, plant.times, plant.coefficients, plant.harmonic)
        _guards_and_rates(G, gh, g0, A, B, c, run.x, z0[size], z0[size + 1], values0, rates0, rate_work)
        x1 = z1[:size]
        dense = not full
        if full:
            _matvec(tables.transition[m], z0, z1)
        else:
            _chebyshev_state(tables.chebyshev[m], z0, coefficients)
            _dense(flow, t1, x1)
        _ground(plant.times, plant.coefficients, plant.harmonic, t1, k, ground1)
        _guards_and_rates(G, gh, g0, A, B, c, x1, ground1[0], ground1[1], values1, rates1, rate_work)
        if full and (_suspect(values0, values1, rates0, rates1, t1 - t0, threshold, tolerance) or _any(run.is_open)):
            _chebyshev_state(tables.chebyshev[m], z0, coefficients)
            dense = True
        if not dense:
            _quadrature(tables.nodes[m], weights, z0, node, F, f0, Fr, frg, frc, plant.load, plant.damping,
                        plant.influence, plant.base_dofs, run.is_open, run.impact_impulse, run.running)
            arm_where_negative(values1, threshold, tolerance, rearmable, disarmed)
            run.x[:] = x1
            continue
        t_event, guard = _first_crossing(flow, threshold, tolerance, rearmable, disarmed, run.ints, t1, values0, values1, rates0, rates1, work)
        t_stop = t1 if guard < 0 else t_event
        x_stop = x1 if guard < 0 else np.empty(size)
        if guard >= 0:
            _dense(flow, t_event, x_stop)
        if t_stop > t0:  # Recorder.on_step
            half = 0.5 * (t_stop - t0)
            for g in range(plant.gauss_nodes.shape[0]):
                t_node = t0 + half * (plant.gauss_nodes[g] + 1.0)
                _dense(flow, t_node, work)
                add_power(work, _ground_value(flow, t_node), half * plant.gauss_weights[g], F, f0, Fr, frg, frc, plant.load,
                          plant.damping, plant.influence, plant.base_dofs, run.is_open, run.impact_impulse, run.running)
            _track_peaks(flow, run.is_open, run.impact_peak, run.impact_peak_time, t_stop, run.x, x_stop, work)
        if guard < 0:
            run.x[:] = x1
            continue
        run.clock[0] = t_event
        run.pending_x[:] = x_stop
        run.pending_mode[:] = tables.modes[m]
        run.ints[FIRED_KIND], run.ints[FIRED_TARGET], run.ints[FIRED_DIRECTION] = tables.kind[m, guard], tables.target[m, guard], tables.direction[m, guard]
        run.ints[PENDING] = EVENT
        run.ints[TOTAL] += 1
        return True
    return False


@njit(cache=True, inline="always")
def _any(flags):
    for flag in flags:
        if flag:
            return True
    return False


@njit(cache=True)
def _chebyshev_state(chebyshev, z, coefficients):
    """Chebyshev coefficients (D × 2N) of x(t0 + τ) from z(t0)."""
    for n in range(chebyshev.shape[0]):
        _matvec(chebyshev[n], z, coefficients[n])


@njit(cache=True, nogil=True)
def run_engine(tables, plant, run, scratch, saved):
    """Run (or resume) the simulation; returns FINISHED, NEED_MODE or NEED_SPACE.

    On NEED_MODE, ``run.missing_mode`` is the mode to build; on NEED_SPACE the
    impact table is full. Either way the caller fixes it and calls again.
    ``scratch`` and ``saved`` are work arrays (:func:`exact_kernel.work_arrays`).
    """
    eps = 2.0 * np.finfo(np.float64).eps
    times = plant.times
    transitions = np.empty((_MAX_SETTLE + 1, 3), dtype=np.int64)
    while True:
        if run.ints[PENDING] != NONE:  # settle and record the pending event (Run._event)
            if run.ints[N_IMPACTS] + plant.gap.shape[0] > run.impacts.shape[0]:
                return NEED_SPACE
            m, x, n_transitions = _settle(tables, plant, run, transitions)
            if m < 0:
                return NEED_MODE
            _on_transitions(tables, plant, run, m, run.clock[0], x, transitions, n_transitions)
            run.x[:] = x
            run.ints[MODE] = m
            run.visited[tables.ids[m]] = True
            if run.ints[PENDING] == INITIAL:
                run.states[0], run.energy[:, 0], run.sample_modes[0] = run.x, run.running, tables.ids[m]
            run.ints[PENDING] = NONE
        k = run.ints[K]
        if k < times.shape[0] - 1 and run.clock[0] == times[k]:  # the fast path over quiet intervals
            m = run.ints[MODE]
            n = tables.n_guards[m]
            k, _ = advance_quiet(
                k, run.x, plant.forcing, times, tables.substeps[m], tables.transition[m], tables.nodes[m],
                0.5 * tables.step[m] * plant.gauss_weights, tables.A[m], tables.B[m], tables.c[m],
                tables.G[m, :n], tables.gh[m, :n], tables.g0[m, :n],
                run.threshold[:n], run.tolerance[:n], run.rearmable[:n], run.disarmed[:n],
                tables.F[m], tables.f0[m], tables.Fr[m], tables.frg[m], tables.frc[m],
                plant.load, plant.damping, plant.influence, plant.base_dofs,
                run.is_open, run.impact_impulse, run.impact_peak, run.impact_peak_time, run.running,
                run.states, run.energy, scratch, saved,
            )
            run.sample_modes[run.ints[K] + 1 : k + 1] = tables.ids[m]
            run.ints[K] = k
            run.clock[0] = times[k]
        if k >= times.shape[0] - 1:
            return FINISHED
        t, t_end = run.clock[0], times[k + 1]
        stopped = False
        while t_end - t > eps * max(1.0, abs(t_end)):
            if _advance_span(tables, plant, run, k, t, t_end):
                stopped = True
                break
            t = t_end
        if stopped:
            continue
        run.clock[0] = t_end
        run.ints[K] = k + 1
        run.states[k + 1], run.energy[:, k + 1], run.sample_modes[k + 1] = run.x, run.running, tables.ids[run.ints[MODE]]
