"""The linear Kelvin–Voigt contact law (``kelvin``, the default and the reference study's).

Scene keys (``[[contact]]`` or ``[[wall]]``): ``stiffness`` (k, N/m, > 0),
``restitution`` (r ∈ (0, 1]) or ``damping`` (c, N·s/m, ≥ 0), ``tensile``
(default true).

The law (docs/model.md, "Impact elements"). With the penetration δ, the
element's force while closed is

    F = k δ + c δ̇,    c = 2 ξ √(k m_eff),  ξ = −ln r / √(π² + ln² r),

which realises the restitution r exactly for two free masses. A tensile
element separates when δ returns to 0 (it may pull just before); a
non-tensile one when F returns to 0. Piecewise linear: a closed element adds
k and c to its mode (:func:`stochpound.model.contact.closed_terms`), and the
exact solver takes it.

Mass scaling (experiment variants): k × m_eff,new/m_eff,old keeps √(k/m_eff);
c follows from r, or (given as ``damping``) × the same ratio, which keeps
its damping ratio.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from stochpound.errors import SceneError
from stochpound.model import fields
from stochpound.model.law import ContactLaw, ElementParameters, quantity


def restitution_damping_ratio(restitution: float) -> float:
    """Damping ratio ξ of a Kelvin–Voigt element with coefficient of restitution r.

    ξ = −ln r / sqrt(π² + (ln r)²) (Anagnostopoulos 1988); ξ = 0 for r = 1.
    """
    log_r = math.log(restitution)
    return -log_r / math.sqrt(math.pi**2 + log_r**2)


class KelvinVoigt(ContactLaw):
    """``kelvin``: F = k δ + c δ̇ while closed."""

    name = "kelvin"
    title = "linear Kelvin–Voigt"
    formula = "F = k δ + c δ̇"
    keys = frozenset({"stiffness", "restitution", "damping", "tensile"})
    piecewise_linear = True
    stiffness_unit = "N/m"

    def read(self, table: Mapping[str, Any], prefix: str, mass: float) -> ElementParameters:
        stiffness = fields.number(table, "stiffness", prefix, required=True, low=0.0, low_open=True)
        restitution = None
        if "restitution" in table and "damping" in table:
            raise SceneError(f"{prefix}.damping: give either restitution or damping, not both")
        if "damping" in table:
            damping = fields.number(table, "damping", prefix, low=0.0)
        else:
            restitution = fields.number(table, "restitution", prefix, required=True, low=0.0, low_open=True, high=1.0)
            damping = 2.0 * restitution_damping_ratio(restitution) * math.sqrt(stiffness * mass)
        tensile = fields.boolean(table, "tensile", prefix, default=True)
        return ElementParameters(stiffness, damping, restitution, tensile, mass)

    def force(self, element: ElementParameters, delta: np.ndarray, rate: np.ndarray, onset: float) -> np.ndarray:
        return element.stiffness * np.asarray(delta) + element.damping * np.asarray(rate)

    def partials(self, element: ElementParameters, delta: np.ndarray, rate: np.ndarray, onset: float) -> tuple[np.ndarray, np.ndarray]:
        return np.full(np.shape(delta), element.stiffness), np.full(np.shape(delta), element.damping)

    def describe(self, element: ElementParameters) -> str:
        frequency = math.sqrt(element.stiffness / element.mass)
        origin = f"from e = {element.restitution:.4g}" if element.restitution is not None else "given"
        return (f"Kelvin–Voigt, k = {quantity(element.stiffness, self.stiffness_unit)} (√(k/m_eff) = {quantity(frequency, 'rad/s')}), "
                f"c = {quantity(element.damping, 'N·s/m')} {origin}")

    def separation(self, element: ElementParameters) -> str:
        return "tensile (separates when the penetration returns to 0)" if element.tensile else "non-tensile (separates when the force returns to 0)"


KELVIN = KelvinVoigt()
"""The Kelvin–Voigt law."""
