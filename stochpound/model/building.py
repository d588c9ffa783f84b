"""Shear buildings: lumped floor masses joined by storey springs and dashpots.

Scene keys (``[[building]]``): ``name``, ``mass`` (kg per floor, floor 1
upwards), ``stiffness`` (N/m per storey), ``damping`` (N·s/m per storey) or
``damping_ratio`` (stiffness-proportional damping C = a₁K with that ratio
in mode 1), ``base`` (a sliding base, :mod:`stochpound.model.friction`;
none: a fixed base), ``initial`` (initial conditions) and ``storey_height``
(m per storey, optional: storey drift ratios), ``yield_force`` (N per
storey, optional: bilinear yielding storeys, :mod:`stochpound.model.yielding`)
and ``hardening`` (their post-yield to elastic stiffness ratio α, default 0),
``p_delta`` (true: each storey gains the geometric stiffness −W/h of the
weight W above it, needs ``storey_height``).
Storey i joins floor i − 1 (floor 0 is the base) to floor i.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
import numpy as np
from scipy.linalg import eigh

from stochpound._errors import SceneError
from stochpound.model.fields import TomlTable
from stochpound.model.friction import Base, base_from_table

BUILDING_KEYS = {"name", "mass", "stiffness", "damping", "damping_ratio", "base", "initial", "storey_height", "yield_force", "hardening", "p_delta"}
INITIAL_KEYS = {"displacement", "velocity", "base_displacement", "base_velocity"}


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
        The sliding base; ``None`` for a fixed base (the one encoding of a fixed base).
    initial : InitialState
        Initial conditions.
    storey_height : tuple of float or None
        Storey heights h_i, m (for storey drift ratios), when given.
    yield_force : tuple of float or None
        Storey yield shears F_y,i, N (bilinear storeys, :mod:`stochpound.model.yielding`); None: elastic storeys.
    hardening : float
        Post-yield to elastic stiffness ratio α of the bilinear storeys (0 ≤ α < 1; 0: elastic–perfectly plastic).
    p_delta : bool
        Whether each storey i carries the geometric stiffness −W_i / h_i of the
        weight W_i = g Σ_{j ≥ i} m_j above it (P-Δ; needs ``storey_height``).
    """

    name: str
    mass: tuple[float, ...]
    stiffness: tuple[float, ...]
    damping: tuple[float, ...]
    damping_ratio: float | None = None
    base: Base | None = None
    initial: InitialState | None = None
    storey_height: tuple[float, ...] | None = None
    yield_force: tuple[float, ...] | None = None
    hardening: float = 0.0
    p_delta: bool = False

    def geometric_stiffness(self, g: float) -> np.ndarray:
        """Each storey's P-Δ stiffness −W_i / h_i (N/m) under gravity ``g`` (m/s²): zeros without ``p_delta``."""
        if not self.p_delta:
            return np.zeros(self.n_floors)
        weight_above = g * np.cumsum(np.asarray(self.mass, float)[::-1])[::-1]
        return -weight_above / np.asarray(self.storey_height, float)

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
    eigenvalues = eigh(storey_matrix(np.asarray(stiffness, float)), np.diag(mass), eigvals_only=True)
    return np.sqrt(np.clip(eigenvalues, 0.0, None))


def stiffness_proportional_damping(mass: np.ndarray, stiffness: np.ndarray, ratio: float) -> np.ndarray:
    """Storey dashpots of C = a1·K with damping ``ratio`` in mode 1 (a1 = 2ζ1/ω1), N·s/m."""
    omega_1 = fixed_base_frequencies(mass, stiffness)[0]
    return 2.0 * ratio / omega_1 * np.asarray(stiffness, float)


# ---------------------------------------------------------------- scene file


def buildings_from_tables(tables: list[TomlTable]) -> list[Building]:
    """The ``[[building]]`` tables of a scene file, validated (names unique)."""
    if not tables:
        raise SceneError("building: at least one [[building]] is required")
    buildings = [building_from_table(table, i) for i, table in enumerate(tables)]
    names = [b.name for b in buildings]
    for i, name in enumerate(names):
        if names.index(name) != i:
            raise SceneError(f"building[{i}].name: must be unique, {name!r} is used twice")
    return buildings


def default_name(index: int) -> str:
    """The name of the ``index``-th (0-based) ``[[building]]`` of a scene that gives it none: B1, B2, ..."""
    return f"B{index + 1}"


