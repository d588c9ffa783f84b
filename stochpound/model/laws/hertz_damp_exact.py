"""The Hertz-damp law with its damping solved to realise the restitution exactly (``hertz_damp_exact``).

Scene keys (``[[contact]]`` or ``[[wall]]`` with ``law = "hertz_damp_exact"``):
``stiffness`` k_h (N/m^1.5, > 0) and ``restitution`` e (in [0.05, 1]).

The law (docs/model.md, "Contact laws"). With the penetration δ > 0, its rate
δ̇ and the impact's approach velocity δ̇₀ at onset:

    F = k_h δ^{3/2} (1 + ξ δ̇ / δ̇₀),   c_h = ξ k_h / δ̇₀,

the force of :mod:`stochpound.model.laws.hertz`'s ``hertz_damp`` with the
dimensionless damping ξ(e) solved so that a free two-mass impact leaves with
exactly −e times its approach velocity. Scaling δ = δ_s x and
t = (δ_s / δ̇₀) τ with δ_s = (m_eff δ̇₀² / k_h)^{2/5} turns the impact
m_eff δ̈ = −F into

    x'' = −x^{3/2} (1 + ξ x'),   x(0) = 0,  x'(0) = 1,

free of m_eff, k_h and δ̇₀: the realised restitution −x'(τ_end) at the return
to x = 0 depends on ξ alone, and decreases with it. :func:`damping_ratio`
finds ξ(e) once per e by a bracketed root find on that integration (DOP853,
rtol 1e-12; ξ to 1e-12, the realised e to about 1e-10) and caches it. For
e ≥ 0.05, ξ e < 1, so the force stays ≥ 0 up to the separation at δ = 0
(the law never pulls). Not piecewise linear (ivp path); mass scaling as the
Hertz family's (k_h × m_eff,new/m_eff,old).
"""

from __future__ import annotations

from functools import lru_cache

from stochpound.model.fields import TomlTable
from stochpound.model.laws.contract import ElementParameters
from stochpound.model.laws.hertz import HertzDamp

LOWEST_RESTITUTION = 0.05
"""The lowest restitution the law accepts (below it ξ grows without bound and the force would pull)."""


def realised_restitution(xi: float) -> float:
    """The restitution of a free two-mass impact under F = k_h δ^{3/2} (1 + ξ δ̇/δ̇₀), from its dimensionless form.

    Parameters
    ----------
    xi : float
        The dimensionless damping ξ (≥ 0).

    Returns
    -------
    float
        −x'(τ_end) of x'' = −x^{3/2} (1 + ξ x'), x(0) = 0, x'(0) = 1, at the return to x = 0.
    """
    from scipy.integrate import solve_ivp

    def rate(tau: float, y: list[float]) -> list[float]:
        x = max(y[0], 0.0)
        return [y[1], -(x**1.5) * (1.0 + xi * y[1])]

    def returned(tau: float, y: list[float]) -> float:
        return y[0]

    returned.terminal, returned.direction = True, -1  # type: ignore[attr-defined]
    solution = solve_ivp(rate, (0.0, 100.0), [0.0, 1.0], method="DOP853", rtol=1e-12, atol=1e-14, events=returned, first_step=1e-6)
    return -float(solution.y_events[0][-1][1])


@lru_cache(maxsize=256)
def damping_ratio(restitution: float) -> float:
    """ξ(e): the dimensionless damping whose free two-mass impact realises the restitution e exactly (cached).

    Parameters
    ----------
    restitution : float
        The target e, in [:data:`LOWEST_RESTITUTION`, 1].

    Returns
    -------
    float
        ξ ≥ 0 with :func:`realised_restitution` (ξ) = e (root found to 1e-12 in ξ); 0 for e = 1.
    """
    from scipy.optimize import brentq

    if restitution >= 1.0:
        return 0.0
    upper = 8.0 * (1.0 - restitution) / (5.0 * restitution)  # Ye, Li & Zhu's ξ: realises a little less than e
    while realised_restitution(upper) > restitution:
        upper *= 2.0
    return float(brentq(lambda xi: realised_restitution(xi) - restitution, 0.0, upper, xtol=1e-12, rtol=1e-12))


class HertzDampExact(HertzDamp):
    """``hertz_damp_exact``: F = k_h δ^{3/2} + c_h δ^{3/2} δ̇ with c_h = ξ(e) k_h / δ̇₀, ξ(e) solved for e (:func:`damping_ratio`)."""

    name = "hertz_damp_exact"
    title = "Hertz-damp (damping solved for the restitution)"
    formula = "F = k_h δ^{3/2} + c_h δ^{3/2} δ̇, c_h = ξ(e) k_h / δ̇₀, ξ(e) solved so that a free impact realises e"

    def damping_coefficient(self, stiffness: float, restitution: float, onset: float) -> float:
        return damping_ratio(restitution) * stiffness / onset

    def read(self, table: TomlTable, mass: float) -> ElementParameters:
        stiffness = table.number("stiffness", low=0.0, low_open=True)
        restitution = table.number("restitution", low=LOWEST_RESTITUTION, high=1.0)
        return ElementParameters(stiffness, 0.0, restitution, True, mass)

    def describe(self, element: ElementParameters) -> str:
        return (f"{super().describe(element)} (ξ = {damping_ratio(element.restitution):.4g}: realises e exactly in a free "
                "two-mass impact)")


HERTZ_DAMP_EXACT = HertzDampExact()
"""The Hertz law with its damping solved for the restitution."""
