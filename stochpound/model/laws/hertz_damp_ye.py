"""The Hertz law with Ye, Li & Zhu's damping (``hertz_damp_ye``), the damping OpenSees's manual recommends for Hertzdamp.

Scene keys (``[[contact]]`` or ``[[wall]]`` with ``law = "hertz_damp_ye"``):
``stiffness`` k_h (N/m^1.5, > 0) and ``restitution`` e (in (0, 1]).

The law (docs/model.md, "Contact laws"; K. Ye, L. Li, H. Zhu, Earthquake
Engng Struct. Dyn. 38 (2009) 1135–1142). With the penetration δ > 0, its rate
δ̇ and the impact's approach velocity δ̇₀ at onset:

    F = k_h δ^{3/2} (1 + ξ δ̇ / δ̇₀),   ξ = 8 (1 − e) / (5 e),

that is :mod:`stochpound.model.laws.hertz`'s ``hertz_damp`` with
c_h = 8 k_h (1 − e) / (5 e δ̇₀) instead of Muthukumar & DesRoches's
3 k_h (1 − e²) / (4 δ̇₀). Derived for low restitutions, it realises a
restitution much closer to the target than ``hertz_damp`` does below
e ≈ 0.9 (tabulated in docs/model.md). Not piecewise linear (ivp path); never
pulls; mass scaling as the Hertz family's (k_h × m_eff,new/m_eff,old).
"""

from __future__ import annotations

from stochpound.model.laws.hertz import HertzDamp


class HertzDampYe(HertzDamp):
    """``hertz_damp_ye``: F = k_h δ^{3/2} + c_h δ^{3/2} δ̇ with c_h = 8 k_h (1 − e) / (5 e δ̇₀)."""

    name = "hertz_damp_ye"
    title = "Hertz-damp (Ye, Li & Zhu 2009)"
    formula = "F = k_h δ^{3/2} + c_h δ^{3/2} δ̇, c_h = 8 k_h (1 − e) / (5 e δ̇₀)"

    def damping_coefficient(self, stiffness: float, restitution: float, onset: float) -> float:
        return 8.0 * stiffness * (1.0 - restitution) / (5.0 * restitution * onset)


HERTZ_DAMP_YE = HertzDampYe()
"""The Hertz law with Ye, Li & Zhu's damping."""
