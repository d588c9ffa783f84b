"""The fixed-base twin's recursion: the exact solver's response, whatever batch a realization is computed in."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import stochpound
from stochpound import motions
from stochpound.motions.ground import HarmonicMotion, SampledMotion
from stochpound.solvers.twin import fixed_base_displacements
from stochpound.studies.agarwal2004 import reference_building

PLACEHOLDER = {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 1.0}


def _building(**extra) -> stochpound.model.scene.Scene:
    return stochpound.scene_from_dict({"g": 9.814, "building": [reference_building("B1", **extra)], "motion": PLACEHOLDER})


@pytest.fixture(scope="module")
def realizations() -> list[SampledMotion]:
    values = motions.kanai_tajimi(12, 20.0, 0.02, omega_g=15.0, zeta_g=0.6, pga=3.0, envelope="jennings", seed=3).values
    return [SampledMotion(0.02, row, "linear") for row in values]


def test_the_recursion_is_the_exact_solvers_response(realizations):
    """Linear and spline input, a harmonic motion, initial conditions: agreement with the event-driven exact solver to rounding."""
    scene = _building()
    cases = [*realizations[:3], SampledMotion(0.02, realizations[3].values, "spline"), HarmonicMotion(3.0, 9.0, 10.0, 0.01, 0.4)]
    twins = [fixed_base_displacements(scene, [motion])[0] for motion in cases]
    moving = _building(initial={"displacement": [0.01, 0.02], "velocity": [0.0, -0.1]})
    cases.append(realizations[4])
    twins.append(fixed_base_displacements(moving, [realizations[4]])[0])
    for motion, twin, base in zip(cases, twins, [scene] * 5 + [moving]):
        exact = stochpound.simulate(dataclasses.replace(base, motion=motion))["total_displacement"].values[0]
        assert twin.shape == exact.shape
        assert np.abs(twin - exact).max() <= 1e-12 * np.abs(exact).max()


def test_a_realization_is_bitwise_the_same_in_any_batch(realizations):
    scene = _building()
    together = fixed_base_displacements(scene, realizations)
    for start, stop in [(0, 1), (5, 6), (3, 11), (11, 12)]:
        assert np.array_equal(fixed_base_displacements(scene, realizations[start:stop]), together[start:stop])


def test_only_a_fixed_base_building_alone_is_a_twin(realizations):
    with pytest.raises(ValueError, match="one building on a fixed base"):
        fixed_base_displacements(_building(mu=0.2), realizations[:1])
