"""The modes and periods of a shear building, and the closed-form response of a fixed-base, classically damped one to harmonic ground acceleration.

The study's harmonic check (its section 3.1) compares the numerical solution
with this semi-analytic one. For a building whose damping matrix is
diagonalised by the undamped mode shapes (e.g. C = a1·K, the study's
choice), each mode n obeys

    η̈ₙ + 2ζₙωₙη̇ₙ + ωₙ²ηₙ = −Γₙ A sin(Ωt),   ηₙ(0) = η̇ₙ(0) = 0,

with mass-normalised shapes φₙ, Γₙ = φₙᵀM1, and u(t) = Σ φₙ ηₙ(t): the
steady-state particular solution plus the damped free vibration that
satisfies the zero initial conditions.
"""

from __future__ import annotations

from dataclasses import dataclass

import math
from typing import TYPE_CHECKING

import numpy as np
from scipy.linalg import eigh

from stochpound.model.building import Building, storey_matrix
from stochpound.model.friction import is_fixed_base

if TYPE_CHECKING:
    from stochpound.model.scene import Scene

#: Largest off-diagonal modal damping, relative to the diagonal, still treated as
#: classical (and neglected): the study's dashpots are a1·K rounded to 6 digits.
CLASSICAL_TOLERANCE = 1e-4


@dataclass(frozen=True)
class Modes:
    """The undamped modes of a fixed-base shear building and their damping.

    Attributes
    ----------
    omega : numpy.ndarray
        Natural circular frequencies ω_n, rad/s, ascending.
    damping_ratio : numpy.ndarray
        Modal damping ratios ζ_n = φ_nᵀ C φ_n / (2 ω_n) (mass-normalised φ_n).
    shapes : numpy.ndarray
        Mass-normalised mode shapes, one per column.
    participation : numpy.ndarray
        Γ_n = φ_nᵀ M 1.
    classical : bool
        Whether φᵀ C φ is diagonal (to :data:`CLASSICAL_TOLERANCE`): only then
        do the modes decouple and ζ_n describe the damping exactly.
    """

    omega: np.ndarray
    damping_ratio: np.ndarray
    shapes: np.ndarray
    participation: np.ndarray
    classical: bool

    @property
    def periods(self) -> np.ndarray:
        """Natural periods 2π/ω_n, s."""
        return 2.0 * np.pi / self.omega


def modal_properties(building: Building) -> Modes:
    """The modes of ``building`` on a fixed base (its base, if any, is ignored)."""
    mass = np.diag(building.mass)
    stiffness = storey_matrix(np.asarray(building.stiffness, dtype=float))
    damping = storey_matrix(np.asarray(building.damping, dtype=float))
    eigenvalues, shapes = eigh(stiffness, mass)  # mass-normalised shapes
    modal_damping = shapes.T @ damping @ shapes
    off_diagonal = modal_damping - np.diag(np.diag(modal_damping))
    classical = bool(np.max(np.abs(off_diagonal), initial=0.0) <= CLASSICAL_TOLERANCE * np.max(np.abs(np.diag(modal_damping))))
    omega = np.sqrt(eigenvalues)
    participation = shapes.T @ mass @ np.ones(len(building.mass))
    return Modes(omega, np.diag(modal_damping) / (2.0 * omega), shapes, participation, classical)


def building_periods(building: Building, g: float) -> dict[str, float]:
    """The periods of interest of a building, s, by name.

    Parameters
    ----------
    building : Building
        A shear building.
    g : float
        Acceleration of gravity, m/s² (a friction pendulum's restoring stiffness is W/R).

    Returns
    -------
    dict
        ``"first mode"``: the first-mode period of the floors on a fixed base
        (elastic storeys, without P-Δ; inf for a storey without stiffness),
        unless the building has no floors; ``"isolated"``: 2π √(M/k_r) of a
        sliding base with a restoring stiffness k_r (M the floors' and the
        base's mass).
    """
    periods = {}
    if building.n_floors:
        with np.errstate(divide="ignore", invalid="ignore"):
            first = float(modal_properties(building).periods[0])
        periods["first mode"] = first if math.isfinite(first) else math.inf
    base = building.base
    if base is not None and not is_fixed_base(base.mu) and base.restoring(building.total_mass * g) > 0:
        periods["isolated"] = 2.0 * math.pi * math.sqrt(building.total_mass / base.restoring(building.total_mass * g))
    return periods


def scene_periods(scene: Scene) -> dict[str, float]:
    """Every building's periods of interest (:func:`~stochpound.model.building_periods`), s, named ``"<building> first mode"``, ``"<building> isolated"``."""
    return {f"{building.name} {kind}": period for building in scene.buildings for kind, period in building_periods(building, scene.g).items()}


def harmonic_response(building: Building, amplitude: float, omega: float, times: np.ndarray) -> np.ndarray:
    """Floor displacements relative to the ground of a fixed-base building from rest under A sin(Ωt).

    Parameters
    ----------
    building : Building
        A shear building (its base, if any, is ignored: the building is taken as fixed).
    amplitude : float
        Ground-acceleration amplitude A, m/s².
    omega : float
        Circular frequency Ω of the ground acceleration, rad/s (> 0).
    times : numpy.ndarray
        Times, s (≥ 0).

    Returns
    -------
    numpy.ndarray
        u(t), m, shape (floors, times).

    Raises
    ------
    ValueError
        If the damping is not classical (the modes would not decouple), or
        a mode is in exact resonance with undamped forcing.
    """
    modes = modal_properties(building)
    if not modes.classical:
        raise ValueError(f"building {building.name!r}: damping is not classical (not diagonal in the mode shapes)")
    response = np.zeros((len(building.mass), len(times)))
    for n, (natural, ratio) in enumerate(zip(modes.omega, modes.damping_ratio)):
        eta = modal_coordinate(float(natural), float(ratio), -modes.participation[n] * amplitude, omega, times)
        response += np.outer(modes.shapes[:, n], eta)
    return response


def modal_coordinate(natural: float, ratio: float, force: float, omega: float, times: np.ndarray) -> np.ndarray:
    """η(t) of η̈ + 2ζωₙη̇ + ωₙ²η = F sin(Ωt) from rest (0 ≤ ζ < 1).

    Parameters
    ----------
    natural : float
        ωₙ, rad/s.
    ratio : float
        ζ, the modal damping ratio.
    force : float
        F, the forcing amplitude per unit modal mass, m/s².
    omega : float
        Ω, rad/s.
    times : numpy.ndarray
        s.

    Returns
    -------
    numpy.ndarray
        η(t), m (per unit participation).
    """
    # particular solution X sin(Ωt) + Y cos(Ωt)
    detuning = natural**2 - omega**2
    coupling = 2.0 * ratio * natural * omega
    determinant = detuning**2 + coupling**2
    if determinant == 0.0:
        raise ValueError(f"undamped mode at resonance (omega = {omega} rad/s): no bounded particular solution")
    sine = force * detuning / determinant
    cosine = -force * coupling / determinant
    # free vibration making η(0) = η̇(0) = 0
    damped = natural * np.sqrt(1.0 - ratio**2)
    a = -cosine
    b = (ratio * natural * a - omega * sine) / damped
    decay = np.exp(-ratio * natural * times)
    return (sine * np.sin(omega * times) + cosine * np.cos(omega * times)
            + decay * (a * np.cos(damped * times) + b * np.sin(damped * times)))
