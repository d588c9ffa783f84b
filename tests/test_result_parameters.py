"""What ran, in a result and in a store: each base's friction law and each contact's and wall's law with its parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest

import stochpound
from stochpound.model.scene_file import scene_from_dict


@pytest.fixture(scope="module")
def run():
    """A pendulum-isolated building beside a fixed one: a Hertz contact, a Kelvin wall with its dashpot given."""
    building = {"mass": [1.0, 1.0], "stiffness": [40.0, 40.0], "damping_ratio": 0.05}
    scene = scene_from_dict(
        {
            "g": 9.81,
            "building": [{"name": "A", **building, "base": {"mass": 2.0, "mu": 0.08, "mu_static": 0.1, "radius": 2.0}}, {"name": "B", **building}],
            "contact": [{"between": [["A", 2], ["B", 2]], "gap": 0.01, "stiffness": 4.0e4, "restitution": 0.5, "law": "hertz_damp"}],
            "wall": [{"building": "A", "side": "left", "level": 0, "gap": 0.1, "stiffness": 100.0, "damping": 1.5, "tensile": False}],
            "motion": {"type": "harmonic", "amplitude": 1.0, "omega": 5.0, "duration": 0.5, "dt": 0.01},
        },
        source="parameters test",
    )
    return stochpound.simulate(scene, "ivp")


def test_a_result_names_its_bases(run) -> None:
    """μ, μ_s, base mass, k_r = W/R and R per building; μ = ∞ and nan for the fixed base."""
    np.testing.assert_array_equal(run["base_mu"].values, [0.08, math.inf])
    np.testing.assert_array_equal(run["base_mu_static"].values, [0.1, math.inf])
    np.testing.assert_array_equal(run["base_mass"].values, [2.0, np.nan])
    np.testing.assert_allclose(run["base_restoring_stiffness"].values, [9.81 * 4.0 / 2.0, np.nan])
    np.testing.assert_array_equal(run["base_radius"].values, [2.0, np.nan])
    assert np.all(np.isnan(run["base_mu_fast"].values)) and np.all(np.isnan(run["base_mu_rate"].values))
    assert run["base_mu"].attrs["units"] == "1" and "inf: a fixed base" in run["base_mu"].attrs["long_name"]


def test_a_result_names_its_contact_and_wall_laws(run) -> None:
    """Law, restitution (nan when the dashpot was given) and the separation rule of every contact and wall."""
    assert list(run["contact_law"].values) == ["hertz_damp"] and list(run["wall_law"].values) == ["kelvin"]
    np.testing.assert_array_equal(run["contact_restitution"].values, [0.5])
    np.testing.assert_array_equal(run["wall_restitution"].values, [np.nan])
    assert bool(run["contact_tensile"].values[0]) and not bool(run["wall_tensile"].values[0])
    np.testing.assert_array_equal(run["contact_stiffness"].values, [4.0e4])
    np.testing.assert_array_equal(run["wall_damping"].values, [1.5])


def test_a_store_names_what_each_grid_point_ran(laws_store) -> None:  # noqa: F811
    """Per grid point: each building's μ (∞ for the fixed one) and each contact's law and stiffness, as the variants set them."""
    store = stochpound.open_store(laws_store[1])
    assert store["base_mu"].dims == ("law", "moat", "gap", "mu", "building")
    np.testing.assert_array_equal(store["base_mu"].sel(building="B1").values, 0.1)
    assert np.all(np.isinf(store["base_mu"].sel(building="B2").values))
    assert set(store["contact_law"].sel(law="hertz_damp").values.ravel()) == {"hertz_damp"}
    assert set(store["contact_law"].sel(law="kelvin").values.ravel()) == {"kelvin"}
    np.testing.assert_array_equal(store["contact_stiffness"].sel(law="hertz_damp").values, 2.75e9)
    np.testing.assert_array_equal(store["contact_gap"].values, 0.005)
    assert "base_mu" not in store["impacts"].coords  # on building: not on the per-case summaries without it
