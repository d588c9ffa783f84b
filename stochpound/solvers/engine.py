"""The event engine: the one implementation of the discrete event logic (numba).

Every solver runs through this module (:mod:`stochpound.solvers.driver`):
``method="exact"`` lets it advance each mode with exact propagators,
``method="ivp"`` supplies an integrator's steps as Chebyshev expansions of
its dense output. Either way the engine alone

* screens and locates guard crossings (:func:`_may_cross`, the cubic
  Hermite screen; :func:`_first_crossing`, with a Brent root finder and a
  bounded Brent minimiser for grazing guards and dips, :func:`_brentq`,
  :func:`_bounded_brent`);
* settles an instant (:func:`_settle_pending`: which guard fires first, mode
  transitions, re-arming);
* records the run: energy terms by 5-point Gauss–Legendre quadrature,
  impulses, located peak forces and monitored peaks, the impact table.

Most sample intervals have no event: :func:`_advance_quiet` advances them
sub-step by sub-step, screening every sub-step exactly as
:func:`_first_crossing` would, and stops (rolled back to the start of the
interval) at the first interval in which a guard is suspected to cross or an
impact force has an interior maximum; :func:`_advance_span` then takes the
interval event by event. With ``NUMBA_DISABLE_JIT=1`` the same functions run
as plain Python (the debugging path, tested).

Data. Modes are int64 vectors [closed flags of every contact, state of every
slider: the bases, then the yielding storeys' plastic elements]. Every
linear read-out of a mode is an *affine map*, an array whose
row i gives ``row[:S] · x + row[S] a_g + row[S + 1]`` (S = 2N): ``rate``
(ẋ = A x + B a_g + c), ``guard`` (G x + h a_g + g0) and ``force`` (contact
forces, no a_g term). The powers of
the energy balance are quadratic forms of the augmented state z = [x, w, 1]
(``tables._power_forms``), and their 5-point Gauss–Legendre integrals over a
whole sub-step are quadratic forms of z(t0) (``tables._sub_step_forms``).
The arrays are grouped in small named tuples: :class:`ModeTable`,
:class:`Dynamics` and :class:`Propagators` (one row per slot of modes),
:class:`Motion` and :class:`Layout` (the plant), :class:`Run`,
:class:`Arming`, :class:`Impacts` and :class:`Outputs` (everything a run
changes, so that a call can stop for a missing mode and resume).

Compile time (``cache=True``: once per machine). numba type-infers and lowers
every jitted function on its own, optimises it again inside each caller
(into which it is linked as LLVM IR), spends about as much
on each source line as on each optimised LLVM line, copies every field of a
named tuple wherever one is bound or passed, and inlines (``inline="always"``)
at a high cost per call site. So :func:`run_engine` is the only entry point:
it unpacks the named tuples once and calls its phases
(:func:`_settle_pending`, :func:`_advance_quiet`, :func:`_advance_span`,
:func:`_supplied_step`), which take arrays; the phases and the helpers are
compiled once without Python wrappers (:data:`INTERNAL`), and none is inlined
by numba: LLVM inlines the small helpers and keeps each phase a function of
its own, which compiles in a fifth less time than the phases inlined into
:func:`run_engine` (its one huge function then took most of LLVM's time), with
the same results, bit for bit (docs/benchmarks.md, "Start-up"). A call LLVM
keeps passes every array as its fields (a flow's arrays are a hundred words on
the stack), so the quiet loop builds a flow and passes it only on a sub-step
where a monitor may peak (:func:`_offer_end_monitors`): passing it on every
sub-step made the phases compiled on their own 1.1 to 1.2 times slower than
inlined (docs/benchmarks.md, "Against an earlier revision"); no
compile-time constant is passed to a helper (it would compile a second
specialisation), and no array is assigned to an array slice (its error
message alone compiles string formatting). Reference counting would make up
half of the unoptimised IR (every incref or decref of an array extracts all
its fields), so everything is compiled without numba's runtime
(``_nrt=False``, numba's private option, given only where numba offers it:
:data:`~stochpound.solvers.compiling.NO_RUNTIME`): the engine allocates nothing (every work vector is a row of
the arrays of :func:`work_arrays`), and it calls no builtin ``min`` or
``max`` (each compiles an overload; the comparisons written out give the same
results). :func:`stochpound.solvers.first_call.run` compiles it inside
:func:`~stochpound.solvers.compiling.engine_compile`: its own LLVM level, and no
machine code for the helpers of their own (they are optimised and turned
into machine code once, inside :func:`run_engine`). All jitted code lives in
this one module, whose source stamp is what invalidates numba's cache (the
compile settings change no result, so they need not).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit

from stochpound._jit import cached_njit
from stochpound.model.friction import STUCK
from stochpound.model.guards import Guard
from stochpound.solvers.compiling import NO_RUNTIME
from stochpound.solvers.propagators import GAUSS_NODES, GAUSS_WEIGHTS

ROUND_OFF = 1e-10
"""Relative size under which a guard value or derivative counts as zero."""
FIRE_THRESHOLD = 1e-7
"""Relative level at which a disarmed guard fires anyway (progress guarantee)."""
TIME_TOLERANCE = 1e-13
"""Absolute tolerance of event times, s."""
MAX_SETTLE_ITERATIONS = 64
"""Most mode transitions applied at one instant before settling declares a cycle (chattering)."""

INTERNAL = {"no_cpython_wrapper": True, "no_cfunc_wrapper": True, "error_model": "numpy", **NO_RUNTIME}
"""Options of the jitted helpers, called only from compiled code (no runtime: they allocate nothing)."""

ModeTable = namedtuple("ModeTable", "modes ids codes n_guards substeps")
ModeTable.__doc__ = """The modes in the table's slots: mode vector (invalid in an empty slot), the mode's id (kept
when it changes slot, recorded per sample), guard codes (rows KIND, TARGET, DIRECTION; padded), number of guards
and of sub-steps per sample interval."""
Dynamics = namedtuple("Dynamics", "rate guard force monitor power")
Dynamics.__doc__ = """The slots' modes' affine maps of ẋ, the guards (padded), the contact forces and the monitors, and their power forms.

A *monitor* is a read-out whose largest value over the run is located on
the solution (e.g. a contact's closure, whose peak is the separation the run
needed). ``power[m]`` stacks the quadratic forms P of the input, damping,
friction and impact powers, zᵀ P z at z = [x, a_g, 0, 0, 0, 1], transposed
(Z × 4Z) (``tables._power_forms``).
"""
Propagators = namedtuple("Propagators", "propagate chebyshev step")
Propagators.__doc__ = """Exact sub-step propagators of the slots' modes.

``propagate[m]`` is [exp(𝒜h); Q_input; Q_damping; Q_friction; Q_impact; R;
V; W; V_m; W_m] transposed (Z × (5Z + n_contacts + 2 n_guards + 2 n_monitors),
guards padded, then zero columns up to :func:`propagate_columns`): one
product of z(t0) gives z(t0 + h), Q z(t0) of every energy term (whose gain
over the sub-step is z(t0) · Q z(t0)), the impulses R z(t0)
(``tables._sub_step_forms``), and the guards' and monitors' values V z(t0)
and rates W z(t0) at t0 + h (``tables._read_out_rows``). ``chebyshev[m]`` is the
Chebyshev expansion of the flow on a sub-step of length ``step[m]``,
transposed (Z × D·2N).
"""
Motion = namedtuple("Motion", "times forcing coefficients harmonic")
Motion.__doc__ = """Output times, exosystem state per interval, cubic per interval (sampled) or [A, ω, φ] (harmonic)."""
Layout = namedtuple("Layout", "geometry gap tensile left_rows right_rows base_dofs")
Layout.__doc__ = """Impact elements (penetration rows, gaps, tensile flags, displacement rows of their left and right sides) and the sliders' DOFs.

``base_dofs`` (2 × sliders: the sliding bases, then the yielding storeys): a
STOP sets the velocity of DOF ``base_dofs[0, i]`` to that of DOF
``base_dofs[1, i]`` (0 when it is −1): a base's sliding velocity, a storey's
drift rate end exactly at 0."""
Run = namedtuple("Run", "clock ints x pending_x pending_mode missing_mode visited")
Run.__doc__ = """Time, counters (``ints``; ``ints[MODE]`` is a slot), state, the pending event and the ids of the modes visited."""
Arming = namedtuple("Arming", "threshold tolerance rearmable disarmed")
Arming.__doc__ = """Arming of the current mode's guards.

