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

LAWS = ("hertz", "hertz_damp")
PIECEWISE_LINEAR = False


def damping_coefficient(stiffness: float, restitution: float, onset: np.ndarray) -> np.ndarray:
    """c_h = 3 k_h (1 − e²) / (4 δ̇₀), N·s/m^{5/2}, for approach velocities δ̇₀ (m/s, > 0)."""
    return 3.0 * stiffness * (1.0 - restitution**2) / (4.0 * onset)


def force(law: str, stiffness: float, restitution: float | None, delta: np.ndarray, rate: np.ndarray, onset: np.ndarray) -> np.ndarray:
    """The element's force F (N) at penetration δ (m, clipped at 0), rate δ̇ (m/s) and onset velocity δ̇₀ (m/s)."""
    power = np.clip(delta, 0.0, None) ** 1.5
    if law == "hertz":
        return stiffness * power
    return power * (stiffness + damping_coefficient(stiffness, restitution, onset) * rate)


def partials(law: str, stiffness: float, restitution: float | None, delta: np.ndarray, rate: np.ndarray,
             onset: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """∂F/∂δ (N/m) and ∂F/∂δ̇ (N·s/m) at (δ, δ̇, δ̇₀)."""
    delta = np.clip(delta, 0.0, None)
    if law == "hertz":
        return 1.5 * stiffness * np.sqrt(delta), np.zeros_like(delta)
    c = damping_coefficient(stiffness, restitution, onset)
    return 1.5 * np.sqrt(delta) * (stiffness + c * rate), c * delta**1.5
