"""Momentum of two frictionless isolated buildings, one launched at the other, no ground motion."""

import numpy as np
import stochpound
from stochpound.studies.agarwal2004 import REFERENCE_MASS, reference_building, study_contacts

V0 = 0.3  # m/s
GAP = 0.02  # m
FLOORS = np.array(REFERENCE_MASS)
BASE = 0.5 * REFERENCE_MASS[0]
BUILDING_MASS = FLOORS.sum() + BASE


def launched_pair(study_compat: bool) -> dict:
    return {
        "study_compat": study_compat,
        "building": [reference_building("B1", mu=0.0, initial={"base_velocity": V0}), reference_building("B2", mu=0.0)],
        "contact": study_contacts(GAP, mass_factor=1.0),
        "motion": {"type": "constant", "acceleration": 0.0, "duration": 3.0, "dt": 0.01},
    }


def run(study_compat: bool):
    return stochpound.simulate(stochpound.scene_from_dict(launched_pair(study_compat)), method="ivp", rtol=1e-12, atol=1e-14)


def centre_of_mass(result) -> np.ndarray:
    """Centre of mass of both buildings and bases, m, relative to the ground."""
    y = result.total_displacement.values  # building, floor, time
    s = result.sliding_displacement.values
    return (np.einsum("f,bft->t", FLOORS, y) + BASE * s.sum(axis=0)) / (2 * BUILDING_MASS)


def test_total_momentum_is_conserved_through_the_impacts():
    result = run(study_compat=False)
    assert result.sizes["impact"] >= 2
    t = result.time.values
    # constant momentum <=> the centre of mass moves at the initial momentum / total mass
    expected = V0 * BUILDING_MASS * t / (2 * BUILDING_MASS)
    assert np.max(np.abs(centre_of_mass(result) - expected)) <= 1e-9 * np.max(np.abs(expected))
    # the impacts stop B1 from entering B2: penetration stays millimetric
    y = result.total_displacement
    penetration = (y.sel(building="B1") - y.sel(building="B2") - GAP).max()
    assert float(penetration) < 0.01


def test_study_compat_lets_the_isolated_building_drive_through_its_neighbour():
    """Without Σf in the base equation (the study's eq. 2.32), impacts cannot change a building's momentum."""
    result = run(study_compat=True)
    y = result.total_displacement
    penetration = (y.sel(building="B1", floor=1) - y.sel(building="B2", floor=1) - GAP).max()
    assert float(penetration) > 0.3  # tens of centimetres: B1 passes through B2
    assert float(result.impact_peak_force.max()) > 1e7  # ten-meganewton contact forces
    # the momentum of B1 alone is unchanged by its impacts: its centre of mass moves at V0 throughout
    y1 = result.total_displacement.sel(building="B1").values
    s1 = result.sliding_displacement.sel(building="B1").values
    centre_1 = (FLOORS @ y1 + BASE * s1) / BUILDING_MASS
    t = result.time.values
    assert np.max(np.abs(centre_1 - V0 * t)) <= 1e-9 * V0 * t[-1]
    # while its base is pushed towards the neighbour, beyond where the floors are
    assert np.max(s1 - y1[0]) > 0.1
    # the energy balance still closes: the error is in the model, not the solver
    assert float(abs(result.energy_residual).max()) <= 1e-6 * float(abs(result.energy_impact).max())
