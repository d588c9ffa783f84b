"""Nonlinear contact laws (Hertz, Hertz-damp, Jankowski) and velocity-dependent friction, run on the ivp path.

References: a single impact of two free masses against an independent
integration of its relative motion, m_eff δ̈ = −F(δ, δ̇) (scipy's DOP853 at
rtol 1e-12, with its own event at δ = 0), and the Hertz closed form.
"""


import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar
from scipy.special import gamma

import stochpound
from stochpound.model import laws
from stochpound.model.laws.contract import ElementParameters
from stochpound.solvers.ivp import run_ivp
from stochpound.studies.agarwal2004 import reference_building
from tests.helpers import GAP, K_HERTZ, M_EFF, V0, docs_restitution_column, free_masses, realised_restitution, run


def law_force(law: str, restitution: float | None, delta, rate):
    return laws.contact_law(law).force(ElementParameters(K_HERTZ, 0.0, restitution, True, M_EFF), delta, rate, V0)


def reference_impact(law: str, restitution: float | None) -> dict:
    """The impact from the relative motion alone: duration, peak force and exit velocity."""

    def rate(t, y):
        return [y[1], -law_force(law, restitution, np.array(y[0]), np.array(y[1])) / M_EFF]

    def separated(t, y):
        return y[0]

    separated.terminal, separated.direction = True, -1
    solution = solve_ivp(rate, (0.0, 1.0), [0.0, V0], method="DOP853", rtol=1e-12, atol=1e-16, events=separated, dense_output=True,
                         first_step=1e-6)
    end = float(solution.t_events[0][-1])
    peak = minimize_scalar(lambda t: -law_force(law, restitution, *solution.sol(t)), bounds=(0.0, end), method="bounded",
                           options={"xatol": 1e-14})
    return {"duration": end, "peak": -float(peak.fun), "exit": float(solution.y_events[0][-1][1])}


@pytest.mark.parametrize("law, restitution", [("hertz", None), ("hertz_damp", 0.6), ("jankowski", 0.6)])
def test_a_single_impact_matches_the_relative_motion_integrated_on_its_own(law, restitution):
    result = run(free_masses(law, restitution))
    reference = reference_impact(law, restitution)
    assert result.attrs["solver"] == "ivp" and result.sizes["impact"] == 1
    start, end = float(result.impact_start[0]), float(result.impact_end[0])
    assert start == pytest.approx(GAP / V0, rel=1e-10)
    assert end - start == pytest.approx(reference["duration"], rel=1e-5)
    assert float(result.impact_peak_force[0]) == pytest.approx(reference["peak"], rel=1e-5)
    assert realised_restitution(result) == pytest.approx(-reference["exit"] / V0, rel=1e-6)
    residual = float(np.abs(result.energy_residual).max() / np.abs(result.energy_kinetic).max())
    assert residual < 1e-8  # the energy balance closes with the law's own work


def test_hertz_matches_its_closed_form():
    """δ_max = (5 m_eff δ̇₀² / (4 k_h))^{2/5}, peak force k_h δ_max^{3/2}, duration (4/5) B(2/5, 1/2) δ_max / δ̇₀ ≈ 2.943 δ_max / δ̇₀, no loss."""
    result = run(free_masses("hertz"))
    delta_max = (5.0 * M_EFF * V0**2 / (4.0 * K_HERTZ)) ** 0.4
    factor = 0.8 * gamma(0.4) * gamma(0.5) / gamma(0.9)
    assert factor == pytest.approx(2.943, abs=5e-4)
    assert float(result.impact_duration[0]) == pytest.approx(factor * delta_max / V0, rel=1e-6)
    assert float(result.impact_peak_force[0]) == pytest.approx(K_HERTZ * delta_max**1.5, rel=1e-6)
    assert realised_restitution(result) == pytest.approx(1.0, abs=1e-7)


def test_the_realised_restitution_table_in_the_docs_is_reproduced():
    """docs/model.md tabulates the restitution hertz_damp and jankowski realise against the target; spot-check three rows."""
    columns = {law: docs_restitution_column(law) for law in ("hertz_damp", "jankowski")}
    assert all(len(column) >= 7 for column in columns.values())
    for target in (0.3, 0.6, 0.9):
        for law, column in columns.items():
            assert -reference_impact(law, target)["exit"] / V0 == pytest.approx(float(column[target]), abs=5e-4)


