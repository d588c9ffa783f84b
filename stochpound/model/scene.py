"""The scene: buildings in a row, their bases, the contact elements and the ground motion.

A :class:`Scene` is a validated, immutable description of one physical
situation (MODEL.md §1–4). It is built from a scene file by
:func:`stochpound.model.scene_file.load_scene`, or directly in Python. All
quantities are SI (kg, N/m, N·s/m, m, s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from stochpound.motions.ground import GroundMotion


@dataclass(frozen=True)
class Base:
    """A flat sliding (friction) base under a building.

    Attributes
    ----------
    mass : float
        Base mass M_b, kg (> 0).
    mu : float
        Kinetic friction coefficient (>= 0). ``0`` makes a frictionless,
        free base with no stick state.
    mu_static : float
        Static friction coefficient (>= mu); the base sticks while the
        friction force it needs stays within ``mu_static * W``.
    restoring_stiffness : float
        Optional restoring stiffness k_r, N/m (a friction pendulum has W/R).
    """

    mass: float
    mu: float
    mu_static: float
    restoring_stiffness: float = 0.0

    @property
    def frictionless(self) -> bool:
        """True when the base has no friction (a free degree of freedom)."""
        return self.mu == 0.0 and self.mu_static == 0.0


@dataclass(frozen=True)
class InitialState:
    """Initial conditions of one building (all zero by default).

    Attributes
    ----------
    displacement, velocity : tuple of float
        Floor displacements u (m) and velocities (m/s) relative to the base.
    base_displacement, base_velocity : float
        Sliding displacement s (m) and velocity (m/s) of the base; only for
        a sliding base.
    """

    displacement: tuple[float, ...]
    velocity: tuple[float, ...]
    base_displacement: float = 0.0
    base_velocity: float = 0.0


@dataclass(frozen=True)
class Building:
    """A shear building: lumped floor masses joined by storey springs and dashpots.

    Attributes
    ----------
    name : str
        Unique name of the building in its scene.
    mass : tuple of float
        Floor masses m_i, kg, floor 1 (lowest) upwards.
    stiffness : tuple of float
        Storey stiffnesses k_i, N/m; storey i joins floor i-1 (the base) to floor i.
    damping : tuple of float
        Storey dashpots c_i, N·s/m (derived from ``damping_ratio`` when that is given).
    damping_ratio : float or None
        Mode-1 damping ratio of a stiffness-proportional damping C = a1·K,
        when the damping was specified that way.
    base : Base or None
        The sliding base; ``None`` for a fixed base.
    initial : InitialState
        Initial conditions.
    """

    name: str
    mass: tuple[float, ...]
    stiffness: tuple[float, ...]
    damping: tuple[float, ...]
    damping_ratio: float | None = None
    base: Base | None = None
    initial: InitialState | None = None

    @property
    def n_floors(self) -> int:
        """Number of floors (storeys)."""
        return len(self.mass)

    @property
    def isolated(self) -> bool:
        """True when the building stands on a sliding base."""
        return self.base is not None

    @property
    def total_mass(self) -> float:
        """Mass of the floors plus the base, kg."""
        return float(sum(self.mass)) + (self.base.mass if self.base else 0.0)


@dataclass(frozen=True)
class Contact:
    """A linear Kelvin–Voigt impact element between neighbouring floors.

    Attributes
    ----------
    left, right : int
        Indices (0-based, in the scene's building list) of the left building
        and its right-hand neighbour (``right == left + 1``).
    left_floor, right_floor : int
        Floors (1-based) that can collide.
    gap : float
        At-rest gap d, m (>= 0). Penetration is δ = y_left − y_right − d.
    stiffness : float
        Impact spring k_imp, N/m (> 0).
    damping : float
        Impact dashpot c_imp, N·s/m (>= 0); derived from ``restitution`` when given.
    restitution : float or None
        Coefficient of restitution r in (0, 1] the damping was derived from.
    tensile : bool
        True: the element separates when δ returns to 0 and may pull just
        before (the study's choice). False: it separates when its force
        returns to 0 and never pulls.
    """

    left: int
    left_floor: int
    right: int
    right_floor: int
    gap: float
    stiffness: float
    damping: float
    restitution: float | None = None
    tensile: bool = True


@dataclass(frozen=True)
class Scene:
    """One physical situation: buildings left to right, contacts, ground motion.

    Attributes
    ----------
    buildings : tuple of Building
        The row, left to right.
    contacts : tuple of Contact
        Contact elements between neighbours.
    motion : GroundMotion
        The ground acceleration shared by all buildings.
    g : float
        Gravitational acceleration, m/s² (weights of sliding buildings).
    study_compat : bool
        Drop the impact forces from the base equation, as the reference study did.
    source : str
        Where the scene came from (file name or "python"), for provenance.
    """

    buildings: tuple[Building, ...]
    contacts: tuple[Contact, ...]
    motion: GroundMotion
    g: float = 9.81
    study_compat: bool = False
    source: str = field(default="python", compare=False)

    @property
    def building_names(self) -> list[str]:
        """Names of the buildings, left to right."""
        return [b.name for b in self.buildings]

    @property
    def max_floors(self) -> int:
        """Largest number of floors of any building."""
        return max(b.n_floors for b in self.buildings)


def restitution_damping_ratio(restitution: float) -> float:
    """Damping ratio ξ of a Kelvin–Voigt element with coefficient of restitution r.

    ξ = −ln r / sqrt(π² + (ln r)²) (Anagnostopoulos 1988); ξ = 0 for r = 1.
    """
    log_r = math.log(restitution)
    return -log_r / math.sqrt(math.pi**2 + log_r**2)


def impact_damping(stiffness: float, restitution: float, mass_1: float, mass_2: float) -> float:
    """Impact dashpot c_imp = 2 ξ sqrt(k_imp m1 m2 / (m1 + m2)), N·s/m."""
    effective_mass = mass_1 * mass_2 / (mass_1 + mass_2)
    return 2.0 * restitution_damping_ratio(restitution) * math.sqrt(stiffness * effective_mass)


def storey_matrix(storey_values: np.ndarray) -> np.ndarray:
    """Tridiagonal shear-building matrix (stiffness or damping) from storey values.

    Storey i joins floor i-1 to floor i; floor 0 is the base.
    """
    n = len(storey_values)
    matrix = np.zeros((n, n))
    for i, value in enumerate(storey_values):
        matrix[i, i] += value
        if i > 0:
            matrix[i - 1, i - 1] += value
            matrix[i - 1, i] -= value
            matrix[i, i - 1] -= value
    return matrix


def fixed_base_frequencies(mass: np.ndarray, stiffness: np.ndarray) -> np.ndarray:
    """Natural circular frequencies (rad/s, ascending) of the fixed-base building."""
    from scipy.linalg import eigh

    eigenvalues = eigh(storey_matrix(np.asarray(stiffness, float)), np.diag(mass), eigvals_only=True)
    return np.sqrt(np.clip(eigenvalues, 0.0, None))


def stiffness_proportional_damping(mass: np.ndarray, stiffness: np.ndarray, ratio: float) -> np.ndarray:
    """Storey dashpots of C = a1·K with damping ``ratio`` in mode 1 (a1 = 2ζ1/ω1), N·s/m."""
    omega_1 = fixed_base_frequencies(mass, stiffness)[0]
    return 2.0 * ratio / omega_1 * np.asarray(stiffness, float)