def building_from_table(table: TomlTable, index: int) -> Building:
    """One ``[[building]]`` table (the ``index``-th: default name B{index + 1}), validated."""
    table.reject_unknown(BUILDING_KEYS)
    name = table.string("name", default_name(index))
    base = base_from_table(table.table("base"))
    mass = table.numbers("mass", low=0.0, low_open=True)
    if not mass and base is None:
        raise table.error("mass", "must have at least one floor (only a sliding base may carry no floors)")
    stiffness = table.numbers("stiffness", low=0.0, length=len(mass))
    damping, ratio = _storey_damping(table, np.array(mass), np.array(stiffness))
    initial = _initial(table.table("initial"), len(mass), base is not None)
    height = table.numbers("storey_height", None, low=0.0, low_open=True, length=len(mass))
    yield_force, hardening = _yielding(table, stiffness)
    if yield_force is not None:
        drift = np.diff(np.concatenate([[0.0], initial.displacement]))
        for i, (d, force, k) in enumerate(zip(drift, yield_force, stiffness)):
            if abs(d) > force / k:
                raise SceneError(f"{table.name}.initial.displacement: storey {i + 1}'s drift {d:.6g} m is beyond its yield drift F_y/k = {force / k:.6g} m "
                                 "(a yielding building starts elastic)")
    p_delta = table.boolean("p_delta", False)
    if p_delta and height is None:
        raise table.error("p_delta", "needs storey_height (the geometric stiffness of a storey is −W/h)")
    return Building(name, mass, stiffness, damping, ratio, base, initial, height, yield_force, hardening, p_delta)


def _yielding(table: TomlTable, stiffness: tuple[float, ...]) -> tuple[tuple[float, ...] | None, float]:
    """The bilinear storeys' ``yield_force`` (None: elastic) and ``hardening`` of a ``[[building]]`` table, validated."""
    if "yield_force" not in table:
        if "hardening" in table:
            raise table.error("hardening", "only a building with yield_force (bilinear storeys) can have it")
        return None, 0.0
    yield_force = table.numbers("yield_force", low=0.0, low_open=True, length=len(stiffness))
    if any(k <= 0.0 for k in stiffness):
        raise table.error("yield_force", "needs every storey stiffness > 0 (the yield drift is F_y / k)")
    return yield_force, table.number("hardening", 0.0, low=0.0, high=1.0, high_open=True)


def _storey_damping(table: TomlTable, mass: np.ndarray, stiffness: np.ndarray) -> tuple[tuple[float, ...], float | None]:
    if "damping" in table and "damping_ratio" in table:
        raise table.error("damping", "give either damping (N·s/m per storey) or damping_ratio, not both")
    if "damping_ratio" in table:
        ratio = table.number("damping_ratio", low=0.0, high=1.0, high_open=True)
        if len(mass) == 0 or np.any(stiffness <= 0.0):
            raise table.error("damping_ratio", "needs every storey stiffness > 0 (mode 1 must have a frequency); give damping instead")
        return tuple(stiffness_proportional_damping(mass, stiffness, ratio)), ratio
    return table.numbers("damping", tuple(0.0 for _ in mass), low=0.0, length=len(mass)), None


def _initial(table: TomlTable | None, n_floors: int, has_base: bool) -> InitialState:
    zeros = tuple(0.0 for _ in range(n_floors))
    if table is None:
        return InitialState(zeros, zeros)
    table.reject_unknown(INITIAL_KEYS)
    for key in ("base_displacement", "base_velocity"):
        if key in table and not has_base:
            raise table.error(key, "only a building with a sliding [building.base] can have it")
    return InitialState(
        table.numbers("displacement", zeros, low=-math.inf, length=n_floors),
        table.numbers("velocity", zeros, low=-math.inf, length=n_floors),
        table.number("base_displacement", 0.0),
        table.number("base_velocity", 0.0),
    )


def scaled_masses(table: TomlTable, factor: float) -> tuple[dict[str, list[float]], dict[str, float]]:
    """The fields of a ``[[building]]`` table, and of its ``[building.base]``, whose masses are multiplied by ``factor``, keeping its modal damping ratios.

    The floor masses and a base's ``mass`` × factor; storey dashpots given as
    ``damping`` × √factor (M → fM with K fixed scales every frequency by
    1/√f, so C → √f C keeps every modal damping ratio); a ``damping_ratio``
    is kept as it is (not among the fields returned).

    Returns
    -------
    tuple of (dict, dict)
        The building's changed fields (``mass``, and ``damping`` when given), and its base's (``mass``; empty without a base mass).
    """
    scaled = {"mass": [float(m) * factor for m in table.raw("mass")]}
    if "damping" in table:
        scaled["damping"] = [float(c) * math.sqrt(factor) for c in table.raw("damping")]
    base = table.raw("base")
    return scaled, ({"mass": float(base["mass"]) * factor} if isinstance(base, dict) and "mass" in base else {})