def test_slow_equal_to_fast_friction_is_coulomb():
    """mu = {slow = fast = 0.1}: the ivp path with the velocity-dependent law equals the exact Coulomb run (1e-8 m)."""
    motion = {"record": "el_centro_1940_study", "duration": 10.0}
    coulomb = {"g": 9.81, "building": [reference_building("B1", mu=0.1)], "motion": motion}
    velocity = {"g": 9.81, "building": [reference_building("B1")], "motion": motion}
    velocity["building"][0]["base"] = {"mass": coulomb["building"][0]["base"]["mass"], "mu": {"slow": 0.1, "fast": 0.1, "rate": 20.0}}
    exact, nonlinear = stochpound.simulate(stochpound.scene_from_dict(coulomb)), run(velocity)
    assert nonlinear.attrs["solver"] == "ivp" and "velocity-dependent" in nonlinear.attrs["solver_choice"]
    assert np.abs(exact.sliding_displacement).max() > 1e-3
    np.testing.assert_allclose(nonlinear.total_displacement.values, exact.total_displacement.values, rtol=0, atol=1e-8)


def test_velocity_dependent_friction_follows_its_law_while_slipping():
    """While the base slips, the foundation's force is −sgn(ṡ) W (μ_fast − (μ_fast − μ_slow) e^{−a|ṡ|}); the energy balance closes."""
    slow, fast, rate, mass = 0.06, 0.12, 20.0, 13134.0
    scene = {"g": 9.81, "building": [reference_building("B1")], "motion": {"record": "el_centro_1940_study", "duration": 10.0}}
    scene["building"][0]["base"] = {"mass": mass, "mu": {"slow": slow, "fast": fast, "rate": rate}}
    result = run(scene)
    recorder, _, visited = run_ivp(stochpound.scene_from_dict(scene), rtol=1e-12, atol=1e-15)
    base = visited.system.bases[0]
    state = recorder.base_states[:, 0]
    slipping = state != 0
    assert slipping.sum() > 20
    speed = np.abs(recorder.states[:, visited.system.n_dof + base.dof])
    weight = 9.81 * (mass + sum(scene["building"][0]["mass"]))
    force = result.base_friction_force.sel(building="B1").values
    expected = -state * weight * (fast - (fast - slow) * np.exp(-rate * speed))
    np.testing.assert_allclose(force[slipping], expected[slipping], rtol=1e-12, atol=0)
    assert np.all(np.abs(force[slipping]) >= slow * weight * (1 - 1e-12)) and np.all(np.abs(force[slipping]) <= fast * weight * (1 + 1e-12))
    assert float(np.abs(result.energy_residual).max() / np.abs(result.energy_input).max()) < 1e-8


def test_nonlinear_laws_route_to_ivp_and_refuse_the_exact_solver():
    scene = stochpound.scene_from_dict(free_masses("hertz"))
    with pytest.raises(ValueError, match=r"method='exact' needs piecewise-linear laws, and contact\[0\]\.law = 'hertz' is not"):
        stochpound.simulate(scene, method="exact")


@pytest.mark.parametrize("change, message", [
    ({"law": "hertz", "restitution": 0.5}, r"contact\[0\]\.restitution: law 'hertz' is elastic"),
    ({"law": "hertz_damp", "damping": 1e5}, r"contact\[0\]\.damping: not a field of law 'hertz_damp'"),
    ({"law": "jankowski", "restitution": 1.0}, r"contact\[0\]\.restitution: must be < 1"),
    ({"law": "coulomb"}, r"contact\[0\]\.law: must be one of kelvin, hertz, hertz_damp, jankowski"),
])
def test_contact_law_fields_are_validated(change, message):
    scene = free_masses("hertz_damp", 0.6)
    scene["contact"][0].update(change)
    with pytest.raises(stochpound.SceneError, match=message):
        stochpound.scene_from_dict(scene)
