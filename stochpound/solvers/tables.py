"""The event engine's arrays: the modes a run reaches, the plant, the run state and the work arrays.

:mod:`stochpound.solvers.engine` takes only arrays, grouped in small
named tuples. This module lays them out from the model's objects:

* :class:`Slots`: every mode the runs of one library reach, one per slot of
  fixed-size arrays (mode vector and guard codes, affine maps of ẋ, the
  guards and the contact forces, the power forms and, for the exact solver,
  the sub-step propagator with the energy and impulse forms stacked beside
  it and the Chebyshev expansion of the flow). Slots are shared by the
  library's runs; within a memory budget new modes take free slots, beyond
  it the slot filled longest ago.
* :func:`plant_arrays` (system and motion), :func:`run_state` (everything one
  run changes) and :func:`work_arrays_for` (the engine's scratch rows).

The powers of the energy balance are defined once, as bilinear forms of the
augmented state z = [x, w, 1] (:func:`_power_factors`); the engine integrates
them on the dense flow at Gauss–Legendre nodes (:func:`_power_forms`), and
over a whole exact sub-step as quadratic forms of z at its start
(:func:`_sub_step_forms`), added with one matrix product per sub-step.
"""

from __future__ import annotations

import weakref
from collections import namedtuple

import numpy as np

from stochpound.model.modes import BoundedCache, Mode, ModeDynamics, ModeLibrary, monitor_count
from stochpound.model.system import System
from stochpound.motions.ground import GroundMotion, HarmonicMotion
from stochpound.results.record import ENERGY_TERMS
from stochpound.solvers import engine
from stochpound.solvers.propagators import (
    CHEBYSHEV_DEGREE,
    GAUSS_WEIGHTS,
    ModePropagator,
    PropagatorLibrary,
    interval_forcing,
)

Built = namedtuple("Built", "table dynamics propagators")
"""The engine's arrays of the modes in a library's slots (:class:`Slots`)."""
Plant = namedtuple("Plant", "motion layout")
"""The engine's arrays of a system and motion (:func:`plant_arrays`)."""
State = namedtuple("State", "run arming impacts outputs supplied readouts")
"""The engine's arrays of one run (:func:`run_state`)."""


def mode_vector(mode: Mode) -> np.ndarray:
    """The engine's int64 vector of a mode: closed flags, then base states, then yielding storey states, then 1 (an empty slot's vector ends in -9 instead).

    The engine treats a yielding storey's plastic element like a sliding base
    (:mod:`stochpound.model.yielding`): its sliders are the bases, then the storeys.
    """
    return np.array([int(flag) for flag in mode.closed] + list(mode.base) + list(mode.storey) + [1], dtype=np.int64)


def vector_mode(vector: np.ndarray, n_contacts: int, n_bases: int) -> Mode:
    """The :class:`~stochpound.model.modes.Mode` of an engine mode vector (``n_contacts`` impact elements, ``n_bases`` sliding bases)."""
    sliders = n_contacts + n_bases
    return Mode(tuple(bool(v) for v in vector[:n_contacts]), tuple(int(v) for v in vector[n_contacts:sliders]), tuple(int(v) for v in vector[sliders:-1]))


def mode_length(system: System) -> int:
    """Length of the engine's mode vectors of ``system`` (:func:`mode_vector`)."""
    return system.n_elements + len(system.bases) + len(system.storeys) + 1


def slider_dofs(system: System) -> np.ndarray:
    """The engine's slider DOFs (2 × sliders, int64: :data:`stochpound.solvers.engine.Layout`): the sliding bases, then the yielding storeys.

    A STOP sets the velocity of the first row's DOF to the second's (−1: to
    0): a base's own, a storey's upper floor's to its lower floor's (its
    drift rate to 0; u_0 = 0 for the first storey).
    """
    bases = system.base_dofs
    upper = [storey.upper for storey in system.storeys]
    lower = [storey.lower for storey in system.storeys]
    return np.array([[*bases.tolist(), *upper], [-1] * len(bases) + lower], dtype=np.int64).reshape(2, len(bases) + len(upper))


