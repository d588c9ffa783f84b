"""Jankowski's nonlinear viscoelastic contact law (``jankowski``).

Scene keys (``[[contact]]`` or ``[[wall]]`` with ``law = "jankowski"``):
``stiffness`` β (N/m^1.5, > 0) and ``restitution`` e (in (0, 1)).

The law (docs/model.md, "Contact laws"; R. Jankowski, Earthquake Engng
Struct. Dyn. 34 (2005) 595–611). With the penetration δ > 0 and its rate δ̇:

    F = β δ^{3/2} + c(t) δ̇   while δ̇ > 0 (approach),
    F = β δ^{3/2}            while δ̇ ≤ 0 (restitution),
    c(t) = 2 ξ √(β √δ m_eff),

with the damping ratio from the coefficient of restitution by Jankowski's
analytical relation (Earthquake Engng Struct. Dyn. 35 (2006) 517–524)

    ξ = 9 √5 (1 − e²) / (2 e (e (9π − 16) + 16)).

The force vanishes with δ and is never negative, so the element closes and
opens where δ crosses 0. The relation is an approximation: the restitution a
free two-mass impact realises is tabulated against the target in
docs/model.md. Not piecewise linear: a scene that asks for it runs on the
ivp path. Mass scaling (experiment variants): β × m_eff,new/m_eff,old.
"""

from __future__ import annotations

import math

import numpy as np

LAWS = ("jankowski",)
PIECEWISE_LINEAR = False


def damping_ratio(restitution: float) -> float:
    """Jankowski's ξ(e) = 9 √5 (1 − e²) / (2 e (e (9π − 16) + 16))."""
    e = restitution
    return 9.0 * math.sqrt(5.0) * (1.0 - e**2) / (2.0 * e * (e * (9.0 * math.pi - 16.0) + 16.0))


def force(stiffness: float, restitution: float, mass: float, delta: np.ndarray, rate: np.ndarray) -> np.ndarray:
    """The element's force F (N) at penetration δ (m, clipped at 0) and rate δ̇ (m/s); ``mass`` is m_eff (kg)."""
    delta = np.clip(delta, 0.0, None)
    c = 2.0 * damping_ratio(restitution) * np.sqrt(stiffness * np.sqrt(delta) * mass)
    return stiffness * delta**1.5 + np.where(rate > 0.0, c * rate, 0.0)


def partials(stiffness: float, restitution: float, mass: float, delta: np.ndarray, rate: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """∂F/∂δ (N/m) and ∂F/∂δ̇ (N·s/m) at (δ, δ̇)."""
    delta = np.clip(delta, 0.0, None)
    xi = damping_ratio(restitution)
    c = 2.0 * xi * np.sqrt(stiffness * np.sqrt(delta) * mass)
    approaching = rate > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        dc = np.where(delta > 0.0, 0.25 * c / delta, 0.0)  # d c/dδ = c / (4 δ)
    return 1.5 * stiffness * np.sqrt(delta) + np.where(approaching, dc * rate, 0.0), np.where(approaching, c, 0.0)
