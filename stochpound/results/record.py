"""What one run recorded: samples, impacts, the energy terms and the event counts.

The event engine (:mod:`stochpound.solvers.engine`) writes the state and the
running energy terms at every output time, the mode in force there and one
row per finished impact; :func:`stochpound.solvers.driver.EngineRun.record`
turns its arrays into a :class:`Recorder`, which adds what follows from the
samples and their modes: contact forces, base friction forces and base states.

Energy terms (J, relative-motion energy balance, docs/model.md):
``input`` (work of the ground-acceleration load), ``damping`` (storey
dashpots), ``friction`` (base friction) and ``impact`` (work absorbed by the
impact elements), each the integral of a power over the run.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from stochpound.model.demands import DEMANDS
from stochpound.model.friction import FREE
from stochpound.model.modes import (ModeDynamics, contact_displacement_monitors, demand_monitors_start, monitor_count, monitored_contacts,
                                     storey_monitors_start)
from stochpound.model.system import System
from stochpound.motions.ground import GroundMotion

ENERGY_TERMS = ("input", "damping", "friction", "impact")


@dataclass
class Impact:
    """One impact (a closed phase of one contact).

    Attributes
    ----------
    contact : int
        The contact's index.
    start, end : float
        When it began and ended, s (``end`` is the end of the motion if it was still closed).
    onset_velocity : float
        Rate of penetration at onset, m/s.
    in_phase : bool
        Both floors moving the same way at onset.
    peak_force, peak_time : float
        Largest contact force (N) and when it happened (s), located on the solution.
    impulse : float
        Time integral of the contact force, N·s.
    complete : bool
        The impact ended before the end of the motion.
    """

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
class Recorder:
    """The outputs of one run at the motion's sample times.

    Attributes
    ----------
    system : System
    motion : GroundMotion
    states : np.ndarray
        ξ = [q, v, f] at every output time (n_times × S'), m, m/s and N (the
        read-outs f of nonlinear laws, :mod:`stochpound.model.readouts`).
    forces, friction, base_states : np.ndarray
        Impact element forces (N: contacts, then walls), force of the foundation on each sliding base (N,
        positive to the right) and base states
        (:mod:`stochpound.model.friction`; a free base's is the sign of its
        velocity) at every output time (time × contact or base), filled by
        :meth:`sample_at`.
    energy_history : np.ndarray
        The energy terms (rows in ``ENERGY_TERMS`` order, J) at every
        output time; ``energy`` maps each term's name to its row.
    impacts : list of Impact
        Every impact, in order of start (then contact).
    peaks : np.ndarray
        The monitors' largest values over the run and when they happened
        (rows: value, time in s), located on the solution: each impact
        element's closure y_left − y_right (m), then ± the displacement
        relative to the ground of the two floors of each contact with an
        infinite gap (m; :func:`stochpound.model.modes.monitored_contacts`), then ± the
        demand parameters when the system monitors them
        (:func:`stochpound.model.modes.monitor_rows`).
    demands : dict[str, np.ndarray]
        When the system monitors demands: each parameter of
        :data:`stochpound.model.demands.DEMANDS` at every floor and output
        time (floor, in the order of the system's floors × time), filled by
        :meth:`sample_at`.
    """

    system: System
    motion: GroundMotion
    states: np.ndarray = field(init=False)
    forces: np.ndarray = field(init=False)
    friction: np.ndarray = field(init=False)
    base_states: np.ndarray = field(init=False)
    energy: dict[str, np.ndarray] = field(init=False)
    energy_history: np.ndarray = field(init=False)
    impacts: list[Impact] = field(default_factory=list)
    peaks: np.ndarray = field(init=False)
    demands: dict[str, np.ndarray] = field(init=False)

    def __post_init__(self) -> None:
        n_times = len(self.motion.times)
        self.states = np.zeros((n_times, self.system.xi_size))
        self.forces = np.zeros((n_times, self.system.n_elements))
        self.friction = np.zeros((n_times, len(self.system.base_dofs)))
        self.base_states = np.zeros((n_times, len(self.system.base_dofs)), dtype=np.int8)
        self.energy_history = np.zeros((len(ENERGY_TERMS), n_times))
        self.energy = dict(zip(ENERGY_TERMS, self.energy_history))
        self.peaks = np.full((2, monitor_count(self.system)), np.nan)
        floors = len(self.system.total_displacement)
        self.demands = {name: np.zeros((floors, n_times)) for name in DEMANDS} if self.system.demands else {}

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
        for b, (base, state) in enumerate(zip(self.system.bases, dynamics.mode.base)):
            self.base_states[indices, b] = np.sign(x[:, self.system.n_dof + base.dof]) if state == FREE else state
        if self.demands:  # the demand monitors' + rows (stochpound.model.modes.monitor_rows)
            floors, first = len(self.system.total_displacement), demand_monitors_start(self.system)
            rows = slice(first, first + len(DEMANDS) * floors)
            values = x @ dynamics.monitor_matrix[rows].T + np.outer(ground, dynamics.monitor_ground[rows]) + dynamics.monitor_constant[rows]
            for name, value in zip(DEMANDS, values.T.reshape(len(DEMANDS), floors, len(indices))):
                self.demands[name][:, indices] = value

    def displacements(self) -> tuple[np.ndarray, np.ndarray]:
        """Floor displacements u relative to their base (building × floor × time, NaN above a building's top floor) and sliding displacements s (building × time, 0 for a fixed base), m."""
        floors = self.system.floor_dofs
        q = self.states[:, : self.system.n_dof]
        relative = np.full((len(floors), max(len(dofs) for dofs in floors), len(q)), np.nan)
        for b, dofs in enumerate(floors):
            relative[b, : len(dofs)] = q[:, dofs].T
        return relative, self.by_building(q[:, self.system.base_dofs])

    def closure(self) -> np.ndarray:
        """Each impact element's closure y_left − y_right at the samples (element × time), m (a wall's side is 0)."""
        return self.system.element_geometry @ self.states[:, : self.system.n_dof].T

    def by_floor(self, per_floor: np.ndarray) -> np.ndarray:
        """Values of every floor (floor in system order × ...) as building × floor × ..., NaN above a building's top floor."""
        floors = self.system.floor_dofs
        values = np.full((len(floors), max(len(dofs) for dofs in floors)) + per_floor.shape[1:], np.nan)
        first = 0
        for b, dofs in enumerate(floors):
            values[b, : len(dofs)] = per_floor[first : first + len(dofs)]
            first += len(dofs)
        return values

    def demand_peaks(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Each demand parameter's largest absolute value over the run and when (floor in system order), located on the solution."""
        floors, n, first = len(self.system.total_displacement), len(DEMANDS) * len(self.system.total_displacement), demand_monitors_start(self.system)
        larger = _larger(self.peaks[:, first : first + n], self.peaks[:, first + n : first + 2 * n])
        return {name: (larger[0, i * floors : (i + 1) * floors], larger[1, i * floors : (i + 1) * floors]) for i, name in enumerate(DEMANDS)}

    def contact_displacement_peaks(self) -> tuple[np.ndarray, np.ndarray]:
        """The largest abs(y) over the run of each contact's left and right floor (y = s + u relative to the ground), located on the solution.

        Only a contact with an infinite gap is monitored
        (:func:`stochpound.model.modes.monitored_contacts`): the separation
        rules take u1 and u2 from contact-free runs. A contact with a finite
        gap gets NaN.

        Returns
        -------
        left, right : np.ndarray
            Rows value (m) and time (s), one column per contact: the separation rules' u1 and u2.
        """
        monitored = monitored_contacts(self.system)
        signed = self.peaks[:, contact_displacement_monitors(self.system)].reshape(2, len(monitored), 4)
        left, right = np.full((2, self.system.n_contacts), np.nan), np.full((2, self.system.n_contacts), np.nan)
        left[:, monitored], right[:, monitored] = _larger(signed[:, :, 0], signed[:, :, 1]), _larger(signed[:, :, 2], signed[:, :, 3])
        return left, right

    def by_building(self, per_base: np.ndarray) -> np.ndarray:
        """Values of the sliding bases over time (time × base) as building × time, 0 for fixed bases."""
        values = np.zeros((len(self.system.floor_dofs), len(per_base)), dtype=per_base.dtype)
        values[[base.building for base in self.system.bases]] = per_base.T
        return values

    def storey_drift_peaks(self) -> np.ndarray:
        """The largest abs(drift) over the run of each yielding storey (``System.storeys`` order) and when: rows value (m), time (s), located on the solution."""
        first, n = storey_monitors_start(self.system), len(self.system.storeys)
        return _larger(self.peaks[:, first : first + n], self.peaks[:, first + n : first + 2 * n])

    def plastic_drifts(self) -> tuple[np.ndarray, np.ndarray]:
        """Each yielding storey's plastic drift z and accumulated plastic drift p = Σ|Δz| at the samples (storey × time, m)."""
        storeys = self.system.storeys
        return (self.states[:, [s.plastic_dof for s in storeys]].T.reshape(len(storeys), -1),
                self.states[:, [s.accumulated_dof for s in storeys]].T.reshape(len(storeys), -1))

    def kinetic_and_strain(self) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic energy ½ vᵀMv and storey/restoring strain energy ½ qᵀKq at the samples, J."""
        n = self.system.n_dof
        q, v = self.states[:, :n], self.states[:, n : 2 * n]
        kinetic = 0.5 * np.einsum("ti,ti->t", v @ self.system.mass, v)
        strain = 0.5 * np.einsum("ti,ti->t", q @ self.system.stiffness, q)
        return kinetic, strain


def _larger(plus: np.ndarray, minus: np.ndarray) -> np.ndarray:
    """The peaks (rows value, time) of + and − a read-out combined into the peaks of its absolute value."""
    return np.where(plus[0] >= minus[0], plus, minus)
