"""Hertz contact laws: elastic (``hertz``) and with Muthukumar–DesRoches damping (``hertz_damp``).

Scene keys (``[[contact]]`` or ``[[wall]]`` with ``law = "hertz"`` or
``"hertz_damp"``): ``stiffness`` k_h (N/m^1.5, > 0) and, for ``hertz_damp``,
``restitution`` e (in (0, 1]).

The laws (docs/model.md, "Contact laws"). With the penetration δ > 0 and its
rate δ̇, the element's force is

    hertz:       F = k_h δ^{3/2}
    hertz_damp:  F = k_h δ^{3/2} + c_h δ^{3/2} δ̇,   c_h = 3 k_h (1 − e²) / (4 δ̇₀)

(Muthukumar & DesRoches 2006), δ̇₀ the impact's approach velocity at onset:
the damping is set per impact. Both vanish with δ, so the element closes and
opens where δ crosses 0 and never pulls. For a free two-mass impact the
elastic law has the closed form δ_max = (5 m_eff δ̇₀² / (4 k_h))^{2/5}, peak
force k_h δ_max^{3/2} and duration ≈ 2.943 δ_max / δ̇₀. The laws are not
piecewise linear: a scene that asks for one runs on the ivp path.

Mass scaling (experiment variants): k_h × m_eff,new/m_eff,old, as the
Kelvin–Voigt element's k (it keeps the impact's time scale for a given
velocity).
"""

from __future__ import annotations


import numpy as np

from stochpound.model.fields import TomlTable
from stochpound.model.laws.contract import ContactLaw, ElementParameters, quantity

ONSET_FLOOR = 1e-9
"""Smallest approach velocity (m/s) taken for an impact's δ̇₀ (the damped laws' c_h ∝ 1/δ̇₀)."""


def peak_force(stiffness: float, mass: float, approach: float) -> float:
    """The peak force (N) of an elastic Hertz impact of two free masses: k_h δ_max^{3/2}, δ_max = (5 m_eff δ̇₀² / (4 k_h))^{2/5}.

    Parameters
    ----------
    stiffness : float
        k_h (N/m^1.5).
    mass : float
        The effective mass m_eff = m1 m2 / (m1 + m2) (kg).
    approach : float
        The approach velocity δ̇₀ (m/s).
    """
    return stiffness * (5.0 * mass * approach**2 / (4.0 * stiffness)) ** 0.6


class Hertz(ContactLaw):
    """``hertz``: F = k_h δ^{3/2}, elastic."""

    name = "hertz"
    title = "Hertz"
    formula = "F = k_h δ^{3/2}"
    keys = frozenset({"stiffness"})
    piecewise_linear = False

    def read(self, table: TomlTable, mass: float) -> ElementParameters:
        stiffness = table.number("stiffness", low=0.0, low_open=True)
        return ElementParameters(stiffness, 0.0, None, True, mass)

    def force(self, element: ElementParameters, delta: np.ndarray, rate: np.ndarray, onset: float) -> np.ndarray:
        return element.stiffness * np.clip(delta, 0.0, None) ** 1.5

    def partials(self, element: ElementParameters, delta: np.ndarray, rate: np.ndarray, onset: float) -> tuple[np.ndarray, np.ndarray]:
        delta = np.clip(delta, 0.0, None)
        return 1.5 * element.stiffness * np.sqrt(delta), np.zeros_like(delta)

    def describe(self, element: ElementParameters) -> str:
        return f"{self.title}, k_h = {quantity(element.stiffness, self.stiffness_unit)}, elastic"

    def refuse(self, key: str) -> str:
        if key == "restitution":
            return f"law {self.name!r} is elastic; use a damped law (hertz_damp, hertz_damp_ye, jankowski) for a restitution"
        return super().refuse(key)


class HertzDamp(ContactLaw):
    """``hertz_damp``: F = k_h δ^{3/2} + c_h δ^{3/2} δ̇ with Muthukumar & DesRoches's c_h = 3 k_h (1 − e²) / (4 δ̇₀).

    The damped Hertz laws differ only in c_h(e, δ̇₀) (:meth:`damping_coefficient`).
    """

    name = "hertz_damp"
    title = "Hertz-damp (Muthukumar & DesRoches 2006)"
    formula = "F = k_h δ^{3/2} + c_h δ^{3/2} δ̇, c_h = 3 k_h (1 − e²) / (4 δ̇₀)"
    keys = frozenset({"stiffness", "restitution"})
    piecewise_linear = False

    def damping_coefficient(self, stiffness: float, restitution: float, onset: float) -> float:
        """c_h (N·s/m^{5/2}) for k_h (N/m^1.5), e and the approach velocity δ̇₀ (m/s, > 0)."""
        return 3.0 * stiffness * (1.0 - restitution**2) / (4.0 * onset)

    def read(self, table: TomlTable, mass: float) -> ElementParameters:
        stiffness = table.number("stiffness", low=0.0, low_open=True)
        restitution = table.number("restitution", low=0.0, low_open=True, high=1.0)
        return ElementParameters(stiffness, 0.0, restitution, True, mass)

    def force(self, element: ElementParameters, delta: np.ndarray, rate: np.ndarray, onset: float) -> np.ndarray:
        c = self.damping_coefficient(element.stiffness, element.restitution, max(onset, ONSET_FLOOR))
        return np.clip(delta, 0.0, None) ** 1.5 * (element.stiffness + c * rate)

    def partials(self, element: ElementParameters, delta: np.ndarray, rate: np.ndarray, onset: float) -> tuple[np.ndarray, np.ndarray]:
        delta = np.clip(delta, 0.0, None)
        c = self.damping_coefficient(element.stiffness, element.restitution, max(onset, ONSET_FLOOR))
        return 1.5 * np.sqrt(delta) * (element.stiffness + c * rate), c * delta**1.5

    def describe(self, element: ElementParameters) -> str:
        return f"{self.title}, k_h = {quantity(element.stiffness, self.stiffness_unit)}, c_h from e = {element.restitution:.4g} per impact"


HERTZ = Hertz()
"""The elastic Hertz law."""
HERTZ_DAMP = HertzDamp()
"""The Hertz law with Muthukumar & DesRoches's damping."""
