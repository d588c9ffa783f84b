"""The scene as one linear mechanical system: degrees of freedom and global matrices.

Degrees of freedom (DOFs) are, building by building, the floor displacements
u_{b,i} relative to the building's base, followed by the base's sliding
displacement s_b when the building is isolated (a fixed base has no s_b). With
q the DOF vector and v = q̇, the equations of motion (docs/model.md) read

    M q̈ + C q̇ + K q = −r a_g(t) + f_impact + f_friction

where M couples each floor with its base (the floor equation contains s̈_b,
the base equation contains Σ m_i ü_i), r holds the inertia of each DOF
(m_i for a floor, M_b + Σ m_i for a base), and K includes an optional restoring
stiffness of the base. Contact p has penetration δ_p = g_p·q − d_p and acts on
the structure with the generalised force −F_p h_p, where h_p = g_p in the
momentum-consistent model and h_p is g_p without its base entries in
``study_compat`` mode (the study's base equation lacks Σ f).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, fields
from functools import cached_property, lru_cache

import numpy as np

from stochpound.model.building import Building, storey_matrix
from stochpound.model.contact import Contact
from stochpound.model.friction import SlidingBase
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
    contact_gap, contact_stiffness, contact_damping : np.ndarray
        d_p (m), k_p (N/m), c_p (N·s/m) of each contact.
    contact_geometry : np.ndarray
        g_p as rows (n_contacts × N): δ_p = g_p·q − d_p.
    contact_load : np.ndarray
        h_p as rows (n_contacts × N): generalised load −F_p h_p.
    contact_tensile : np.ndarray of bool
        Which contacts separate at δ = 0 (True) or at F = 0 (False).
    total_displacement : np.ndarray
        Y (n_floors_total × N): total displacements y = s + u of every floor, in DOF order.
    initial_state : np.ndarray
        x(0) = [q(0), v(0)] from the buildings' initial conditions.
    contact_rows : np.ndarray of int
        (n_contacts × 2): rows of ``total_displacement`` of each contact's left and right floor.
    """

    n_dof: int
    floor_dofs: list[np.ndarray]
    bases: tuple[SlidingBase, ...]
    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    influence: np.ndarray
    contact_gap: np.ndarray
    contact_stiffness: np.ndarray
    contact_damping: np.ndarray
    contact_geometry: np.ndarray
    contact_load: np.ndarray
    contact_tensile: np.ndarray
    total_displacement: np.ndarray
    initial_state: np.ndarray
    contact_rows: np.ndarray

    @property
    def n_contacts(self) -> int:
        """Number of contact elements."""
        return len(self.contact_gap)

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
            if isinstance(value, tuple):  # the sliding bases: frozen dataclasses of numbers
                digest.update(repr(value).encode())
                continue
            for array in value if isinstance(value, list) else [value]:
                array = np.ascontiguousarray(array)
                digest.update(f"{item.name}{array.dtype}{array.shape}".encode())
                digest.update(array.tobytes())
        return digest.digest()

    @property
    def contact_floor_velocity(self) -> np.ndarray:
        """Rows (2·n_contacts × 2N) giving ẏ of the left, then the right floor of each contact."""
        rows = self.total_displacement[self.contact_rows.ravel()]
        return np.hstack([np.zeros_like(rows), rows])


def build_system(scene: Scene) -> System:
    """Assemble the DOF layout and the global matrices of ``scene`` (cached: runs of one structure share its system).

    The system depends on the buildings, contacts, g and ``study_compat``
    only, not on the motion; its arrays are shared and must not be changed.
    """
    return _build_system(scene.buildings, scene.contacts, scene.g, scene.study_compat)


@lru_cache(maxsize=16)
def _build_system(buildings: tuple[Building, ...], contacts: tuple[Contact, ...], g: float, study_compat: bool) -> System:
    floor_dofs, base_dofs, n_dof = _layout(buildings)
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
            stiffness[base, base] = building.base.restoring_stiffness
            influence[base] = building.total_mass
            total[row : row + building.n_floors, base] = 1.0
            initial[base] = building.initial.base_displacement
            initial[n_dof + base] = building.initial.base_velocity
            bases.append(SlidingBase(b, base, g * building.total_mass, building.base.mu, building.base.mu_static))
        row += building.n_floors
    geometry, load = _contact_vectors(contacts, study_compat, floor_dofs, base_dofs, n_dof)
    return System(
        n_dof=n_dof,
        floor_dofs=floor_dofs,
        bases=tuple(bases),
        mass=mass,
        stiffness=stiffness,
        damping=damping,
        influence=influence,
        contact_gap=np.array([c.gap for c in contacts], float),
        contact_stiffness=np.array([c.stiffness for c in contacts], float),
        contact_damping=np.array([c.damping for c in contacts], float),
        contact_geometry=geometry,
        contact_load=load,
        contact_tensile=np.array([c.tensile for c in contacts], bool),
        total_displacement=total,
        initial_state=initial,
        contact_rows=_contact_rows(buildings, contacts),
    )


def _layout(buildings: tuple[Building, ...]) -> tuple[list[np.ndarray], list[int | None], int]:
    """Each building's floor DOFs and base DOF (None for a fixed base), and the number of DOFs."""
    floor_dofs, base_dofs, n_dof = [], [], 0
    for building in buildings:
        floor_dofs.append(np.arange(n_dof, n_dof + building.n_floors))
        n_dof += building.n_floors
        base_dofs.append(n_dof if building.base is not None else None)
        n_dof += building.base is not None
    return floor_dofs, base_dofs, n_dof


def _contact_vectors(contacts: tuple[Contact, ...], study_compat: bool, floor_dofs: list[np.ndarray], base_dofs: list[int | None],
                     n_dof: int) -> tuple[np.ndarray, np.ndarray]:
    """Each contact's geometry row g and load row h (h without base entries when ``study_compat``)."""
    geometry = np.zeros((len(contacts), n_dof))
    load = np.zeros((len(contacts), n_dof))
    for p, contact in enumerate(contacts):
        for building, floor, sign in ((contact.left, contact.left_floor, 1.0), (contact.right, contact.right_floor, -1.0)):
            geometry[p, floor_dofs[building][floor - 1]] += sign
            load[p, floor_dofs[building][floor - 1]] += sign
            if base_dofs[building] is not None:
                geometry[p, base_dofs[building]] += sign
                if not study_compat:
                    load[p, base_dofs[building]] += sign
    return geometry, load


def _contact_rows(buildings: tuple[Building, ...], contacts: tuple[Contact, ...]) -> np.ndarray:
    """Rows of the total-displacement map of each contact's left and right floors."""
    first_row = np.cumsum([0] + [b.n_floors for b in buildings])
    rows = [(first_row[c.left] + c.left_floor - 1, first_row[c.right] + c.right_floor - 1) for c in contacts]
    return np.array(rows, dtype=int).reshape(-1, 2)
