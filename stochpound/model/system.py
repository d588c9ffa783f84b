"""The scene as one linear mechanical system: degrees of freedom and global matrices.

Degrees of freedom (DOFs) are, building by building, the floor displacements
u_{b,i} relative to the building's base, followed by the base's sliding
displacement s_b when the building is isolated (a fixed base has no s_b). With
q the DOF vector and v = q̇, the equations of motion (docs/model.md) read

    M q̈ + C q̇ + K q = −r a_g(t) + f_impact + f_friction

where M couples each floor with its base (the floor equation contains s̈_b,
the base equation contains Σ m_i ü_i), r holds the inertia of each DOF
(m_i for a floor, M_b + Σ m_i for a base), and K includes an optional restoring
stiffness of the base.

The *impact elements* are the contacts between buildings, then the walls.
Element p has penetration δ_p = g_p·q − d_p and acts on the structure with
the generalised force −F_p h_p, where h_p = g_p in the momentum-consistent
model and, for a contact, h_p is g_p without its base entries in
``study_compat`` mode (the study's base equation lacks Σ f).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, fields
from functools import cached_property, lru_cache

import numpy as np

from stochpound.model import laws
from stochpound.model.building import Building, storey_matrix
from stochpound.model.contact import Contact, effective_mass
from stochpound.model.wall import Wall
from stochpound.model.friction import SlidingBase
from stochpound.model.yielding import YieldingStorey, plastic_spring
from stochpound.model.scene import Scene


@dataclass(frozen=True)
class System:
    """Global DOF layout and constant matrices of a scene.

    Attributes
    ----------
    n_dof : int
        Number of DOFs N; the state is x = [q, v] of length 2N.
    floor_dofs : list of np.ndarray
        For each building, the DOF indices of its floors (floor 1 first).
    bases : tuple of SlidingBase
        The sliding bases, left to right (fixed bases have none).
    mass, stiffness, damping : np.ndarray
        M, K, C (N × N), kg, N/m, N·s/m.
    influence : np.ndarray
        r (N), kg: the ground-acceleration load is −r a_g.
    n_contacts : int
        Number of contacts between buildings: the first impact elements; the walls follow.
    element_gap, element_stiffness, element_damping : np.ndarray
        d_p (m), k_p (N/m), c_p (N·s/m) of each impact element.
    element_geometry : np.ndarray
        g_p as rows (n_elements × N): δ_p = g_p·q − d_p.
    element_load : np.ndarray
        h_p as rows (n_elements × N): generalised load −F_p h_p.
    element_tensile : np.ndarray of bool
        Which elements separate at δ = 0 (True) or at F = 0 (False).
    element_left, element_right : np.ndarray
        Rows (n_elements × N) giving the displacement relative to the ground
        of each element's left and right side (a wall's side is 0: it moves
        with the ground); g_p = left − right.
    element_law : tuple of str
        Each element's contact law (a name of :data:`stochpound.model.laws.CONTACT_LAWS`).
    element_restitution, element_mass : np.ndarray
        Each element's coefficient of restitution (NaN if none) and effective mass m_eff (kg).
    total_displacement : np.ndarray
        Y (n_floors_total × N): total displacements y = s + u of every floor, in DOF order.
    initial_state : np.ndarray
        x(0) = [q(0), v(0)] from the buildings' initial conditions.
    storey_stiffness, storey_damping : list of np.ndarray
        Each building's storey k_i (N/m) and c_i (N·s/m).
    demands : bool
        Whether runs monitor the demand parameters (:mod:`stochpound.model.demands`).
    readout_elements, readout_bases : np.ndarray of int
        The read-outs f: the forces of nonlinear laws, which enter a mode's
        equations as inputs (ẋ = A x + E f + B a_g + c; the engine's state is
        ξ = [x, f]): first the elements with a nonlinear contact law, then the
        sliding bases with velocity-dependent friction (their indices).
    storeys : tuple of YieldingStorey
        The bilinear storeys (:mod:`stochpound.model.yielding`), building by
        building; their plastic and accumulated plastic drifts are the last
        DOFs (no mass), and K holds their elastic–perfectly-plastic springs.
    """

    n_dof: int
    floor_dofs: list[np.ndarray]
    bases: tuple[SlidingBase, ...]
    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    influence: np.ndarray
    n_contacts: int
    element_gap: np.ndarray
    element_stiffness: np.ndarray
    element_damping: np.ndarray
    element_geometry: np.ndarray
    element_load: np.ndarray
    element_tensile: np.ndarray
    element_left: np.ndarray
    element_right: np.ndarray
    element_law: tuple[str, ...]
    element_restitution: np.ndarray
    element_mass: np.ndarray
    total_displacement: np.ndarray
    initial_state: np.ndarray
    storey_stiffness: list[np.ndarray]
    storey_damping: list[np.ndarray]
    demands: bool
    readout_elements: np.ndarray
    readout_bases: np.ndarray
    storeys: tuple[YieldingStorey, ...] = ()

    @property
    def n_elements(self) -> int:
        """Number of impact elements (contacts, then walls)."""
        return len(self.element_gap)

    @property
    def n_readouts(self) -> int:
        """Number n_f of read-outs (nonlinear elements, then velocity-dependent bases)."""
        return len(self.readout_elements) + len(self.readout_bases)

    @property
    def nonlinear(self) -> np.ndarray:
        """Which elements have a nonlinear contact law (bool per element)."""
        return np.array([not laws.contact_law(law).piecewise_linear for law in self.element_law], dtype=bool)

    @property
    def xi_size(self) -> int:
        """Length S' of ξ = [x, f]: 2N + n_f."""
        return 2 * self.n_dof + self.n_readouts

    @property
    def building_base_dofs(self) -> list[int | None]:
        """For each building, the DOF of its sliding base, or None for a fixed base."""
        dofs: list[int | None] = [None] * len(self.floor_dofs)
        for base in self.bases:
            dofs[base.building] = base.dof
        return dofs

    @property
    def base_dofs(self) -> np.ndarray:
        """The DOF of every sliding base (int64, in base order)."""
        return np.array([base.dof for base in self.bases], dtype=np.int64)

    @cached_property
    def fingerprint(self) -> bytes:
        """Digest of every matrix and layout entry (equal systems share propagators)."""
        digest = hashlib.blake2b(digest_size=20)
        for item in fields(self):
            value = getattr(self, item.name)
            if item.name == "storeys" and not value:  # an elastic system's digest is the one it had before yielding storeys
                continue
            if isinstance(value, (tuple, int, bool)):  # the sliding bases and storeys (frozen dataclasses of numbers), the laws, counts and flags
                digest.update(f"{item.name}{value!r}".encode())
                continue
            for array in value if isinstance(value, list) else [value]:
                array = np.ascontiguousarray(array)
                digest.update(f"{item.name}{array.dtype}{array.shape}".encode())
                digest.update(array.tobytes())
        return digest.digest()


