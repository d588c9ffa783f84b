"""The Hertz law with Ye, Li & Zhu's damping (``hertz_damp_ye``): single two-mass collisions against an independent integration.

The reference integrates the relative motion m_eff δ̈ = −k_h δ^{3/2} (1 + ξ δ̇/δ̇₀),
ξ = 8 (1 − e)/(5 e), written out here (not the law's module), with scipy's
DOP853 at rtol 1e-12 and its own event at δ = 0.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import stochpound
from stochpound.model import laws
from tests.helpers import GAP, K_HERTZ, M_EFF, V0, docs_restitution_column, free_masses, realised_restitution, run


def ye_restitution(target: float, approach: float = V0) -> float:
    """−δ̇(exit)/δ̇₀ of the relative motion under Ye's law, integrated on its own."""
    xi = 8.0 * (1.0 - target) / (5.0 * target)

    def rate(t, y):
        delta = max(y[0], 0.0)
        return [y[1], -K_HERTZ * delta**1.5 * (1.0 + xi * y[1] / approach) / M_EFF]

    def separated(t, y):
        return y[0]

    separated.terminal, separated.direction = True, -1
    solution = solve_ivp(rate, (0.0, 1.0), [0.0, approach], method="DOP853", rtol=1e-12, atol=1e-16, events=separated, first_step=1e-6)
    return -float(solution.y_events[0][-1][1]) / approach


@pytest.mark.parametrize("target", [0.3, 0.6, 0.9])
def test_a_single_collision_realises_the_restitution_of_the_independent_integration(target):
    result = run(free_masses("hertz_damp_ye", target))
    assert result.attrs["solver"] == "ivp" and result.sizes["impact"] == 1
    assert float(result.impact_start[0]) == pytest.approx(GAP / V0, rel=1e-10)
    assert realised_restitution(result) == pytest.approx(ye_restitution(target), rel=1e-6)
    residual = float(np.abs(result.energy_residual).max() / np.abs(result.energy_kinetic).max())
    assert residual < 1e-8  # the energy balance closes with the law's own work


def test_the_realised_restitution_is_scale_invariant_and_tabulated_in_the_docs():
    """The realised e depends on the target only (not on δ̇₀); docs/model.md's column is reproduced."""
    assert ye_restitution(0.5, 0.1) == pytest.approx(ye_restitution(0.5, 1.0), rel=1e-8)
    rows = docs_restitution_column("hertz_damp_ye")
    assert len(rows) >= 7
    for target, realised in rows.items():
        assert ye_restitution(target) == pytest.approx(float(realised), abs=5e-4)


def test_the_law_is_registered_validated_and_described():
    law = laws.contact_law("hertz_damp_ye")
    assert not law.piecewise_linear
    scene = free_masses("hertz_damp_ye", 0.5)
    element = stochpound.scene_from_dict(scene).contacts[0]
    assert law.describe(element.parameters(M_EFF)) == "Hertz-damp (Ye, Li & Zhu 2009), k_h = 1e+10 N/m^1.5, c_h from e = 0.5 per impact"
    for change, message in [({"restitution": 0.0}, r"contact\[0\]\.restitution: must be > 0"),
                            ({"tensile": False}, r"contact\[0\]\.tensile: not a field of law 'hertz_damp_ye'")]:
        scene["contact"][0].update(change)
        with pytest.raises(stochpound.SceneError, match=message):
            stochpound.scene_from_dict(scene)
        scene = free_masses("hertz_damp_ye", 0.5)
