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

import numpy as np

from stochpound.model.fields import TomlTable
from stochpound.model.laws.contract import ContactLaw, ElementParameters, quantity


def restitution_damping_ratio(restitution: float) -> float:
    """Damping ratio ξ of a Kelvin–Voigt element with coefficient of restitution r.

    ξ = −ln r / sqrt(π² + (ln r)²) (Anagnostopoulos 1988); ξ = 0 for r = 1.
    """
    log_r = math.log(restitution)
    return -log_r / math.sqrt(math.pi**2 + log_r**2)


def peak_force_factor(damping_ratio: float) -> float:
    """φ(ξ): the peak force of a Kelvin–Voigt impact of two free masses over √(k m_eff) δ̇₀.

    The relative motion δ = (δ̇₀/ω_d) e^{−ξωt} sin(ω_d t), ω = √(k/m_eff),
    ω_d = ω √(1 − ξ²), carries the force F = k δ + c δ̇ = −m_eff δ̈. For
    ξ < 1/2 it peaks where δ̇/δ = 2ξω/(1 − 4ξ²), i.e. at
    ω_d t* = atan2(√(1 − ξ²)(1 − 4ξ²), ξ(3 − 4ξ²)); for ξ ≥ 1/2 it peaks at
    onset, F = c δ̇₀ (φ = 2ξ).

    Parameters
    ----------
    damping_ratio : float
        ξ of the element (in [0, 1)).

    Returns
    -------
    float
        φ = F_max / (√(k m_eff) δ̇₀), dimensionless.
    """
    xi = damping_ratio
    if xi >= 0.5:
        return 2.0 * xi
    root = math.sqrt(1.0 - xi**2)
    phase = math.atan2(root * (1.0 - 4.0 * xi**2), xi * (3.0 - 4.0 * xi**2))  # ω_d t*
    decay = math.exp(-xi * phase / root)
    # with ω = 1 and δ̇₀ = 1: δ = e^{−ξt} sin(ω_d t)/ω_d, δ̇ = e^{−ξt} (cos(ω_d t) − ξ sin(ω_d t)/ω_d)
    delta = decay * math.sin(phase) / root
    rate = decay * (math.cos(phase) - xi * math.sin(phase) / root)
    return delta + 2.0 * xi * rate


def stiffness_for_peak_force(force: float, mass: float, approach: float, restitution: float) -> float:
    """The stiffness k (N/m) of a Kelvin–Voigt element of restitution e whose free two-mass impact peaks at ``force``.

    The element's peak force is φ(ξ) √(k m_eff) δ̇₀ (:func:`peak_force_factor`,
    ξ from e by :func:`restitution_damping_ratio`), so
    k = (F / (φ(ξ) δ̇₀))² / m_eff. With F the elastic Hertz peak force
    (:func:`stochpound.model.laws.hertz.peak_force`) at a reference approach
    velocity, the element matches a Hertz element's peak force there.

    Parameters
    ----------
    force : float
        The peak force to match (N).
    mass : float
        The impact's effective mass m_eff (kg).
    approach : float
        The reference approach velocity δ̇₀ (m/s).
    restitution : float
        The element's coefficient of restitution e (in (0, 1]).

    Returns
    -------
    float
        k (N/m).
    """
    factor = peak_force_factor(restitution_damping_ratio(restitution))
    return (force / (factor * approach)) ** 2 / mass


class KelvinVoigt(ContactLaw):
    """``kelvin``: F = k δ + c δ̇ while closed."""

    name = "kelvin"
    title = "linear Kelvin–Voigt"
    formula = "F = k δ + c δ̇"
    keys = frozenset({"stiffness", "restitution", "damping", "tensile"})
    piecewise_linear = True
    stiffness_unit = "N/m"

    def read(self, table: TomlTable, mass: float) -> ElementParameters:
        stiffness = table.number("stiffness", low=0.0, low_open=True)
        restitution = None
        if "restitution" in table and "damping" in table:
            raise table.error("damping", "give either restitution or damping, not both")
        if "damping" in table:
            damping = table.number("damping", None, low=0.0)
        else:
            restitution = table.number("restitution", low=0.0, low_open=True, high=1.0)
            damping = 2.0 * restitution_damping_ratio(restitution) * math.sqrt(stiffness * mass)
        tensile = table.boolean("tensile", True)
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