``threshold[j]`` is 0 for an armed guard (it fires at 0), a small positive
level for a disarmed one (it fires there, or at 0 once it has gone below
−``tolerance[j]``) and +inf for a guard that may not fire for now;
``rearmable[j]`` is False for a guard that stays off until the next mode
change (the RECLOSE guard of a contact that is not penetrated).
"""
Impacts = namedtuple("Impacts", "is_open impact table")
Impacts.__doc__ = """Open impacts (``impact[row, contact]``, rows START … IMPULSE) and the table of finished ones."""
Outputs = namedtuple("Outputs", "running states energy sample_modes peaks")
Outputs.__doc__ = """Running energy terms, the state, energy terms and mode id at every output time, and the monitors' peaks (rows PEAK_VALUE, PEAK_AT)."""
Supplied = namedtuple("Supplied", "bounds x coefficients")
Supplied.__doc__ = """A step of the flow supplied by the caller (``external`` runs: an integrator's step).

``bounds`` = [t0, t1] (s), ``x`` the state ξ = [x, f] at t1 (f: the mode's
read-outs, the forces of nonlinear laws) and ``coefficients`` the Chebyshev
coefficients of ξ(t) on [t0, t1], (D + 1) × S' flattened by order (the dense
output of :class:`Flow`). The step starts at the engine's own ξ.
"""
Readouts = namedtuple("Readouts", "slots values x")
Readouts.__doc__ = """The read-outs f of the modes met while settling one event (systems with nonlinear laws only).

Row r holds slot ``slots[r]``'s f and ḟ (``values[r]``, 2 × n_f) at the
settling instant; ``ints[N_READOUTS]`` rows are filled. When a mode's row is
missing the engine returns NEED_READOUTS with the mode's slot in
``ints[READOUT_SLOT]`` and the state in ``x``; the caller appends the row.
"""
Flow = namedtuple("Flow", "rate guard force monitor coefficients ground origin harmonic t0 scale")
Flow.__doc__ = """One mode's flow inside one step: its affine maps and the Chebyshev coefficients of ξ(t) = [x(t), f(t)].

An exact flow has no read-outs (ξ = x); a supplied flow has those of the
mode's nonlinear laws (:func:`_flow_rate`).

``ground`` is the interval's cubic of a_g(t − origin) (sampled motions) or
[amplitude, ω, phase] (``harmonic``); the step starts at t0 and
``scale`` = 2 / h maps it onto [−1, 1].
"""

# entries of Run.ints
K, MODE, PENDING, FIRED_KIND, FIRED_TARGET, FIRED_DIRECTION, N_IMPACTS, TOTAL, CHATTER, GRAZING, READY, N_READOUTS, READOUT_SLOT = range(13)
N_INTS = 13
# rows of ModeTable.codes
KIND, TARGET, DIRECTION = range(3)
# rows of Impacts.impact
START, ONSET, IN_PHASE, PEAK, PEAK_TIME, IMPULSE = range(6)
# rows of Outputs.peaks
PEAK_VALUE, PEAK_AT = range(2)
# pending settles
NONE, INITIAL, EVENT = 0, 1, 2
# statuses returned to Python
FINISHED, NEED_MODE, NEED_SPACE, NEED_STEP, NEED_READOUTS = 0, 1, 2, 3, 4
# columns of Impacts.table (finished impacts): contact, end, then the rows of Impacts.impact
IMPACT_COLUMNS = ("contact", "end", "start", "onset_velocity", "in_phase", "peak_force", "peak_time", "impulse")
N_NODES = 5
"""Gauss–Legendre nodes of the energy quadrature."""

_CLOSE, _RECLOSE, _OPEN, _SLIP, _STOP = int(Guard.CLOSE), int(Guard.RECLOSE), int(Guard.OPEN), int(Guard.SLIP), int(Guard.STOP)
_STUCK = STUCK
_ROUND_OFF, _FIRE_RATIO, _XTOL, _MAX_SETTLE = ROUND_OFF, FIRE_THRESHOLD / ROUND_OFF, TIME_TOLERANCE, MAX_SETTLE_ITERATIONS
_RTOL = 4 * np.finfo(float).eps
_EPS = 2 * np.finfo(float).eps


LANES = 16
"""The columns of ``Propagators.propagate`` are padded to a multiple of this, so that its products vectorise whole."""


