"""The Hertz-damp law with its damping solved for the restitution (``hertz_damp_exact``), and the Kelvin element matched to a Hertz peak force.

References: the two-mass collision integrated here in its dimensional form,
m_eff δ̈ = −k_h δ^{3/2} (1 + ξ δ̇/δ̇₀) (scipy's DOP853 at rtol 1e-12, its own
event at δ = 0), for masses, stiffnesses and velocities other than the
dimensionless form the law solves; the Kelvin–Voigt impact's closed form
integrated numerically for its peak force.
"""

import math
import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import stochpound
from stochpound.model import hertz, kelvin, laws
from stochpound.model.hertz_damp_exact import damping_ratio
from tests.helpers import K_HERTZ, M_EFF, V0, docs_restitution_column, free_masses, realised_restitution, run


def collision(xi: float, mass: float, stiffness: float, approach: float) -> tuple[float, float]:
    """Exit restitution and peak force (N) of the dimensional two-mass Hertz-damp collision with damping ξ."""

    def force(y):
        return stiffness * max(y[0], 0.0) ** 1.5 * (1.0 + xi * y[1] / approach)

    def separated(t, y):
        return y[0]

    separated.terminal, separated.direction = True, -1
    solution = solve_ivp(lambda t, y: [y[1], -force(y) / mass], (0.0, 1.0), [0.0, approach], method="DOP853", rtol=1e-12,
                         atol=1e-16, events=separated, first_step=1e-7, dense_output=True)
    times = np.linspace(0.0, float(solution.t_events[0][-1]), 20001)
    return -float(solution.y_events[0][-1][1]) / approach, max(force(y) for y in solution.sol(times).T)


@pytest.mark.parametrize("target", [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95])
@pytest.mark.parametrize("mass, stiffness, approach", [(M_EFF, K_HERTZ, V0), (8756.0, 2.75e9, 1.3)])
def test_the_solved_damping_realises_the_target_in_an_independent_collision(target, mass, stiffness, approach):
    """The dimensionless ξ(e) serves any m_eff, k_h and δ̇₀ (scale invariance): e to 1e-9."""
    realised, _ = collision(damping_ratio(target), mass, stiffness, approach)
    assert realised == pytest.approx(target, abs=1e-9)


@pytest.mark.parametrize("target", [0.3, 0.5, 0.7, 0.95])
def test_the_solver_realises_the_target_in_a_single_collision(target):
    result = run(free_masses("hertz_damp_exact", target))
    assert result.attrs["solver"] == "ivp" and result.sizes["impact"] == 1
    assert realised_restitution(result) == pytest.approx(target, abs=1e-6)
    residual = float(np.abs(result.energy_residual).max() / np.abs(result.energy_kinetic).max())
    assert residual < 1e-8


def test_the_docs_table_gives_the_target_and_the_solved_damping():
    rows = docs_restitution_column("hertz_damp_exact")
    assert len(rows) >= 7
    for target, cell in rows.items():
        realised, xi = re.fullmatch(r"([0-9.]+) \(([0-9.]+)\)", cell).groups()
        assert float(realised) == target and float(xi) == pytest.approx(damping_ratio(target), rel=5e-4)


def test_the_solved_damping_lies_between_the_published_ones():
    """Ye, Li & Zhu's ξ over-damps (realises less than e), Muthukumar & DesRoches's under-damps; e = 1 is elastic."""
    assert damping_ratio(1.0) == 0.0
    for e in (0.3, 0.5, 0.9):
        ye = 8.0 * (1.0 - e) / (5.0 * e)
        muthukumar = 3.0 * (1.0 - e**2) / 4.0
        assert muthukumar < damping_ratio(e) < ye


def test_the_law_is_registered_validated_and_described():
    law = laws.contact_law("hertz_damp_exact")
    assert not law.piecewise_linear
    element = stochpound.scene_from_dict(free_masses("hertz_damp_exact", 0.5)).contacts[0].parameters(M_EFF)
    assert law.describe(element).startswith("Hertz-damp (damping solved for the restitution), k_h = 1e+10 N/m^1.5, c_h from e = 0.5")
    assert law.damping_coefficient(K_HERTZ, 0.5, V0) == pytest.approx(damping_ratio(0.5) * K_HERTZ / V0, rel=1e-15)
    scene = free_masses("hertz_damp_exact", 0.01)
    with pytest.raises(stochpound.SceneError, match=r"contact\[0\]\.restitution: must be >= 0.05"):
        stochpound.scene_from_dict(scene)


def kelvin_peak_force(stiffness: float, restitution: float, mass: float, approach: float) -> float:
    """The peak of k δ + c δ̇ over a tensile Kelvin–Voigt impact of two free masses, from its closed-form motion on a fine grid."""
    xi = kelvin.restitution_damping_ratio(restitution)
    omega = math.sqrt(stiffness / mass)
    damped = omega * math.sqrt(1.0 - xi**2)
    t = np.linspace(0.0, math.pi / damped, 400001)
    delta = approach / damped * np.exp(-xi * omega * t) * np.sin(damped * t)
    rate = approach * np.exp(-xi * omega * t) * (np.cos(damped * t) - xi * omega / damped * np.sin(damped * t))
    return float(np.max(stiffness * delta + 2.0 * xi * math.sqrt(stiffness * mass) * rate))


@pytest.mark.parametrize("restitution", [0.05, 0.3, 0.5, 0.8, 1.0])
def test_the_calibrated_kelvin_element_peaks_at_the_hertz_peak_force(restitution):
    force = hertz.peak_force(2.75e9, 13134.0, 0.5)
    stiffness = kelvin.stiffness_for_peak_force(force, 13134.0, 0.5, restitution)
    assert kelvin_peak_force(stiffness, restitution, 13134.0, 0.5) == pytest.approx(force, rel=1e-8)


def test_the_hertz_peak_force_is_that_of_the_collision_and_the_calibrated_kelvin_run_reaches_it():
    assert collision(0.0, M_EFF, K_HERTZ, V0)[1] == pytest.approx(hertz.peak_force(K_HERTZ, M_EFF, V0), rel=1e-8)
    stiffness = kelvin.stiffness_for_peak_force(hertz.peak_force(K_HERTZ, M_EFF, V0), M_EFF, V0, 0.5)
    scene = free_masses("kelvin", 0.5)
    scene["contact"][0]["stiffness"] = stiffness
    result = run(scene)
    assert float(result.impact_peak_force[0]) == pytest.approx(hertz.peak_force(K_HERTZ, M_EFF, V0), rel=1e-6)