def plant_arrays(system: System, motion: GroundMotion) -> Plant:
    """System and motion arrays of the engine (raises :class:`~stochpound.solvers.propagators.UnsupportedMotionError` for other motions)."""
    forcing = np.ascontiguousarray(interval_forcing(motion))
    if isinstance(motion, HarmonicMotion):
        coefficients, harmonic = np.zeros((1, 4)), np.array([motion.amplitude, motion.omega, motion.phase], float)
    else:
        coefficients, harmonic = np.ascontiguousarray(motion.coefficients, float), np.zeros(0)
    return Plant(
        engine.Motion(np.asarray(motion.times, float), forcing, coefficients, harmonic),
        engine.Layout(system.element_geometry, system.element_gap, system.element_tensile.astype(np.bool_), system.element_left, system.element_right,
                      slider_dofs(system)),
    )


def max_guards(system: System) -> int:
    """The largest number of guards of a mode: two per contact (CLOSE and RECLOSE), two per base and per yielding storey (SLIP both ways)."""
    return 2 * system.n_elements + 2 * len(system.bases) + 2 * len(system.storeys)


def work_arrays_for(system: System, slots: "Slots") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The engine's work arrays for ``system`` and the current Chebyshev width of ``slots`` (:func:`stochpound.solvers.engine.work_arrays`)."""
    return engine.work_arrays(system.xi_size, max_guards(system), system.n_elements, monitor_count(system), mode_length(system),
                              slots.arrays["chebyshev"].shape[2])


def run_state(system: System, n_times: int, supplied_degree: int = 0) -> State:
    """Fresh arrays of everything a run changes (supplied steps of Chebyshev degree ``supplied_degree``)."""
    size, n_contacts, n_guards = system.xi_size, system.n_elements, max_guards(system)
    length = mode_length(system)
    return State(
        engine.Run(np.zeros(1), np.zeros(engine.N_INTS, dtype=np.int64), np.zeros(size), np.zeros(size),
                   np.zeros(length, dtype=np.int64), np.zeros(length, dtype=np.int64), np.zeros(64, dtype=np.bool_)),
        engine.Arming(np.zeros(n_guards), np.zeros(n_guards), np.zeros(n_guards, dtype=np.bool_), np.zeros(n_guards, dtype=np.bool_)),
        engine.Impacts(np.zeros(n_contacts, dtype=np.bool_), np.zeros((6, n_contacts)),
                       np.zeros((max(64, 4 * n_contacts), len(engine.IMPACT_COLUMNS)))),
        engine.Outputs(np.zeros(len(ENERGY_TERMS)), np.zeros((n_times, size)), np.zeros((len(ENERGY_TERMS), n_times)),
                       np.zeros(n_times, dtype=np.int64), np.array([[-np.inf], [np.nan]]).repeat(monitor_count(system), axis=1)),
        engine.Supplied(np.zeros(2), np.zeros(size), np.zeros((supplied_degree + 1) * size)),
        engine.Readouts(np.zeros(engine.MAX_SETTLE_ITERATIONS + 2, dtype=np.int64), np.zeros((engine.MAX_SETTLE_ITERATIONS + 2, 2, system.n_readouts)),
                        np.zeros(size)),
    )


TABLE_BUDGET = 256 * 2**20
"""Largest size of the engine arrays of one library, bytes: beyond it modes take turns in the slots."""

ENERGY_BUDGET = 256 * 2**20
"""Largest size of the cached :func:`_energy_rows` of one library's modes, bytes (they outlive their slots)."""

INITIAL_SLOTS = 128
"""Slots allocated at first (doubled when full, up to the budget)."""

_SLOTS: "weakref.WeakKeyDictionary[PropagatorLibrary | ModeLibrary, Slots]" = weakref.WeakKeyDictionary()


def slots_of(library: PropagatorLibrary | ModeLibrary) -> "Slots":
    """The engine arrays of ``library``'s modes, shared by its runs.

    With a :class:`~stochpound.solvers.propagators.PropagatorLibrary` (the exact solver) the slots hold the
    modes' propagators too; with a :class:`~stochpound.model.modes.ModeLibrary` (supplied flows) only
    their dynamics.
    """
    slots = _SLOTS.get(library)
    if slots is None:
        slots = _SLOTS[library] = Slots(library)
    return slots


