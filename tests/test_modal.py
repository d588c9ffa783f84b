"""Fixed-base reference building under harmonic ground acceleration vs the closed-form modal solution."""

import numpy as np
import pytest
from scipy.linalg import eigh

import stochpound
from stochpound.scene import storey_matrix
from tests.conftest import REFERENCE_DAMPING, REFERENCE_MASS, REFERENCE_STIFFNESS, reference_building

AMPLITUDE = 10.0  # m/s²


def modal_solution(times: np.ndarray, omega_ground: float) -> np.ndarray:
    """Exact u(t) (floors × times) of the classically damped building from rest, a_g = A sin(Ω t)."""
    mass = np.diag(REFERENCE_MASS)
    stiffness = storey_matrix(np.array(REFERENCE_STIFFNESS))
    damping = storey_matrix(np.array(REFERENCE_DAMPING))
    eigenvalues, shapes = eigh(stiffness, mass)  # mass-normalised shapes
    response = np.zeros((2, len(times)))
    for n in range(2):
        phi = shapes[:, n]
        omega = np.sqrt(eigenvalues[n])
        zeta = phi @ damping @ phi / (2 * omega)
        participation = phi @ mass @ np.ones(2)
        # particular solution X sin + Y cos of η'' + 2ζωη' + ω²η = −Γ A sin(Ωt)
        matrix = np.array([[omega**2 - omega_ground**2, -2 * zeta * omega * omega_ground],
                           [2 * zeta * omega * omega_ground, omega**2 - omega_ground**2]])
        x_coef, y_coef = np.linalg.solve(matrix, [-participation * AMPLITUDE, 0.0])
        omega_d = omega * np.sqrt(1 - zeta**2)
        c1 = -y_coef
        c2 = (zeta * omega * c1 - omega_ground * x_coef) / omega_d
        eta = (x_coef * np.sin(omega_ground * times) + y_coef * np.cos(omega_ground * times)
               + np.exp(-zeta * omega * times) * (c1 * np.cos(omega_d * times) + c2 * np.sin(omega_d * times)))
        response += np.outer(phi, eta)
    return response


@pytest.mark.parametrize("omega_ground", [2.0, 10.0])
def test_fixed_base_building_matches_modal_solution(omega_ground):
    scene = stochpound.scene_from_dict({
        "building": [reference_building()],
        "motion": {"type": "harmonic", "amplitude": AMPLITUDE, "omega": omega_ground, "duration": 15.0, "dt": 0.01},
    })
    run = stochpound.simulate(scene, method="ivp", rtol=1e-12, atol=1e-14)
    computed = run.relative_displacement.sel(building="B1").values
    exact = modal_solution(run.time.values, omega_ground)
    assert np.max(np.abs(computed - exact)) <= 1e-9
    # the study's check: displacements stay within ±5 cm
    assert np.max(np.abs(exact)) < 0.05
    assert np.array_equal(run.total_displacement.values, run.relative_displacement.values)
