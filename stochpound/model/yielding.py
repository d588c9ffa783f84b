"""Bilinear (kinematic hardening) yielding storeys: their plastic states, mode terms and guards.

Scene keys (``[[building]]``): ``yield_force`` (N per storey) and
``hardening`` (α, the post-yield to elastic stiffness ratio, 0 ≤ α < 1).

The law (docs/model.md, "Yielding storeys"). A storey of elastic stiffness
k, yield shear F_y and drift d = u_i − u_{i−1} is an elastic spring α k in
parallel with an elastic–perfectly-plastic element: a spring (1 − α) k in
series with a Coulomb slider of strength (1 − α) F_y, whose position z is
the storey's plastic drift. The element's force is (1 − α) k (d − z). Each
yielding storey carries two kinematic states, both DOFs of the system
without mass: z and the accumulated plastic drift p = Σ|Δz| (the hysteretic
energy is (1 − α) F_y p). A storey is

* ``ELASTIC`` (0): z and p held; the element is a spring;
* ``FLOWING_UP`` (+1) / ``FLOWING_DOWN`` (−1): the element's force is the
  constant σ (1 − α) F_y, ż = ḋ and ṗ = σ ḋ.

Guards: an elastic storey flows in direction σ when
σ (1 − α) k (d − z) − (1 − α) F_y crosses 0 upwards (kind ``SLIP``, both
directions watched); a flowing storey turns elastic when −σ ḋ crosses 0
upwards (kind ``STOP``): the event engine treats the slider like a sliding
base's (the targets of storey guards follow the bases'). Every state is a
linear mode: the exact solver takes the law.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stochpound.model.guards import Guard

ELASTIC = 0
"""Storey state: its plastic element is elastic (z held)."""
FLOWING_UP, FLOWING_DOWN = 1, -1
"""Storey states: its plastic element flows, its plastic drift z growing or shrinking."""


@dataclass(frozen=True)
class YieldingStorey:
    """A bilinear storey in a system's layout.

    Attributes
    ----------
    building : int
        Index of its building in the scene.
    storey : int
        Its index in the building (0: the first storey, joining the base to floor 1).
    upper, lower : int
        The DOFs of the floors above and below it (``lower`` −1 for the first storey: the base, u_0 = 0).
    plastic_dof, accumulated_dof : int
        The DOFs of its plastic drift z and accumulated plastic drift p (m, no mass).
    stiffness, yield_force, hardening : float
        k (N/m), F_y (N) and α.
    """

    building: int
    storey: int
    upper: int
    lower: int
    plastic_dof: int
    accumulated_dof: int
    stiffness: float
    yield_force: float
    hardening: float

    @property
    def plastic_stiffness(self) -> float:
        """Stiffness (1 − α) k of its elastic–perfectly-plastic element, N/m."""
        return (1.0 - self.hardening) * self.stiffness

    @property
    def plastic_strength(self) -> float:
        """Strength (1 − α) F_y of its elastic–perfectly-plastic element, N."""
        return (1.0 - self.hardening) * self.yield_force

    @property
    def yield_drift(self) -> float:
        """Yield drift d_y = F_y / k, m."""
        return self.yield_force / self.stiffness

    def drift_row(self, n_dof: int) -> np.ndarray:
        """The row e over q with d = e · q (N)."""
        row = np.zeros(n_dof)
        row[self.upper] = 1.0
        if self.lower >= 0:
            row[self.lower] = -1.0
        return row

    def element_row(self, n_dof: int) -> np.ndarray:
        """The row g over q with d − z = g · q (N): the deformation of its elastic–perfectly-plastic element's spring."""
        row = self.drift_row(n_dof)
        row[self.plastic_dof] = -1.0
        return row


def plastic_spring(storey: YieldingStorey, n_dof: int) -> np.ndarray:
    """The stiffness (N × N, N/m) of a storey's elastic–perfectly-plastic spring (1 − α) k g gᵀ, g = :meth:`YieldingStorey.element_row`."""
    g = storey.element_row(n_dof)
    return storey.plastic_stiffness * np.outer(g, g)


def flowing(state: int) -> bool:
    """True for FLOWING_UP and FLOWING_DOWN."""
    return state in (FLOWING_UP, FLOWING_DOWN)


def flow_terms(storey: YieldingStorey, state: int, n_dof: int) -> tuple[np.ndarray, np.ndarray]:
    """A flowing storey's change of the mode's stiffness (N × N) and constant load (N).

    Its spring leaves K; the constant force σ (1 − α) F_y acts on the storey's
    floors (−σ (1 − α) F_y e: the generalised load of a storey shear).
    """
    return -plastic_spring(storey, n_dof), -state * storey.plastic_strength * storey.drift_row(n_dof)


def flow_rates(storey: YieldingStorey, state: int, A: np.ndarray, n_dof: int) -> None:
    """Write ż = ḋ and ṗ = σ ḋ of a flowing storey into the rows of A (2N × S') in place."""
    drift = storey.drift_row(n_dof)
    A[storey.plastic_dof, n_dof : 2 * n_dof] = drift
    A[storey.accumulated_dof, n_dof : 2 * n_dof] = state * drift


def guards(storey: YieldingStorey, target: int, state: int, size: int, n_dof: int) -> list[tuple]:
    """The guards of a storey in ``state`` (``target``: its index among the engine's sliders): (row over ξ, a_g coefficient, constant, kind, target, direction)."""
    row = np.zeros(size)
    if state == ELASTIC:
        row[:n_dof] = storey.plastic_stiffness * storey.element_row(n_dof)
        return [(sense * row, 0.0, -storey.plastic_strength, Guard.SLIP, target, sense) for sense in (FLOWING_UP, FLOWING_DOWN)]
    row[n_dof : 2 * n_dof] = -state * storey.drift_row(n_dof)
    return [(row, 0.0, 0.0, Guard.STOP, target, 0)]


def residual_drift(storey: YieldingStorey, plastic_drift: np.ndarray) -> np.ndarray:
    """The drift (m) a storey keeps at rest without external force from its plastic drift z (m): (1 − α) z."""
    return (1.0 - storey.hardening) * plastic_drift