class Slots:
    """The engine's arrays (:class:`Built`) of a library's modes, one mode per slot.

    The arrays grow to :data:`TABLE_BUDGET` bytes (and at least to a settling
    chain's length); beyond that a new mode takes the slot filled longest ago,
    and the mode it held is loaded again when the engine asks for it. Every
    mode keeps one id (``modes[id]``), which the engine records per sample.
    Empty slots never match a mode (their mode vector is invalid).

    Parameters
    ----------
    library : PropagatorLibrary or ModeLibrary
        The exact solver's propagators of the modes, or their dynamics only
        (flows supplied by the caller: the ``Propagators`` arrays stay empty).
    """

    def __init__(self, library: PropagatorLibrary | ModeLibrary) -> None:
        self.library = library
        self.exact = isinstance(library, PropagatorLibrary)
        self.system = library.system
        self.modes: list[Mode] = []
        self._ids: dict[Mode, int] = {}
        self._slot: dict[Mode, int] = {}
        self._held: list[Mode] = []
        self._oldest = 0
        self._energy: BoundedCache[Mode, tuple[np.ndarray, ...]] = BoundedCache(ENERGY_BUDGET, _total_bytes)
        self.arrays: dict[str, np.ndarray] = {}
        width = (CHEBYSHEV_DEGREE + 1) * 2 * self.system.n_dof  # the usual Chebyshev rows (grown if a mode's are wider)
        self._grow(1, width)
        self._capacity = max(engine.MAX_SETTLE_ITERATIONS + 2, TABLE_BUDGET // sum(array[0].nbytes for array in self.arrays.values()))
        self._grow(min(self._capacity, INITIAL_SLOTS), width)

    @property
    def tables(self) -> Built:
        """The arrays, grouped as the engine takes them."""
        return Built(*(group(**{name: self.arrays[name] for name in group._fields}) for group in (engine.ModeTable, engine.Dynamics, engine.Propagators)))

    def dynamics(self, mode: Mode) -> ModeDynamics:
        """The dynamics of ``mode`` (from the library's cache)."""
        return self.library[mode].dynamics if self.exact else self.library[mode]

    def slot(self, mode: Mode) -> int:
        """The slot of ``mode`` (loaded if it holds none)."""
        slot = self._slot.get(mode)
        return self.load(mode) if slot is None else slot

    def load(self, mode: Mode) -> int:
        """Put ``mode`` into a free slot, or else the one filled longest ago; return the slot."""
        propagator = self.library[mode] if self.exact else None
        dynamics = self.dynamics(mode)
        energy = self._energy.get(mode)
        if energy is None:  # worth keeping: their products cost more than building the propagator
            energy = _energy_rows(self.system, dynamics, propagator)
            self._energy.put(mode, energy)
        row = _mode_rows(self.system, mode, dynamics, energy)
        if propagator is not None:
            row.update(_propagator_rows(propagator, row["guard"], row["monitor"], row["rate"], energy[1]))
        row["ids"] = np.int64(self._ids.setdefault(mode, len(self._ids)))
        if row["ids"] == len(self.modes):
            self.modes.append(mode)
        slot, size = self._take_slot(mode), len(self.arrays["modes"])
        chebyshev_width = row["chebyshev"].shape[1] if "chebyshev" in row else 0
        if slot == size or chebyshev_width > self.arrays["chebyshev"].shape[2]:
            self._grow(min(self._capacity, 2 * size) if slot == size else size, chebyshev_width)
        if "chebyshev" in row and chebyshev_width < self.arrays["chebyshev"].shape[2]:
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
        for name, value in _placeholder(self.system, width, self.exact).items():
            self.arrays[name] = np.zeros((capacity,) + np.shape(value), np.asarray(value).dtype)  # untouched pages stay unallocated
            if np.any(value):
                self.arrays[name][:] = value
        for name, array in old.items():
            self.arrays[name][(slice(0, len(array)), ...) + tuple(slice(0, n) for n in array.shape[1:])] = array


def _mode_rows(system: System, mode: Mode, dynamics: ModeDynamics, energy: tuple[np.ndarray, ...]) -> dict[str, np.ndarray]:
    """One mode's entries of the :class:`Built` arrays but its id and propagators (guards padded to the system's largest count).

    ``energy`` is the mode's :func:`_energy_rows`.
    """
    d = dynamics
    count, n_guards = len(d.guard_kind), max_guards(system)
    codes = np.zeros((3, n_guards), dtype=np.int64)
    codes[:, :count] = d.guard_kind, d.guard_target, d.guard_direction
    guard = np.zeros((n_guards, d.A.shape[1] + 2))
    guard[:count] = _affine(d.guard_matrix, d.guard_ground, d.guard_constant)
    return {
        "modes": mode_vector(mode), "codes": codes, "n_guards": np.int64(count), "rate": _affine(d.A, d.B, d.c), "guard": guard,
        "force": _affine(d.force_matrix, 0.0, d.force_constant), "monitor": _affine(d.monitor_matrix, d.monitor_ground, d.monitor_constant),
        "power": energy[0],
    }


def _propagator_rows(propagator: ModePropagator, guard: np.ndarray, monitor: np.ndarray, rate: np.ndarray, forms: np.ndarray) -> dict[str, np.ndarray]:
    """One mode's entries of the ``Propagators`` arrays (and its sub-steps per interval).

    ``guard``, ``monitor`` and ``rate`` are the mode's affine maps (guards
    padded), ``forms`` its sub-step energy forms and impulses (:func:`_energy_rows`).
    """
    width = len(propagator.transition)
    read_outs = np.vstack([_read_out_rows(guard, rate, width), _read_out_rows(monitor, rate, width)])
    return {
        "substeps": np.int64(propagator.substeps),
        # the slot's columns beyond these stay zero: the padding to engine.propagate_columns
        "propagate": np.concatenate([propagator.transition.T, forms, (read_outs @ propagator.transition).T], axis=1),
        "step": np.float64(propagator.step),
        "chebyshev": propagator.chebyshev.reshape(-1, propagator.transition.shape[0]).T,
    }


def _energy_rows(system: System, dynamics: ModeDynamics, propagator: ModePropagator | None) -> tuple[np.ndarray, ...]:
    """A mode's power forms (Z × 4Z, :func:`_power_forms`) and, with a propagator, its sub-step forms and impulses (Z × (4Z + n_contacts))."""
    d, width = dynamics, system.xi_size + 5
    force = _in_z(_affine(d.force_matrix, 0.0, d.force_constant), width)
    friction = _in_z(_affine(d.friction_matrix, d.friction_ground, d.friction_constant), width)
    factors = _power_factors(system, force, friction)
    power = np.ascontiguousarray(_power_forms(factors))
    if propagator is None:
        return (power,)
    return power, np.concatenate([form.T for form in _sub_step_forms(factors, force, propagator)], axis=1)


def _read_out_rows(read_out: np.ndarray, rate: np.ndarray, width: int) -> np.ndarray:
    """Rows V and W acting on z = [x, w, 1] that give an affine read-out's values and rates (2 n × Z).

    For the affine maps ``read_out`` (G x + h a_g + g0: guards, monitors) and
    ``rate`` (ẋ = A x + B a_g + c): values V z = G x + h a_g + g0, rates
    W z = G A x + (G B) a_g + h ȧ_g + G c.
    """
    size = read_out.shape[1] - 2
    rates = _in_z(read_out[:, :size] @ rate, width)
    rates[:, size + 1] = read_out[:, size]
    return np.vstack([_in_z(read_out, width), rates])


def _total_bytes(arrays: tuple[np.ndarray, ...]) -> int:
    return sum(array.nbytes for array in arrays)


def _affine(matrix: np.ndarray, ground: np.ndarray | float, constant: np.ndarray) -> np.ndarray:
    """The engine's affine map [matrix | ground | constant] of ``matrix · x + ground a_g + constant``."""
    return np.column_stack([matrix, np.broadcast_to(ground, len(matrix)), constant])


def _power_factors(system: System, force: np.ndarray, friction: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The powers of the energy balance as bilinear forms (L z) · (R z) of z = [x, w, 1]: their factors (L, R).

    In ``ENERGY_TERMS`` order, W: the input power −a_g (ι · v), the
    damping power vᵀ C v, the friction power −Σ F_b ṡ_b over sliding bases
    (F_b the foundation's force on base b) and the impact power
    Σ F_p (h_p · v) over contacts. ``force`` and ``friction`` are the mode's
    contact and friction forces (rows acting on z).
    """
    n, width = system.n_dof, force.shape[1]
    velocity = np.zeros((n, width))
    velocity[:, n : 2 * n] = np.eye(n)
    ground = np.zeros((1, width))
    ground[0, width - 5] = 1.0  # z = [ξ, a_g, ȧ_g, ä_g, a⃛_g, 1]
    return [
        (ground, (-system.influence @ velocity)[None]),
        (velocity, system.damping @ velocity),
        (velocity[system.base_dofs], -friction),
        (system.element_load @ velocity, force),
    ]


def _power_forms(factors: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    """The quadratic forms P = Lᵀ R of the powers (:func:`_power_factors`), zᵀ P z, stacked and transposed (Z × 4Z)."""
    return np.concatenate([left.T @ right for left, right in factors]).T


def _sub_step_forms(factors: list[tuple[np.ndarray, np.ndarray]], force: np.ndarray, propagator: ModePropagator) -> list[np.ndarray]:
    """Energy terms and impulses of one exact sub-step as functions of z(t0).

    The 5-point Gauss–Legendre integral of a power (L z)·(R z) over a
    sub-step is z(t0)ᵀ Q z(t0) with Q = Σᵢ wᵢ (L Nᵢ)ᵀ (R Nᵢ) (Nᵢ the node
    propagators, wᵢ the weights): the quadrature of the dense flow, summed
    in closed form. The impulses are linear, r · z(t0).

    Returns
    -------
    list of np.ndarray
        Q of the four powers (Z × Z each, J) and the impulse rows of every
        contact (n_contacts × Z, N·s).
    """
    weights = 0.5 * propagator.step * GAUSS_WEIGHTS
    nodes = propagator.nodes
    width = nodes.shape[-1]
    forms = [(weights[:, None, None] * (left @ nodes)).reshape(-1, width).T @ (right @ nodes).reshape(-1, width) for left, right in factors]
    return [*forms, force @ np.tensordot(weights, nodes, 1)]


def _in_z(rows: np.ndarray, width: int) -> np.ndarray:
    """Affine rows [x-coefficients | a_g coefficient | constant] as rows acting on z = [x, w, 1]."""
    size = rows.shape[1] - 2
    out = np.zeros((len(rows), width))
    out[:, :size], out[:, size], out[:, width - 1] = rows[:, :size], rows[:, size], rows[:, size + 1]
    return out


def _placeholder(system: System, chebyshev_width: int, exact: bool) -> dict[str, np.ndarray]:
    """An empty slot of the :class:`Built` arrays (it matches no mode: its mode vector is invalid).

    Without ``exact`` the ``Propagators`` arrays are one column wide (the engine does not read them).
    """
    size, n_contacts, n_guards = system.xi_size, system.n_elements, max_guards(system)
    width = size + 5
    propagate = (width, engine.propagate_columns(size, n_guards, n_contacts, monitor_count(system))) if exact else (1, 1)
    return {
        "modes": np.full(mode_length(system), -9, dtype=np.int64), "ids": np.int64(0), "codes": np.zeros((3, n_guards), np.int64),
        "n_guards": np.int64(0), "substeps": np.int64(1), "rate": np.zeros((2 * system.n_dof, size + 2)),
        "guard": np.zeros((n_guards, size + 2)), "force": np.zeros((n_contacts, size + 2)), "monitor": np.zeros((monitor_count(system), size + 2)),
        "power": np.zeros((width, 4 * width)),
        "propagate": np.zeros(propagate), "chebyshev": np.zeros((width, chebyshev_width) if exact else (1, 1)),
        "step": np.float64(1.0),
    }