def build_system(scene: Scene, demands: bool = False) -> System:
    """Assemble the DOF layout and the global matrices of ``scene`` (cached: runs of one structure share its system).

    The system depends on the buildings, contacts, walls, g and
    ``study_compat`` only, not on the motion; its arrays are shared and must
    not be changed. With ``demands`` its runs also monitor the demand
    parameters (floor accelerations, storey drifts and shears).
    """
    return _build_system(scene.buildings, scene.contacts, scene.walls, scene.g, scene.study_compat, demands)


@lru_cache(maxsize=16)
def _build_system(buildings: tuple[Building, ...], contacts: tuple[Contact, ...], walls: tuple[Wall, ...], g: float, study_compat: bool,
                  demands: bool) -> System:
    floor_dofs, base_dofs, n_dof = _layout(buildings)
    storeys = _yielding_storeys(buildings, floor_dofs, n_dof)
    n_dof += 2 * len(storeys)
    mass = np.zeros((n_dof, n_dof))
    stiffness = np.zeros((n_dof, n_dof))
    damping = np.zeros((n_dof, n_dof))
    influence = np.zeros(n_dof)
    total = np.zeros((sum(b.n_floors for b in buildings), n_dof))
    initial = np.zeros(2 * n_dof)
    bases = []
    row = 0
    for b, building in enumerate(buildings):
        floors, base = floor_dofs[b], base_dofs[b]
        m = np.asarray(building.mass, float)
        block = np.ix_(floors, floors)
        mass[block] = np.diag(m)
        stiffness[block] = storey_matrix(np.asarray(building.stiffness, float))
        if building.p_delta:
            stiffness[block] += storey_matrix(building.geometric_stiffness(g))
        damping[block] = storey_matrix(np.asarray(building.damping, float))
        influence[floors] = m
        for i, dof in enumerate(floors):
            total[row + i, dof] = 1.0
        initial[floors] = building.initial.displacement
        initial[n_dof + floors] = building.initial.velocity
        if base is not None:
            mass[floors, base] = m
            mass[base, floors] = m
            mass[base, base] = building.total_mass
            stiffness[base, base] = building.base.restoring(g * building.total_mass)
            influence[base] = building.total_mass
            total[row : row + building.n_floors, base] = 1.0
            initial[base] = building.initial.base_displacement
            initial[n_dof + base] = building.initial.base_velocity
            bases.append(SlidingBase(b, base, g * building.total_mass, building.base.mu, building.base.mu_static, building.base.mu_fast,
                                     building.base.mu_rate))
        row += building.n_floors
    for storey in storeys:  # α k of the storey stays in the tridiagonal block, (1 − α) k goes through its plastic element
        drift = storey.drift_row(n_dof)
        stiffness += plastic_spring(storey, n_dof) - storey.plastic_stiffness * np.outer(drift, drift)  # exactly 0 on the floors
    levels = _level_rows(buildings, floor_dofs, base_dofs, n_dof)
    left, right, load = _element_rows(contacts, walls, study_compat, levels, base_dofs)
    elements = (*contacts, *walls)
    return System(
        n_dof=n_dof,
        floor_dofs=floor_dofs,
        bases=tuple(bases),
        mass=mass,
        stiffness=stiffness,
        damping=damping,
        influence=influence,
        n_contacts=len(contacts),
        element_gap=np.array([e.gap for e in elements], float),
        element_stiffness=np.array([e.stiffness for e in elements], float),
        element_damping=np.array([e.damping for e in elements], float),
        element_geometry=left - right,
        element_load=load,
        element_tensile=np.array([e.tensile for e in elements], bool),
        element_left=left,
        element_right=right,
        element_law=tuple(e.law for e in elements),
        element_restitution=np.array([np.nan if e.restitution is None else e.restitution for e in elements], float),
        element_mass=_element_masses(buildings, contacts, walls),
        total_displacement=total,
        initial_state=initial,
        storey_stiffness=[np.asarray(b.stiffness, float) for b in buildings],
        storey_damping=[np.asarray(b.damping, float) for b in buildings],
        demands=demands,
        readout_elements=np.array([p for p, e in enumerate(elements) if not laws.contact_law(e.law).piecewise_linear], dtype=np.int64),
        readout_bases=np.array([i for i, base in enumerate(bases) if not laws.friction_law(base.friction_law).piecewise_linear], dtype=np.int64),
        storeys=storeys,
    )


