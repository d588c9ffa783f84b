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

from stochpound.model.fields import TomlTable
from stochpound.model.laws.contract import ContactLaw, ElementParameters, quantity


def damping_ratio(restitution: float) -> float:
    """Jankowski's ξ(e) = 9 √5 (1 − e²) / (2 e (e (9π − 16) + 16))."""
    e = restitution
    return 9.0 * math.sqrt(5.0) * (1.0 - e**2) / (2.0 * e * (e * (9.0 * math.pi - 16.0) + 16.0))


class Jankowski(ContactLaw):
    """``jankowski``: F = β δ^{3/2} + c(t) δ̇ while approaching, β δ^{3/2} while restoring."""

    name = "jankowski"
    title = "Jankowski (2005, 2006)"
    formula = "F = β δ^{3/2} + c(t) δ̇ while δ̇ > 0, β δ^{3/2} while δ̇ ≤ 0, c(t) = 2 ξ √(β √δ m_eff)"
    keys = frozenset({"stiffness", "restitution"})
    piecewise_linear = False

    def read(self, table: TomlTable, mass: float) -> ElementParameters:
        stiffness = table.number("stiffness", low=0.0, low_open=True)
        restitution = table.number("restitution", low=0.0, low_open=True, high=1.0, high_open=True)
        return ElementParameters(stiffness, 0.0, restitution, True, mass)

    def force(self, element: ElementParameters, delta: np.ndarray, rate: np.ndarray, onset: float) -> np.ndarray:
        delta = np.clip(delta, 0.0, None)
        c = 2.0 * damping_ratio(element.restitution) * np.sqrt(element.stiffness * np.sqrt(delta) * element.mass)
        return element.stiffness * delta**1.5 + np.where(rate > 0.0, c * rate, 0.0)

    def partials(self, element: ElementParameters, delta: np.ndarray, rate: np.ndarray, onset: float) -> tuple[np.ndarray, np.ndarray]:
        delta = np.clip(delta, 0.0, None)
        xi = damping_ratio(element.restitution)
        c = 2.0 * xi * np.sqrt(element.stiffness * np.sqrt(delta) * element.mass)
        approaching = rate > 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            dc = np.where(delta > 0.0, 0.25 * c / delta, 0.0)  # d c/dδ = c / (4 δ)
        return 1.5 * element.stiffness * np.sqrt(delta) + np.where(approaching, dc * rate, 0.0), np.where(approaching, c, 0.0)

    def describe(self, element: ElementParameters) -> str:
        return (f"{self.title}, β = {quantity(element.stiffness, self.stiffness_unit)}, "
                f"ξ = {damping_ratio(element.restitution):.4g} from e = {element.restitution:.4g} while approaching")


JANKOWSKI = Jankowski()
"""Jankowski's law."""