def propagate_columns(size: int, n_guards: int, n_contacts: int, n_monitors: int) -> int:
    """Columns of ``Propagators.propagate`` (padded to :data:`LANES`) for state size ``size`` (2N)."""
    used = 5 * (size + 5) + n_contacts + 2 * n_guards + 2 * n_monitors
    return -(-used // LANES) * LANES


def work_arrays(size: int, n_guards: int, n_contacts: int, n_monitors: int, mode_size: int,
                chebyshev_width: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``scratch``, ``saved`` and ``marks`` work arrays of :func:`run_engine`.

    For state size ``size`` (2N), mode vectors of ``mode_size`` and Chebyshev
    rows of ``chebyshev_width`` (``Propagators.chebyshev.shape[2]``). The
    engine allocates nothing: every work vector is a row of these.
    ``scratch`` rows: 0–6 and 9 the quiet loop's (:func:`_advance_quiet`),
    0–15 an event step's (:func:`_advance_span`, :func:`_first_crossing`),
    16–23 settling's, 24–27 the monitors' values and rates at a step's ends.
    ``marks`` rows: the settling chain's modes, its transitions, then the
    guard headings and two mode vectors.
    """
    scratch = np.zeros((28, max(propagate_columns(size, n_guards, n_contacts, n_monitors), chebyshev_width)))
    marks = np.zeros((2 * (_MAX_SETTLE + 1) + 3, max(mode_size, 3, n_guards)), dtype=np.int64)
    return scratch, np.zeros((8, max(4, n_contacts, n_guards, n_monitors))), marks


# ---------------------------------------------------------------- linear algebra and read-outs


@njit(**INTERNAL)
def _copy(source, target):
    """target[i] = source[i] for every i of target."""
    for i in range(target.shape[0]):
        target[i] = source[i]


@njit(**INTERNAL)
def _product(transposed, vector, out):
    """out = Mᵀ vector for M = ``transposed``: a column at a time (vectorised; the sums of row dot products).

    Zero entries of ``vector`` are skipped (they add nothing to a finite M):
    the ground's higher coefficients under linear interpolation, a stuck base.
    """
    for i in range(out.shape[0]):
        out[i] = 0.0
    for j in range(vector.shape[0]):
        value = vector[j]
        if value == 0.0:
            continue
        for i in range(out.shape[0]):
            out[i] += transposed[j, i] * value


@njit(**INTERNAL)
def _affine(M, i, xi, ground):
    """Row i of the affine map M at (ξ, a_g): M[i, S'] a_g + M[i, S' + 1] + M[i, :S'] · ξ (ξ = [x, f], S' = M.shape[1] − 2)."""
    size = M.shape[1] - 2
    total = M[i, size] * ground + M[i, size + 1]
    for j in range(size):
        total += M[i, j] * xi[j]
    return total


@njit(**INTERNAL)
def _rate_of(M, i, rate, x, ground, ground_rate):
    """Rate of row i of the affine map M along an exact flow (no read-outs): M[i, :S] · ẋ + M[i, S] ȧ_g."""
    total = M[i, rate.shape[0]] * ground_rate
    for j in range(rate.shape[0]):
        total += M[i, j] * _affine(rate, j, x, ground)
    return total


@njit(**INTERNAL)
def _read_outs(M, xi, xi_rate, ground, ground_rate, values, rates):
    """The first len(values) rows of the affine map M at (ξ, a_g) and their rates M ξ̇ + h ȧ_g."""
    size = M.shape[1] - 2
    for g in range(values.shape[0]):
        value = M[g, size] * ground + M[g, size + 1]
        slope = M[g, size] * ground_rate
        for j in range(size):
            value += M[g, j] * xi[j]
            slope += M[g, j] * xi_rate[j]
        values[g] = value
        rates[g] = slope


@njit(**INTERNAL)
def _guards_and_rates(rate, guard, monitor, x, ground, ground_rate, values, rates, monitor_values, monitor_rates, work):
    """The first len(values) guards and len(monitor_values) monitors and their rates at (x, a_g) on an exact flow (ẋ, computed once, into ``work``)."""
    for i in range(rate.shape[0]):
        work[i] = _affine(rate, i, x, ground)
    _read_outs(guard, x, work, ground, ground_rate, values, rates)
    _read_outs(monitor, x, work, ground, ground_rate, monitor_values, monitor_rates)


@njit(**INTERNAL)
def _add_forms(z, products, weight, running):
    """running[term] += weight × zᵀ Pₜ z for the four power forms, from products = [P₀ z, P₁ z, P₂ z, P₃ z]."""
    width = z.shape[0]
    for term in range(running.shape[0]):
        value = 0.0
        for j in range(width):
            value += z[j] * products[term * width + j]
        running[term] += weight * value


@njit(**INTERNAL)
def _sub_step_energy(z0, propagated, is_open, impulse, running):
    """Add a full sub-step's energy terms and impulses from ``propagated`` = ``propagate[m]`` z(t0) (see :class:`Propagators`).

    The energy gains are z(t0) · Q z(t0), as :func:`_add_forms` (written out: this is the quiet loop's hot path).
    """
    width = z0.shape[0]
    for term in range(running.shape[0]):
        start = (term + 1) * width
        gain = 0.0
        for j in range(width):
            gain += z0[j] * propagated[start + j]
        running[term] += gain
    for p in range(is_open.shape[0]):
        if is_open[p]:
            impulse[p] += propagated[5 * width + p]


@njit(**INTERNAL)
def _any(flags):
    """True if some flag is set."""
    for flag in flags:
        if flag:
            return True
    return False


@njit(**INTERNAL)
def _offer_peaks(force, is_open, impact, t, x):
    """Offer the contact forces at (t, x) as peaks of the open impacts."""
    for p in range(is_open.shape[0]):
        if is_open[p]:
            value = _affine(force, p, x, 0.0)
            if value > impact[PEAK, p]:
                impact[PEAK, p], impact[PEAK_TIME, p] = value, t


@njit(**INTERNAL)
def _record_sample(x, running, mode_id, states, energy, sample_modes, k):
    """Store the state, the energy terms and the mode's id at output time k."""
    _copy(x, states[k])
    for term in range(running.shape[0]):
        energy[term, k] = running[term]
    sample_modes[k] = mode_id


# ---------------------------------------------------------------- guard screen


@njit(**INTERNAL)
def _interior_maximum(a0, a1, a2, a3):
    """Largest value of the cubic a0 + a1 τ + a2 τ² + a3 τ³ at its critical points inside (0, 1), −inf if none."""
    best = -math.inf
    if a3 != 0.0:
        discriminant = 4.0 * a2 * a2 - 12.0 * a3 * a1
        if discriminant >= 0.0:
            root = math.sqrt(discriminant)
            tau = (-2.0 * a2 + root) / (6.0 * a3)
            value = a0 + tau * (a1 + tau * (a2 + tau * a3))
            if 0.0 < tau < 1.0 and value > best:
                best = value
            tau = (-2.0 * a2 - root) / (6.0 * a3)
            value = a0 + tau * (a1 + tau * (a2 + tau * a3))
            if 0.0 < tau < 1.0 and value > best:
                best = value
    elif a2 != 0.0:
        tau = -a1 / (2.0 * a2)
        value = a0 + tau * (a1 + tau * (a2 + tau * a3))
        if 0.0 < tau < 1.0 and value > best:
            best = value
    return best


@njit(**INTERNAL)
def _hermite(value0, value1, rate0, rate1, h):
    """Coefficients (a0, a1, a2, a3) in τ ∈ [0, 1] of the cubic Hermite interpolant of a guard over a step of h seconds."""
    return value0, rate0 * h, 3.0 * (value1 - value0) - (2.0 * rate0 + rate1) * h, 2.0 * (value0 - value1) + (rate0 + rate1) * h


@njit(**INTERNAL)
def _screen_margin(value0, value1, rate0, rate1, h, tolerance):
    """How close below zero a guard's Hermite cubic may come before the guard is examined on the flow itself."""
    return 1e-3 * (abs(value0) + abs(value1) + abs(rate0 * h) + abs(rate1 * h)) + tolerance


@njit(**INTERNAL)
def _may_cross(value0, value1, rate0, rate1, h, tolerance):
    """The guard screen: True when a guard ends the step at or above zero, or its Hermite cubic peaks within the margin of zero."""
    if value1 >= 0.0:
        return True
    a0, a1, a2, a3 = _hermite(value0, value1, rate0, rate1, h)
    return _interior_maximum(a0, a1, a2, a3) >= -_screen_margin(value0, value1, rate0, rate1, h, tolerance)


@njit(**INTERNAL)
def _suspect(values0, values1, rates0, rates1, h, threshold, tolerance):
    """True when some guard that may fire passes the screen (:func:`_may_cross`) over this step."""
    for g in range(values0.shape[0]):
        if abs(threshold[g]) < math.inf and _may_cross(values0[g], values1[g], rates0[g], rates1[g], h, tolerance[g]):
            return True
    return False


@njit(**INTERNAL)
def _arm_where_negative(values, threshold, tolerance, rearmable, disarmed):
    """``GuardStates.arm_where_negative``: arm the disarmed guards that went below −tolerance."""
    for g in range(values.shape[0]):
        if disarmed[g] and rearmable[g] and values[g] < -tolerance[g]:
            threshold[g] = 0.0
            disarmed[g] = False


@njit(**INTERNAL)
def _peaks(rate, force, is_open, impact, x0, a0, t0, x1, a1, t1):
    """Offer the end-point forces as peaks; True if some open impact has a force maximum inside."""
    _offer_peaks(force, is_open, impact, t0, x0)
    _offer_peaks(force, is_open, impact, t1, x1)
    for p in range(is_open.shape[0]):
        if is_open[p] and _rate_of(force, p, rate, x0, a0, 0.0) > 0.0 > _rate_of(force, p, rate, x1, a1, 0.0):
            return True
    return False


# ---------------------------------------------------------------- the quiet loop


@njit(**INTERNAL)
def _save(saved, running, impact, threshold, disarmed, peaks):
    """Copy the running totals, the open impacts' peaks and impulses, the guard arming and the monitors' peaks into the rows of ``saved``."""
    for i in range(running.shape[0]):
        saved[0, i] = running[i]
    for p in range(impact.shape[1]):
        saved[1, p], saved[2, p], saved[3, p] = impact[PEAK, p], impact[PEAK_TIME, p], impact[IMPULSE, p]
    for g in range(threshold.shape[0]):
        saved[4, g], saved[5, g] = threshold[g], 1.0 if disarmed[g] else 0.0
    for i in range(peaks.shape[1]):
        saved[6, i], saved[7, i] = peaks[PEAK_VALUE, i], peaks[PEAK_AT, i]


@njit(**INTERNAL)
def _restore(saved, running, impact, threshold, disarmed, peaks):
    """Undo everything since :func:`_save`."""
    for i in range(running.shape[0]):
        running[i] = saved[0, i]
    for p in range(impact.shape[1]):
        impact[PEAK, p], impact[PEAK_TIME, p], impact[IMPULSE, p] = saved[1, p], saved[2, p], saved[3, p]
    for g in range(threshold.shape[0]):
        threshold[g], disarmed[g] = saved[4, g], saved[5, g] != 0.0
    for i in range(peaks.shape[1]):
        peaks[PEAK_VALUE, i], peaks[PEAK_AT, i] = saved[6, i], saved[7, i]


# ---------------------------------------------------------------- monitors


@njit(**INTERNAL)
def _offer_monitors(values, t, peaks):
    """Offer the monitors' ``values`` at time t as their peaks."""
    for i in range(values.shape[0]):
        if values[i] > peaks[PEAK_VALUE, i]:
            peaks[PEAK_VALUE, i], peaks[PEAK_AT, i] = values[i], t


@njit(**INTERNAL)
def _maximum_may_beat(value0, value1, rate0, rate1, h, peak):
    """True when a monitor has a maximum inside a step of h seconds (rate from + to −) whose Hermite cubic comes near its ``peak``."""
    if not rate0 > 0.0 > rate1:
        return False
    a0, a1, a2, a3 = _hermite(value0, value1, rate0, rate1, h)
    return _interior_maximum(a0, a1, a2, a3) >= peak - _screen_margin(value0, value1, rate0, rate1, h, 0.0)


@njit(**INTERNAL)
def _any_maximum_may_beat(values0, values1, rates0, rates1, h, peaks):
    """True when some monitor's maximum inside the step may beat its peak (:func:`_maximum_may_beat`)."""
    for i in range(values0.shape[0]):
        if _maximum_may_beat(values0[i], values1[i], rates0[i], rates1[i], h, peaks[PEAK_VALUE, i]):
            return True
    return False


@njit(**INTERNAL)
def _offer_end_monitors(values0, values1, rates0, rates1, h, t1, peaks):
    """Offer the monitors' values at the end t1 of a step of h seconds as their peaks; True instead when a maximum inside may beat one.

    On True nothing is offered: the caller locates the peaks on the flow
    (:func:`_sub_step_monitors`). Most sub-steps have no such maximum, and
    this test takes no flow: the quiet loop builds one, and passes its
    arrays to a call, only for the few that do.
    """
    if _any_maximum_may_beat(values0, values1, rates0, rates1, h, peaks):
        return True
    _offer_monitors(values1, t1, peaks)
    return False


@njit(**INTERNAL)
def _sub_step_monitors(flow, chebyshev, z0, t1, values0, values1, rates0, rates1, peaks, work):
    """The monitors' peaks over an exact sub-step [flow.t0, t1] from z0, located on the flow (:func:`_monitor_peaks`).

    Called when :func:`_offer_end_monitors` says a maximum inside may beat a
    peak: the sub-step's Chebyshev coefficients (``chebyshev`` z0, into
    ``flow.coefficients``) are computed only then.
    """
    _product(chebyshev, z0, flow.coefficients)
    _monitor_peaks(flow, t1, values0, values1, rates0, rates1, peaks, work)


@njit(**INTERNAL)
def _monitor_peaks(flow, t1, values0, values1, rates0, rates1, peaks, work):
    """Offer the monitors' values at t1 and their maxima inside [flow.t0, t1], located on the flow, as their peaks.

    ``values*``/``rates*``: the monitors' values and rates at the step's ends.
    A maximum is located (Brent on the monitor's rate) when the rate goes from
    + to − on the flow and the Hermite cubic says it may beat the peak.
    """
    t0, n_contacts, xi = flow.t0, flow.force.shape[0], work[: flow.rate.shape[1] - 2]
    for i in range(values1.shape[0]):
        if _maximum_may_beat(values0[i], values1[i], rates0[i], rates1[i], t1 - t0, peaks[PEAK_VALUE, i]):
            index = -1 - n_contacts - i
            if _evaluate(flow, index, 0.0, t0, work) > 0.0 > _evaluate(flow, index, 0.0, t1, work):
                t_peak = _brentq(flow, index, 0.0, t0, t1, work)
                _dense(flow, t_peak, xi)
                value = _affine(flow.monitor, i, xi, _ground_value(flow, t_peak))
                if value > peaks[PEAK_VALUE, i]:
                    peaks[PEAK_VALUE, i], peaks[PEAK_AT, i] = value, t_peak
    _offer_monitors(values1, t1, peaks)


@njit(**INTERNAL)
def _advance_quiet(mode_id, n, substeps, step, propagate, chebyshev, rate, guard, force, monitor, motion, ints, clock, x, arming, is_open,
                   impact, outputs, scratch, saved):
    """Advance the current mode (its id, n guards and arrays) from interval ``ints[K]`` until an interval needs the event code.

    Does for every sub-step what the event code does for a step without event:
    the guard screen of ``first_crossing`` and the re-arming of guards, the
    energy terms, impulses and end-point peak forces of ``Recorder.on_step``,
    and the monitors' peaks (located on the flow when a maximum inside a
    sub-step may beat one). Every completed interval k is recorded at output
    time k + 1; ``ints[K]``, ``clock`` and ``x`` are left at the start of the
    interval where the loop stopped (or at the end of the motion).
    """
    threshold, tolerance, rearmable, disarmed = arming
    running, states, energy, sample_modes, peaks = outputs
    times, forcing, harmonic = motion.times, motion.forcing, motion.harmonic
    is_harmonic = harmonic.shape[0] > 0
    size = x.shape[0]
    width = size + 5
    z0, propagated, work, coefficients = scratch[0, :width], scratch[1, : propagate.shape[1]], scratch[2], scratch[9, : chebyshev.shape[1]]
    z1, x0, x1 = propagated[:width], z0[:size], propagated[:size]
    values_at = 5 * width + is_open.shape[0]
    rates_at, monitors_at = values_at + guard.shape[0], values_at + 2 * guard.shape[0]
    n_monitors = monitor.shape[0]
    values0, values1, rates0, rates1 = scratch[3, :n], propagated[values_at : values_at + n], scratch[5, :n], propagated[rates_at : rates_at + n]
    monitors0, monitors1 = scratch[24, :n_monitors], propagated[monitors_at : monitors_at + n_monitors]
    monitor_rates0, monitor_rates1 = scratch[26, :n_monitors], propagated[monitors_at + n_monitors : monitors_at + 2 * n_monitors]
    any_open = _any(is_open)
    for k in range(ints[K], forcing.shape[0]):
        h = (times[k + 1] - times[k]) / substeps
        _save(saved, running, impact, threshold, disarmed, peaks)
        _copy(x, x0)
        _copy(forcing[k], z0[size : size + 4])
        z0[width - 1] = 1.0
        _guards_and_rates(rate, guard, monitor, x0, z0[size], z0[size + 1], values0, rates0, monitors0, monitor_rates0, work)
        for j in range(substeps):
            _product(propagate, z0, propagated)
            t0 = times[k] + j * h
            t1 = times[k + 1] if j == substeps - 1 else t0 + h
            if _suspect(values0, values1, rates0, rates1, h, threshold, tolerance) or (
                any_open and _peaks(rate, force, is_open, impact, x0, z0[size], t0, x1, z1[size], t1)
            ):
                _restore(saved, running, impact, threshold, disarmed, peaks)
                ints[K] = k
                clock[0] = times[k]
                return
            _sub_step_energy(z0, propagated, is_open, impact[IMPULSE], running)
            _arm_where_negative(values1, threshold, tolerance, rearmable, disarmed)
            if _offer_end_monitors(monitors0, monitors1, monitor_rates0, monitor_rates1, t1 - t0, t1, peaks):
                flow = Flow(rate, guard, force, monitor, coefficients, harmonic if is_harmonic else motion.coefficients[k], times[k], is_harmonic, t0, 2.0 / step)
                _sub_step_monitors(flow, chebyshev, z0, t1, monitors0, monitors1, monitor_rates0, monitor_rates1, peaks, work)
            _copy(values1, values0)
            _copy(rates1, rates0)
            _copy(monitors1, monitors0)
            _copy(monitor_rates1, monitor_rates0)
            _copy(z1, z0)
        _copy(x0, x)
        ints[K] = k + 1
        _record_sample(x, running, mode_id, states, energy, sample_modes, k + 1)
    clock[0] = times[ints[K]]


# ---------------------------------------------------------------- ground and dense state


@njit(**INTERNAL)
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
        out[0] = a * math.sin(angle)
        out[1] = a * w * math.cos(angle)
        out[2] = -a * w * w * math.sin(angle)
        out[3] = -a * w * w * w * math.cos(angle)


@njit(**INTERNAL)
def _ground_value(flow, t):
    """a_g at t in the flow's interval (as ``GroundMotion.acceleration``)."""
    c = flow.ground
    if flow.harmonic:
        return c[0] * math.sin(c[1] * t + c[2])
    tau = t - flow.origin
    return c[0] + tau * (c[1] + tau * (c[2] + tau * c[3]))


@njit(**INTERNAL)
def _dense_derivative(flow, t, out):
    """dξ/dt from the step's Chebyshev coefficients: Σ cₙ n Uₙ₋₁(s) ds/dt (Uₙ₊₁ = 2s Uₙ − Uₙ₋₁)."""
    s = (t - flow.t0) * flow.scale - 1.0
    s = -1.0 if s < -1.0 else (1.0 if s > 1.0 else s)
    size = out.shape[0]
    coefficients = flow.coefficients
    for i in range(size):
        out[i] = 0.0
    previous, current = 0.0, 1.0  # U₋₁, U₀
    for n in range(1, coefficients.shape[0] // size):
        for i in range(size):
            out[i] += n * current * coefficients[n * size + i] * flow.scale
        previous, current = current, 2.0 * s * current - previous


@njit(**INTERNAL)
def _flow_rate(flow, t, xi, ground, out):
    """ξ̇ at t on the flow, given ξ(t) and a_g(t) (``out``: S' entries).

    ẋ is the rate map's at ξ (exact, read-outs included); the read-outs'
    rates ḟ (nonlinear laws, supplied flows only) are the derivative of the
    flow's expansion.
    """
    rows = flow.rate.shape[0]
    if out.shape[0] > rows:
        _dense_derivative(flow, t, out)
    for j in range(rows):
        out[j] = _affine(flow.rate, j, xi, ground)


@njit(**INTERNAL)
def _flow_read_outs(flow, t, xi, values, rates, monitor_values, monitor_rates, work):
    """The first len(values) guards and len(monitor_values) monitors and their rates at t on the flow, ξ(t) given (ξ̇, computed once, into ``work``)."""
    ground, ground_rate = _ground_value(flow, t), _ground_rate(flow, t)
    _flow_rate(flow, t, xi, ground, work[: xi.shape[0]])
    _read_outs(flow.guard, xi, work, ground, ground_rate, values, rates)
    _read_outs(flow.monitor, xi, work, ground, ground_rate, monitor_values, monitor_rates)


@njit(**INTERNAL)
def _dense(flow, t, out):
    """x(t) from the step's Chebyshev coefficients (``ModePropagator.dense``; Tₙ by the recurrence Tₙ₊₁ = 2s Tₙ − Tₙ₋₁)."""
    s = (t - flow.t0) * flow.scale - 1.0
    s = -1.0 if s < -1.0 else (1.0 if s > 1.0 else s)  # clipped to [−1, 1]
    size = out.shape[0]
    coefficients = flow.coefficients
    previous, current = 1.0, s
    for i in range(size):
        out[i] = coefficients[i]
    for n in range(1, coefficients.shape[0] // size):
        for i in range(size):
            out[i] += current * coefficients[n * size + i]
        previous, current = current, 2.0 * s * current - previous


@njit(**INTERNAL)
def _ground_rate(flow, t):
    """ȧ_g at t in the flow's interval."""
    c = flow.ground
    if flow.harmonic:
        return c[0] * c[1] * math.cos(c[1] * t + c[2])
    tau = t - flow.origin
    return c[1] + tau * (2.0 * c[2] + 3.0 * tau * c[3])


@njit(**INTERNAL)
def _evaluate(flow, index, level, t, work):
    """Guard ``index`` minus ``level`` at t; for index < 0, the rate of read-out r = −1 − index.

    Read-out r < n_elements is element force r, else monitor r − n_elements.
    ``work`` holds ξ(t) then ξ̇(t) (at least 2 S' entries).
    """
    size = flow.rate.shape[1] - 2
    xi, xi_rate = work[:size], work[size : 2 * size]
    _dense(flow, t, xi)
    ground = _ground_value(flow, t)
    if index >= 0:
        return _affine(flow.guard, index, xi, ground) - level
    _flow_rate(flow, t, xi, ground, xi_rate)
    r, n_elements = -1 - index, flow.force.shape[0]
    M, row = (flow.force, r) if r < n_elements else (flow.monitor, r - n_elements)
    total = M[row, size] * _ground_rate(flow, t)
    for j in range(size):
        total += M[row, j] * xi_rate[j]
    return total


# ---------------------------------------------------------------- scipy's brentq and bounded Brent, ported


@njit(**INTERNAL)
def _brentq(flow, index, level, xa, xb, work):
    """Root of _evaluate in [xa, xb] (scipy.optimize.brentq, xtol = TIME_TOLERANCE, rtol = 4 eps)."""
    xpre, xcur = xa, xb
    xblk, fblk, spre, scur = 0.0, 0.0, 0.0, 0.0
    fpre = _evaluate(flow, index, level, xpre, work)
    fcur = _evaluate(flow, index, level, xcur, work)
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
            limit = 3.0 * abs(sbis) - delta
            if 2.0 * abs(stry) < (limit if limit < abs(spre) else abs(spre)):  # min(abs(spre), limit)
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
        fcur = _evaluate(flow, index, level, xcur, work)
    return xcur


@njit(**INTERNAL)
def _bounded_brent(flow, j, level, a, b, sign, work):
    """(t, f(t)) minimising f = −sign (guard − level) on [a, b] (scipy's bounded Brent, xatol = 1e-12).

    ``sign`` = 1 maximises the guard (a grazing guard), −1 minimises it (:func:`_after_dip`).
    """
    xatol, sqrt_eps, golden_mean = 1e-12, math.sqrt(2.2e-16), 0.5 * (3.0 - math.sqrt(5.0))
    fulc = a + golden_mean * (b - a)
    nfc, xf = fulc, fulc
    rat = e = 0.0
    fx = -sign * _evaluate(flow, j, level, xf, work)
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
        x = xf + (1.0 if rat >= 0.0 else -1.0) * (tol1 if tol1 > abs(rat) else abs(rat))
        fu = -sign * _evaluate(flow, j, level, x, work)
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


@njit(**INTERNAL)
def _after_dip(flow, j, tolerance, start, crossing, work):
    """Where disarmed guard j, at its threshold at ``crossing``, fires after dipping below it.

    At its first zero after a dip below −``tolerance`` in [start, crossing],
    found by minimising the guard; at ``crossing`` if it did not dip.
    """
    t_min, value = _bounded_brent(flow, j, 0.0, start, crossing, -1.0, work)
    if value < -tolerance:
        return _brentq(flow, j, 0.0, t_min, crossing, work)
    return crossing


@njit(**INTERNAL)
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
        half = -0.5 * (qb + math.sqrt(discriminant)) if qb >= 0.0 else -0.5 * (qb - math.sqrt(discriminant))
        r1 = half / qa
        r2 = qc / half if half != 0.0 else r1
        low, high = (r2 if r2 < r1 else r1), (r2 if r2 > r1 else r1)
    else:
        low = high = -qb / (2.0 * qa)
        if math.sqrt(-discriminant) / (2.0 * abs(qa)) > 1e-12 * (abs(low) if abs(low) > 1.0 else 1.0):
            return 0
    if 0.0 < low < 1.0:
        out[count] = low
        count += 1
    if 0.0 < high < 1.0:
        out[count] = high
        count += 1
    return count


@njit(**INTERNAL)
def _first_crossing(flow, threshold, tolerance, rearmable, disarmed, counters, t1, values0, values1, rates0, rates1, work, taus, times,
                    raw):
    """(time, guard) of the earliest crossing in [t0, t1], or (NaN, −1).

    Every guard whose cubic Hermite interpolant may reach zero is located on
    the dense flow: the step is cut at the cubic's
    critical points; an armed guard fires at 0, a disarmed one at its
    threshold until it has dipped below −tolerance (at a cut point, or found
    by :func:`_after_dip`); a cubic maximum close to
    the level is checked by maximising the true guard (grazing).
    ``taus``, ``times`` and ``raw`` are work vectors (4 entries).
    """
    t0 = flow.t0
    h = t1 - t0
    best_time, best_guard = math.nan, -1
    for j in range(values0.shape[0]):
        # every guard is screened at 0: an armed guard fires there, and a disarmed one may, after a dip
        if not (abs(threshold[j]) < math.inf and _may_cross(values0[j], values1[j], rates0[j], rates1[j], h, tolerance[j])):
            continue
        a0, a1, a2, a3 = _hermite(values0[j], values1[j], rates0[j], rates1[j], h)
        margin = _screen_margin(values0[j], values1[j], rates0[j], rates1[j], h, tolerance[j])
        n = _critical_points(a1, a2, a3, taus[1:3]) + 2
        taus[0], taus[n - 1] = 0.0, 1.0
        raw[0] = a0
        for i in range(n):
            times[i] = t0 + taus[i] * h
            if i > 0:
                raw[i] = _evaluate(flow, j, 0.0, times[i], work)
        armed = not disarmed[j]
        level = 0.0 if armed else threshold[j]
        previous = (-tolerance[j] if -tolerance[j] < raw[0] else raw[0]) if armed else raw[0] - level
        time = math.nan
        for i in range(1, n):
            if not armed and raw[i] < -tolerance[j]:  # a dip: armed from here on, fires at 0
                armed, level, previous = True, 0.0, raw[i]
                continue
            current = raw[i] - level
            if previous < 0.0 <= current:
                # an armed guard within its tolerance above zero at the step's start (clamped to −tolerance above) crosses there
                start = times[i - 1]
                time = start if _evaluate(flow, j, level, start, work) >= 0.0 else _brentq(flow, j, level, start, times[i], work)
                break
            tau = taus[i]
            if 0 < i < n - 1 and current < 0.0 and a0 + tau * (a1 + tau * (a2 + tau * a3)) - level >= -margin:  # grazing
                counters[GRAZING] += 1
                start = times[i - 1]
                t_max, value = _bounded_brent(flow, j, level, start, times[i + 1], 1.0, work)  # i + 1 < n here
                if -value >= 0.0 and _evaluate(flow, j, level, start, work) < 0.0:
                    time = _brentq(flow, j, level, start, t_max, work)
                    break
            previous = current
        if time == time and not armed:
            time = _after_dip(flow, j, tolerance[j], t0, time, work)
        if time == time and (best_guard < 0 or time < best_time):
            best_time, best_guard = time, j
    if best_guard < 0:
        _arm_where_negative(values1, threshold, tolerance, rearmable, disarmed)
    return best_time, best_guard


# ---------------------------------------------------------------- settle


@njit(**INTERNAL)
def _lookup(modes, mode):
    """Index of the first row of ``modes`` equal to ``mode``, or −1."""
    for i in range(modes.shape[0]):
        j = 0
        while j < mode.shape[0] and modes[i, j] == mode[j]:
            j += 1
        if j == mode.shape[0]:
            return i
    return -1


@njit(**INTERNAL)
def _penetration(geometry, gap, p, x):
    value = -gap[p]
    for j in range(geometry.shape[1]):
        value += geometry[p, j] * x[j]
    return value


@njit(**INTERNAL)
def _apply(geometry, gap, base_dofs, mode, x, kind, target, direction):
    """Apply a transition to a mode vector (changed in place); a STOP zeroes the slider's velocity in x (a base's, a storey's drift rate)."""
    n_contacts = gap.shape[0]
    if kind == _CLOSE or (kind == _RECLOSE and _penetration(geometry, gap, target, x) > 0.0):
        mode[target] = 1
    elif kind == _OPEN:
        mode[target] = 0
    elif kind == _SLIP:
        mode[n_contacts + target] = direction
    elif kind == _STOP:
        n, lower = geometry.shape[1], base_dofs[1, target]
        x[n + base_dofs[0, target]] = x[n + lower] if lower >= 0 else 0.0
        mode[n_contacts + target] = _STUCK


@njit(**INTERNAL)
def _with_bound(M, i, x, magnitude, ground, constant):
    """Row i of the affine map M at (x, a_g), with its constant or not, its round-off scale and Σabs(M[i, :S + 1]).

    The scale is the same sum with every term taken absolute and x replaced
    by ``magnitude``.
    """
    size = M.shape[1] - 2
    slope, offset = M[i, size], M[i, size + 1] if constant else 0.0
    value, scale, floor = slope * ground + offset, abs(slope) * abs(ground) + abs(offset), abs(slope)
    for j in range(size):
        value += M[i, j] * x[j]
        scale += abs(M[i, j]) * magnitude[j]
        floor += abs(M[i, j])
    return value, scale, floor


@njit(**INTERNAL)
def _leaving_sign(rate, guard, n_guards, x, ground, readout, values, tolerance, heading, scratch):
    """Values, tolerances and heading of the first n_guards guards at state x (its first S entries) and a_g derivatives ``ground``.

    The heading of a guard is the sign of its first time derivative (up to the
    third) that is clearly non-zero: 0 while undecided. The derivatives of ξ
    come from the rate map, with the read-outs' value and rate from
    ``readout`` (2 × n_f: f, ḟ; their higher derivatives taken as 0).
    ``scratch``: the engine's work array (:func:`work_arrays`).
    """
    size, rows = rate.shape[1] - 2, rate.shape[0]
    derivative, magnitude, next_derivative, next_magnitude = scratch[20, :size], scratch[21, :size], scratch[22, :size], scratch[23, :size]
    for i in range(rows):
        derivative[i], magnitude[i] = x[i], abs(x[i])
    for j in range(size - rows):
        derivative[rows + j], magnitude[rows + j] = readout[0, j], abs(readout[0, j])
    for g in range(n_guards):
        heading[g] = 0
    for order in range(4):
        for g in range(n_guards):
            value, scale, floor = _with_bound(guard, g, derivative, magnitude, ground[order], order == 0)
            limit = _ROUND_OFF * (scale + 1e-4 * floor)
            if order == 0:
                values[g], tolerance[g] = value, limit
            if heading[g] == 0 and abs(value) > limit:
                heading[g] = 1 if value > 0.0 else -1
        for i in range(rows):
            next_derivative[i], next_magnitude[i], _ = _with_bound(rate, i, derivative, magnitude, ground[order], order == 0)
        for j in range(size - rows):
            next_derivative[rows + j] = readout[1, j] if order == 0 else 0.0
            next_magnitude[rows + j] = abs(next_derivative[rows + j])
        derivative, next_derivative = next_derivative, derivative
        magnitude, next_magnitude = next_magnitude, magnitude


@njit(**INTERNAL)
def _first_wanting(codes, n_guards, geometry, gap, tensile, x, values, tolerance, heading):
    """Index of the first guard that fires at this instant, or −1.

    A RECLOSE guard does not fire while its contact is not penetrated, nor the
    CLOSE guard of a non-tensile contact still penetrated.
    """
    for j in range(n_guards):
        kind, p = codes[KIND, j], codes[TARGET, j]
        if heading[j] <= 0:
            continue
        if kind == _RECLOSE and _penetration(geometry, gap, p, x) <= 0.0:
            continue
        if kind == _CLOSE and not tensile[p] and values[j] > tolerance[j]:
            continue
        return j
    return -1


@njit(**INTERNAL)
def _initial_guard_states(codes, n_guards, geometry, gap, tensile, x, values, tolerance, threshold_out, tolerance_out, rearmable, disarmed):
    """The initial guard states (armed or not) into the run's guard arrays."""
    for j in range(n_guards):
        tolerance_out[j] = tolerance[j]
        threshold_out[j] = 0.0 if values[j] < -tolerance[j] else _FIRE_RATIO * tolerance[j]
        rearmable[j] = True
        kind, p = codes[KIND, j], codes[TARGET, j]
        if kind == _RECLOSE and _penetration(geometry, gap, p, x) <= 0.0:
            threshold_out[j], rearmable[j] = math.inf, False
        elif kind == _CLOSE and not tensile[p] and values[j] > tolerance[j]:
            threshold_out[j] = math.inf
        disarmed[j] = threshold_out[j] != 0.0


@njit(**INTERNAL)
def _settle(modes, codes, n_guards, rate, guard, geometry, gap, tensile, base_dofs, ground, ints, x, mode, transitions,
            threshold, tolerance, rearmable, disarmed, readouts, scratch, marks):
    """Settle the pending event: returns (mode index, number of transitions); x (ξ) and mode are updated.

    The fired transition is applied, then every guard of the new mode is
    judged at the same instant (:func:`_leaving_sign`), and transitions are
    applied until no guard wants to fire; meeting a mode twice (a chattering
    cycle) keeps the last mode and disarms the guards that still want to fire.
    ``codes``, ``rate`` and ``guard`` are the :class:`ModeTable` and
    :class:`Dynamics` arrays of the slots. Returns mode index −1 when a mode
    is in no slot (``mode`` is that mode; nothing else has changed then), −2
    when a mode's read-outs are needed (:class:`Readouts`: ``readouts.x`` and
    ``ints[READOUT_SLOT]`` say which). ``scratch`` and ``marks``: the work
    arrays (:func:`work_arrays`).
    """
    n_guards_max = guard.shape[1]
    values, limits, heading = scratch[18, :n_guards_max], scratch[19, :n_guards_max], marks[-3, :n_guards_max]
    n_transitions = 0
    if ints[PENDING] == EVENT:
        kind, target, direction = ints[FIRED_KIND], ints[FIRED_TARGET], ints[FIRED_DIRECTION]
        _apply(geometry, gap, base_dofs, mode, x, kind, target, direction)
        transitions[0, 0], transitions[0, 1], transitions[0, 2] = kind, target, direction
        n_transitions = 1
    visited, following = marks[: _MAX_SETTLE + 1], marks[-2, : mode.shape[0]]
    _copy(mode, visited[0, : mode.shape[0]])
    n_visited = 1
    settled = False
    for _ in range(_MAX_SETTLE):
        m = _lookup(modes, mode)
        if m < 0:
            break
        r = _readout_of(readouts, ints, m, x)
        if r < 0:
            return -2, 0
        _leaving_sign(rate[m], guard[m], n_guards[m], x, ground, readouts.values[r], values, limits, heading, scratch)
        j = _first_wanting(codes[m], n_guards[m], geometry, gap, tensile, x, values, limits, heading)
        if j < 0:
            settled = True
            break
        kind, target, direction = codes[m, KIND, j], codes[m, TARGET, j], codes[m, DIRECTION, j]
        _copy(mode, following)
        _apply(geometry, gap, base_dofs, following, x, kind, target, direction)
        if _lookup(visited[:n_visited], following) >= 0:
            break
        transitions[n_transitions, 0], transitions[n_transitions, 1], transitions[n_transitions, 2] = kind, target, direction
        n_transitions += 1
        _copy(following, visited[n_visited, : mode.shape[0]])
        n_visited += 1
        _copy(following, mode)
    m = _lookup(modes, mode)
    if m < 0:
        return -1, 0
    r = _readout_of(readouts, ints, m, x)
    if r < 0:
        return -2, 0
    if not settled:
        ints[CHATTER] += 1
        _leaving_sign(rate[m], guard[m], n_guards[m], x, ground, readouts.values[r], values, limits, heading, scratch)
    _initial_guard_states(codes[m], n_guards[m], geometry, gap, tensile, x, values, limits, threshold, tolerance, rearmable, disarmed)
    rows = rate.shape[1]
    for j in range(readouts.values.shape[2]):  # ξ's read-outs: the settled mode's
        x[rows + j] = readouts.values[r, 0, j]
    ints[N_READOUTS] = 0
    return m, n_transitions


@njit(**INTERNAL)
def _readout_of(readouts, ints, m, x):
    """The row of ``readouts`` holding slot m's read-outs at this instant, or −1 after asking for them (state x into ``readouts.x``).

    With no read-outs (n_f = 0) every slot has its (empty) row 0.
    """
    if readouts.values.shape[2] == 0:
        return 0
    for r in range(ints[N_READOUTS]):
        if readouts.slots[r] == m:
            return r
    _copy(x, readouts.x)
    ints[READOUT_SLOT] = m
    return -1


# ---------------------------------------------------------------- recording events


@njit(**INTERNAL)
def _on_transitions(mode, force, left_rows, right_rows, geometry, is_open, impact, table, ints, t, x, transitions, n_transitions):
    """``Recorder.on_transitions`` and ``on_contact_force`` at an event (``impact``: rows of ``Impacts.impact``)."""
    n = geometry.shape[1]
    for i in range(n_transitions):
        kind, p = transitions[i, 0], transitions[i, 1]
        if (kind == _CLOSE or kind == _RECLOSE) and not is_open[p] and mode[p] == 1:
            left, right, onset = 0.0, 0.0, 0.0
            for j in range(n):
                left += left_rows[p, j] * x[n + j]
                right += right_rows[p, j] * x[n + j]
                onset += geometry[p, j] * x[n + j]
            is_open[p] = True
            impact[START, p], impact[ONSET, p], impact[IN_PHASE, p] = t, onset, 1.0 if left * right > 0.0 else 0.0
            impact[PEAK, p], impact[PEAK_TIME, p], impact[IMPULSE, p] = 0.0, math.nan, 0.0
        elif kind == _OPEN and is_open[p] and mode[p] == 0:
            row = table[ints[N_IMPACTS]]
            row[0], row[1] = p, t
            for r in range(impact.shape[0]):
                row[2 + r] = impact[r, p]
            ints[N_IMPACTS] += 1
            is_open[p] = False
    _offer_peaks(force, is_open, impact, t, x)


@njit(**INTERNAL)
def _settle_pending(modes, codes, n_guards, rate, guard, force, monitor, motion, layout, arming, ints, clock, pending_x, pending_mode,
                    missing_mode, is_open, impact, table, peaks, readouts, x, scratch, marks):
    """Settle the pending event (or the start) and record it (:func:`_settle`, :func:`_on_transitions`): returns the mode index.

    The settled ξ goes into ``x``. Returns −1 (with the mode to build in
    ``missing_mode``) when a mode is missing, −2 when read-outs are
    (:func:`_readout_of`); nothing else has changed then.
    ``scratch`` and ``marks``: the work arrays (:func:`work_arrays`).
    """
    settled, mode = scratch[16, : x.shape[0]], marks[-1, : pending_mode.shape[0]]
    _copy(pending_x, settled)
    _copy(pending_mode, mode)
    transitions, ground = marks[_MAX_SETTLE + 1 : 2 * (_MAX_SETTLE + 1)], scratch[17, :4]
    _ground(motion.times, motion.coefficients, motion.harmonic, clock[0], ints[K], ground)
    geometry, gap, tensile, left_rows, right_rows, base_dofs = layout
    threshold, tolerance, rearmable, disarmed = arming
    m, n_transitions = _settle(modes, codes, n_guards, rate, guard, geometry, gap, tensile, base_dofs, ground, ints, settled, mode,
                               transitions, threshold, tolerance, rearmable, disarmed, readouts, scratch, marks)
    if m == -1:
        _copy(mode, missing_mode)
    if m < 0:
        return m
    _on_transitions(modes[m], force[m], left_rows, right_rows, geometry, is_open, impact, table, ints, clock[0], settled, transitions,
                    n_transitions)
    n_monitors = monitor.shape[1]
    monitors, monitor_rates = scratch[24, :n_monitors], scratch[26, :n_monitors]
    _guards_and_rates(rate[m], guard[m], monitor[m], settled, ground[0], ground[1], monitors[:0], monitor_rates[:0], monitors, monitor_rates,
                      scratch[2])
    _offer_monitors(monitors, clock[0], peaks)  # a monitor may jump with the mode (e.g. an acceleration at impact)
    _copy(settled, x)
    return m


# ---------------------------------------------------------------- event steps


@njit(**INTERNAL)
def _locate_and_record(flow, m, modes, codes, force, power, ints, clock, x0, x1, pending_x, pending_mode, arming, is_open, impact,
                       running, peaks, t1, values0, values1, rates0, rates1, scratch):
    """The event code of one step [flow.t0, t1] of mode m on its dense flow: returns True when it stopped at an event (now pending).

    The earliest guard crossing is located (:func:`_first_crossing`); the
    energy terms and impulses are integrated (5-point Gauss–Legendre on the
    flow) and the impact forces' and monitors' peaks located up to the event
    or t1; the
    fired guard becomes the pending event at ``clock[0]`` with the state in
    ``pending_x``. ``values*``/``rates*`` are the guards' values and rates
    at the step's ends; ``scratch``: the work array (:func:`work_arrays`).
    """
    threshold, tolerance, rearmable, disarmed = arming
    t0, size = flow.t0, flow.rate.shape[1] - 2
    width = size + 5
    work, x_stop = scratch[2], scratch[12, :size]
    node, products = scratch[10, :width], scratch[11, : power.shape[1]]  # node: z = [x, a_g, 0, 0, 0, 1] at a Gauss node
    node[size + 1], node[size + 2], node[size + 3], node[width - 1] = 0.0, 0.0, 0.0, 1.0
    t_event, fired = _first_crossing(flow, threshold, tolerance, rearmable, disarmed, ints, t1, values0, values1, rates0, rates1, work,
                                     scratch[13], scratch[14], scratch[15])
    t_stop = t1
    _copy(x1, x_stop)
    if fired >= 0:
        t_stop = t_event
        _dense(flow, t_event, x_stop)
    if t_stop > t0:  # energy terms and impulses at the Gauss nodes, then peak forces
        half = 0.5 * (t_stop - t0)
        for g in range(N_NODES):
            t_node, weight = t0 + half * (GAUSS_NODES[g] + 1.0), half * GAUSS_WEIGHTS[g]
            _dense(flow, t_node, node[:size])
            node[size] = _ground_value(flow, t_node)
            _product(power, node, products)
            _add_forms(node, products, weight, running)
            for p in range(is_open.shape[0]):
                if is_open[p]:
                    impact[IMPULSE, p] += weight * _affine(force, p, node, 0.0)
        _offer_peaks(force, is_open, impact, t0, x0)
        _offer_peaks(force, is_open, impact, t_stop, x_stop)
        for p in range(is_open.shape[0]):  # a force maximum inside the step
            if is_open[p] and _evaluate(flow, -1 - p, 0.0, t0, work) > 0.0 > _evaluate(flow, -1 - p, 0.0, t_stop, work):
                t_peak = _brentq(flow, -1 - p, 0.0, t0, t_stop, work)
                _dense(flow, t_peak, work[:size])
                value = _affine(force, p, work, 0.0)
                if value > impact[PEAK, p]:
                    impact[PEAK, p], impact[PEAK_TIME, p] = value, t_peak
        n_monitors = flow.monitor.shape[0]
        monitors0, monitors1, monitor_rates0, monitor_rates1 = scratch[24, :n_monitors], scratch[25, :n_monitors], scratch[26, :n_monitors], scratch[27, :n_monitors]
        if fired >= 0:  # the caller gave the monitors at t1
            _flow_read_outs(flow, t_stop, x_stop, values1[:0], rates1[:0], monitors1, monitor_rates1, work)
        _monitor_peaks(flow, t_stop, monitors0, monitors1, monitor_rates0, monitor_rates1, peaks, work)
    if fired < 0:
        return False
    clock[0] = t_event
    _copy(x_stop, pending_x)
    _copy(modes[m], pending_mode)
    ints[FIRED_KIND], ints[FIRED_TARGET], ints[FIRED_DIRECTION] = codes[m, KIND, fired], codes[m, TARGET, fired], codes[m, DIRECTION, fired]
    ints[PENDING] = EVENT
    ints[TOTAL] += 1
    return True


@njit(**INTERNAL)
def _advance_span(m, n, modes, codes, substeps, step, propagate, chebyshev, rate, guard, force, monitor, power, motion, ints, clock, x,
                  pending_x, pending_mode, arming, is_open, impact, running, peaks, k, t, t_end, scratch):
    """Exact sub-steps of mode m (n guards, its arrays) from t to t_end, each through :func:`_locate_and_record`.

    A full sub-step in which no guard passes the screen and no impact is
    open takes the quiet loop's shortcut (its energy forms). Returns True
    when it stopped at an event (now pending), False at t_end.
    ``scratch``: the work array (:func:`work_arrays`).
    """
    times, coefficients_k, harmonic = motion.times, motion.coefficients, motion.harmonic
    threshold, tolerance, rearmable, disarmed = arming
    full = t == times[k] and t_end == times[k + 1]
    n_steps = substeps if full else math.ceil((t_end - t) / step - 1e-9)
    if not full and n_steps < 1:
        n_steps = 1
    spacing = (t_end - t) / n_steps
    size = x.shape[0]
    width = size + 5
    z0, propagated = scratch[0, :width], scratch[1, : propagate.shape[1]]
    values0, values1, rates0, rates1 = scratch[3, :n], scratch[4, :n], scratch[5, :n], scratch[6, :n]
    n_monitors = monitor.shape[0]
    monitors0, monitors1, monitor_rates0, monitor_rates1 = scratch[24, :n_monitors], scratch[25, :n_monitors], scratch[26, :n_monitors], scratch[27, :n_monitors]
    rate_work, ground1, coefficients = scratch[7, :size], scratch[8, :4], scratch[9, : chebyshev.shape[1]]
    x1 = propagated[:size]
    is_harmonic = harmonic.shape[0] > 0
    ground = harmonic if is_harmonic else coefficients_k[k]
    any_open = _any(is_open)
    for i in range(n_steps):
        t0 = t + i * spacing  # as np.linspace(t, t_end, n_steps + 1)
        t1 = t_end if i == n_steps - 1 else t + (i + 1) * spacing
        _copy(x, z0[:size])
        _ground(times, coefficients_k, harmonic, t0, k, z0[size : size + 4])
        z0[width - 1] = 1.0
        flow = Flow(rate, guard, force, monitor, coefficients, ground, times[k], is_harmonic, t0, 2.0 / step)
        _guards_and_rates(rate, guard, monitor, x, z0[size], z0[size + 1], values0, rates0, monitors0, monitor_rates0, rate_work)
        if full:
            _product(propagate, z0, propagated)
        else:
            _product(chebyshev, z0, coefficients)
            _dense(flow, t1, x1)
        _ground(times, coefficients_k, harmonic, t1, k, ground1)
        _guards_and_rates(rate, guard, monitor, x1, ground1[0], ground1[1], values1, rates1, monitors1, monitor_rates1, rate_work)
        if full and not _suspect(values0, values1, rates0, rates1, t1 - t0, threshold, tolerance) and not any_open:
            _sub_step_energy(z0, propagated, is_open, impact[IMPULSE], running)
            _arm_where_negative(values1, threshold, tolerance, rearmable, disarmed)
            if _offer_end_monitors(monitors0, monitors1, monitor_rates0, monitor_rates1, t1 - t0, t1, peaks):
                _sub_step_monitors(flow, chebyshev, z0, t1, monitors0, monitors1, monitor_rates0, monitor_rates1, peaks, scratch[2])
            _copy(x1, x)
            continue
        if full:
            _product(chebyshev, z0, coefficients)
        if _locate_and_record(flow, m, modes, codes, force, power, ints, clock, x, x1, pending_x, pending_mode, arming, is_open, impact,
                              running, peaks, t1, values0, values1, rates0, rates1, scratch):
            return True
        _copy(x1, x)
    return False


@njit(**INTERNAL)
def _supplied_step(m, n, modes, codes, rate, guard, force, monitor, power, motion, ints, clock, x, pending_x, pending_mode, arming, is_open,
                   impact, running, peaks, k, supplied, scratch):
    """The supplied step of mode m (n guards, its arrays) through :func:`_locate_and_record`; ξ moves to its end if no event.

    The step starts at the engine's ξ = x (its read-outs included) and its
    rates are the derivative of the supplied expansion. Returns True when it
    stopped at an event (now pending).
    """
    times, harmonic = motion.times, motion.harmonic
    t0, t1 = supplied.bounds[0], supplied.bounds[1]
    values0, values1, rates0, rates1 = scratch[3, :n], scratch[4, :n], scratch[5, :n], scratch[6, :n]
    is_harmonic = harmonic.shape[0] > 0
    ground = harmonic if is_harmonic else motion.coefficients[k]
    flow = Flow(rate, guard, force, monitor, supplied.coefficients, ground, times[k], is_harmonic, t0, 2.0 / (t1 - t0))
    n_monitors = monitor.shape[0]
    monitors0, monitors1, monitor_rates0, monitor_rates1 = scratch[24, :n_monitors], scratch[25, :n_monitors], scratch[26, :n_monitors], scratch[27, :n_monitors]
    _flow_read_outs(flow, t0, x, values0, rates0, monitors0, monitor_rates0, scratch[2])
    _flow_read_outs(flow, t1, supplied.x, values1, rates1, monitors1, monitor_rates1, scratch[2])
    if _locate_and_record(flow, m, modes, codes, force, power, ints, clock, x, supplied.x, pending_x, pending_mode, arming, is_open, impact,
                          running, peaks, t1, values0, values1, rates0, rates1, scratch):
        return True
    _copy(supplied.x, x)
    clock[0] = t1
    return False


# ---------------------------------------------------------------- the run


@cached_njit(nogil=True, no_cfunc_wrapper=True, error_model="numpy", **NO_RUNTIME)
def run_engine(table, dynamics, propagators, motion, layout, run, arming, impacts, outputs, supplied, readouts, scratch, saved, marks, external):
    """Run (or resume) the simulation; returns FINISHED, NEED_MODE, NEED_SPACE, NEED_STEP or NEED_READOUTS.

    Parameters
    ----------
    table, dynamics, propagators : ModeTable, Dynamics, Propagators
        The modes in the slots (``propagators`` unused when ``external``).
    motion, layout : Motion, Layout
        The motion and the system.
    run, arming, impacts, outputs : Run, Arming, Impacts, Outputs
        Everything the run changes, updated in place.
    supplied : Supplied
        The caller's next step of the flow (``external`` runs).
    readouts : Readouts
        The read-outs of the modes met while settling (systems with nonlinear laws).
    scratch, saved, marks : np.ndarray
        Work arrays (:func:`work_arrays`).
    external : bool
        False: the flow is the exact propagators' (the quiet loop and the
        exact sub-steps). True: the caller supplies the flow step by step
        (an integrator's steps, ``method="ivp"``): NEED_STEP asks for the
        step from ``run.clock[0]``, state ``run.x``, in the mode of slot
        ``run.ints[MODE]`` inside interval ``run.ints[K]``; the caller fills
        ``supplied``, sets ``run.ints[READY]`` and calls again.

    Returns
    -------
    int
        On NEED_MODE, ``run.missing_mode`` is the mode to build; on NEED_SPACE
        the impact table is full; on NEED_READOUTS a mode's read-outs are
        missing (:class:`Readouts`). The caller fixes it and calls again.
    """
    modes, ids, codes, n_guards, substeps = table
    rate, guard, force, monitor, power = dynamics
    propagate, chebyshev, step = propagators
    clock, ints, x, pending_x, pending_mode, missing_mode, visited = run
    is_open, impact, impact_table = impacts
    running, states, energy, sample_modes, peaks = outputs
    times = motion.times
    last = times.shape[0] - 1
    while True:
        if ints[PENDING] != NONE:
            if ints[N_IMPACTS] + is_open.shape[0] > impact_table.shape[0]:
                return NEED_SPACE
            m = _settle_pending(modes, codes, n_guards, rate, guard, force, monitor, motion, layout, arming, ints, clock, pending_x,
                                pending_mode, missing_mode, is_open, impact, impact_table, peaks, readouts, x, scratch, marks)
            if m < 0:
                return NEED_MODE if m == -1 else NEED_READOUTS
            ints[MODE] = m
            visited[ids[m]] = True
            if ints[PENDING] == INITIAL:
                _record_sample(x, running, ids[m], states, energy, sample_modes, ints[K])
            ints[PENDING] = NONE
        k, m = ints[K], ints[MODE]
        if not external and k < last and clock[0] == times[k]:
            _advance_quiet(ids[m], n_guards[m], substeps[m], step[m], propagate[m], chebyshev[m], rate[m], guard[m], force[m], monitor[m], motion,
                           ints, clock, x, arming, is_open, impact, outputs, scratch, saved)
            k = ints[K]
        if k >= last:
            return FINISHED
        t, t_end = clock[0], times[k + 1]
        if t_end - t > _EPS * (abs(t_end) if abs(t_end) > 1.0 else 1.0):
            if external:
                if ints[READY] == 0:
                    return NEED_STEP
                ints[READY] = 0
                if _supplied_step(m, n_guards[m], modes, codes, rate[m], guard[m], force[m], monitor[m], power[m], motion, ints, clock, x,
                                  pending_x, pending_mode, arming, is_open, impact, running, peaks, k, supplied, scratch) or clock[0] < t_end:
                    continue
            elif _advance_span(m, n_guards[m], modes, codes, substeps[m], step[m], propagate[m], chebyshev[m], rate[m], guard[m], force[m],
                               monitor[m], power[m], motion, ints, clock, x, pending_x, pending_mode, arming, is_open, impact, running, peaks,
                               k, t, t_end, scratch):
                continue
        clock[0] = t_end
        ints[K] = k + 1
        _record_sample(x, running, ids[m], states, energy, sample_modes, k + 1)
