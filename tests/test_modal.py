"""Fixed-base reference building under harmonic ground acceleration vs the closed-form modal solution."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import stochpound
from stochpound.model.modal_solution import harmonic_response, modal_coordinate
from stochpound.studies.agarwal2004 import reference_building

AMPLITUDE = 10.0  # m/s²


@pytest.mark.parametrize(("natural", "ratio", "omega"), [(20.74, 0.01, 2.0), (46.58, 0.0224, 10.0), (5.0, 0.3, 5.0), (3.0, 0.0, 7.0)])
def test_modal_coordinate_solves_its_equation_from_rest(natural, ratio, omega):
    """The closed form against a tight numerical solution of the same scalar equation."""
    force = -3.0
    times = np.linspace(0.0, 10.0, 2001)

    def rate(t, state):
        return [state[1], force * np.sin(omega * t) - 2 * ratio * natural * state[1] - natural**2 * state[0]]

    numerical = solve_ivp(rate, (0.0, 10.0), [0.0, 0.0], method="DOP853", t_eval=times, rtol=1e-12, atol=1e-15).y[0]
    closed = modal_coordinate(natural, ratio, force, omega, times)
    assert np.max(np.abs(closed - numerical)) <= 1e-10 * max(1.0, np.max(np.abs(numerical)))
    assert closed[0] == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("omega_ground", [2.0, 10.0])
def test_fixed_base_building_matches_modal_solution(omega_ground):
    scene = stochpound.scene_from_dict({
        "building": [reference_building()],
        "motion": {"type": "harmonic", "amplitude": AMPLITUDE, "omega": omega_ground, "duration": 15.0, "dt": 0.01},
    })
    run = stochpound.simulate(scene, method="ivp", rtol=1e-12, atol=1e-14)
    computed = run.relative_displacement.sel(building="B1").values
    exact = harmonic_response(scene.buildings[0], AMPLITUDE, omega_ground, run.time.values)
    assert np.max(np.abs(computed - exact)) <= 1e-9
    # the study's check: displacements stay within ±5 cm
    assert np.max(np.abs(exact)) < 0.05
    assert np.array_equal(run.total_displacement.values, run.relative_displacement.values)
    exact_solver = stochpound.simulate(scene, method="exact").relative_displacement.sel(building="B1").values
    assert np.max(np.abs(exact_solver - exact)) <= 1e-9


def test_non_classical_damping_is_refused():
    building = dict(reference_building(), damping=[50000.0, 100.0])
    scene = stochpound.scene_from_dict({"building": [building], "motion": {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 0.1}})
    with pytest.raises(ValueError, match="not classical"):
        harmonic_response(scene.buildings[0], AMPLITUDE, 2.0, np.linspace(0, 1, 5))