def _yielding_storeys(buildings: tuple[Building, ...], floor_dofs: list[np.ndarray], n_dof: int) -> tuple[YieldingStorey, ...]:
    """The bilinear storeys of ``buildings``, their plastic DOFs numbered from ``n_dof`` (z and p of each storey in turn)."""
    storeys = []
    for b, building in enumerate(buildings):
        if building.yield_force is None:
            continue
        floors = floor_dofs[b].tolist()
        for i, (k, force) in enumerate(zip(building.stiffness, building.yield_force)):
            z = n_dof + 2 * len(storeys)
            storeys.append(YieldingStorey(b, i, floors[i], floors[i - 1] if i > 0 else -1, z, z + 1, float(k), float(force), float(building.hardening)))
    return tuple(storeys)


def _element_masses(buildings: tuple[Building, ...], contacts: tuple[Contact, ...], walls: tuple[Wall, ...]) -> np.ndarray:
    """Each impact element's effective mass m_eff (kg): m1 m2/(m1 + m2) for a contact, the level's mass for a wall."""
    masses = [effective_mass(buildings[c.left].mass[c.left_floor - 1], buildings[c.right].mass[c.right_floor - 1]) for c in contacts]
    masses += [buildings[w.building].base.mass if w.level == 0 else buildings[w.building].mass[w.level - 1] for w in walls]
    return np.array(masses, float)


def _layout(buildings: tuple[Building, ...]) -> tuple[list[np.ndarray], list[int | None], int]:
    """Each building's floor DOFs and base DOF (None for a fixed base), and the number of DOFs."""
    floor_dofs, base_dofs, n_dof = [], [], 0
    for building in buildings:
        floor_dofs.append(np.arange(n_dof, n_dof + building.n_floors))
        n_dof += building.n_floors
        base_dofs.append(n_dof if building.base is not None else None)
        n_dof += building.base is not None
    return floor_dofs, base_dofs, n_dof


def _level_rows(buildings: tuple[Building, ...], floor_dofs: list[np.ndarray], base_dofs: list[int | None], n_dof: int) -> list[np.ndarray]:
    """For each building, rows (levels × N) giving the displacement relative to the ground of its base (level 0: s, or 0 if fixed) and floors (s + u_i)."""
    levels = []
    for building, floors, base in zip(buildings, floor_dofs, base_dofs):
        rows = np.zeros((building.n_floors + 1, n_dof))
        rows[np.arange(1, building.n_floors + 1), floors] = 1.0
        if base is not None:
            rows[:, base] = 1.0
        levels.append(rows)
    return levels


def _element_rows(contacts: tuple[Contact, ...], walls: tuple[Wall, ...], study_compat: bool, levels: list[np.ndarray],
                  base_dofs: list[int | None]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each impact element's left-side and right-side displacement rows and its load row h (n_elements × N each)."""
    n_dof = levels[0].shape[1]
    left, right = np.zeros((len(contacts) + len(walls), n_dof)), np.zeros((len(contacts) + len(walls), n_dof))
    for p, contact in enumerate(contacts):
        left[p], right[p] = levels[contact.left][contact.left_floor], levels[contact.right][contact.right_floor]
    for p, wall in enumerate(walls, start=len(contacts)):
        (left if wall.side > 0 else right)[p] = levels[wall.building][wall.level]
    load = left - right
    if study_compat:  # the study's base equation lacks the contacts' forces (walls are not the study's)
        bases = [dof for dof in base_dofs if dof is not None]
        load[: len(contacts), bases] = 0.0
    return left, right, load
