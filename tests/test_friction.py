"""Coulomb sliding of a base: exact stopping, sticking below μg and slipping above it."""

import numpy as np
import pytest

import stochpound
from stochpound.studies.agarwal2004 import REFERENCE_MASS, reference_building

G = 9.81
MU = 0.2


def block(base_velocity: float = 0.0, acceleration: float = 0.0, duration: float = 1.0, dt: float = 0.01, mu_static: float | None = None) -> dict:
    """A sliding base with no floors: a rigid block of mass 13 134 kg."""
    base = {"mass": 13134.0, "mu": MU}
    if mu_static is not None:
        base["mu_static"] = mu_static
    return {
        "g": G,
        "building": [{"name": "block", "mass": [], "stiffness": [], "base": base, "initial": {"base_velocity": base_velocity}}],
        "motion": {"type": "constant", "acceleration": acceleration, "duration": duration, "dt": dt},
    }


def simulate(scene: dict):
    return stochpound.simulate(stochpound.scene_from_dict(scene), method="ivp", rtol=1e-12, atol=1e-14)


def test_block_launched_stops_at_the_coulomb_distance():
    v0 = 1.3
    run = simulate(block(base_velocity=v0, duration=1.5))
    t = run.time.values
    s = run.sliding_displacement.sel(building="block").values
    stop_time = v0 / (MU * G)
    sliding = t < stop_time
    assert np.max(np.abs(s[sliding] - (v0 * t[sliding] - 0.5 * MU * G * t[sliding] ** 2))) <= 1e-9
    assert np.max(np.abs(s[~sliding] - v0**2 / (2 * MU * G))) <= 1e-9
    state = run.base_state.sel(building="block").values
    assert np.all(state[sliding][1:] == 1) and np.all(state[~sliding] == 0)
    # the kinetic energy went into friction
    assert float(run.energy_friction[-1]) == pytest.approx(0.5 * 13134.0 * v0**2, rel=1e-10)


def test_block_below_mu_g_never_slips():
    run = simulate(block(acceleration=0.999 * MU * G))
    assert np.all(run.sliding_displacement.values == 0.0)
    assert np.all(run.base_state.values == 0)
    assert np.allclose(run.base_friction_force.values, 13134.0 * 0.999 * MU * G, rtol=1e-12)


def test_block_above_mu_g_slips_with_the_exact_relative_acceleration():
    acceleration = 1.5 * MU * G
    run = simulate(block(acceleration=acceleration))
    t = run.time.values
    expected = -0.5 * (acceleration - MU * G) * t**2
    assert np.max(np.abs(run.sliding_displacement.sel(building="block").values - expected)) <= 1e-9
    assert np.all(run.base_state.values[0, 1:] == -1)


def test_static_friction_holds_until_mu_static():
    acceleration = 1.2 * MU * G  # above μ g, below μ_s g
    run = simulate(block(acceleration=acceleration, mu_static=1.3 * MU))
    assert np.all(run.sliding_displacement.values == 0.0)


def building_in_static_equilibrium(acceleration: float) -> dict:
    """The reference building on its base, floors pre-deflected by the constant inertial load."""
    from scipy.linalg import solve

    from stochpound.model.building import storey_matrix
    from stochpound.studies.agarwal2004 import REFERENCE_STIFFNESS

    deflection = solve(storey_matrix(np.array(REFERENCE_STIFFNESS)), -np.array(REFERENCE_MASS) * acceleration)
    building = reference_building("B1", mu=MU, initial={"displacement": list(deflection)})
    return {"g": G, "building": [building], "motion": {"type": "constant", "acceleration": acceleration, "duration": 2.0, "dt": 0.01}}


def test_building_below_mu_g_never_slips_and_stays_at_rest():
    acceleration = 0.99 * MU * G
    run = simulate(building_in_static_equilibrium(acceleration))
    assert np.all(run.sliding_displacement.values == 0.0)
    u = run.relative_displacement.sel(building="B1").values
    assert np.max(np.abs(u - u[:, :1])) <= 1e-12


def test_building_above_mu_g_centre_of_mass_slides_at_the_exact_rate():
    acceleration = 2.0 * MU * G
    run = simulate(building_in_static_equilibrium(acceleration))
    floors = np.array(REFERENCE_MASS)
    base_mass = 0.5 * REFERENCE_MASS[0]
    y = run.total_displacement.sel(building="B1").values
    s = run.sliding_displacement.sel(building="B1").values
    centre = (floors @ (y - y[:, :1]) + base_mass * s) / (floors.sum() + base_mass)
    t = run.time.values
    assert np.all(run.base_state.values[0, 1:] == -1)  # slipping left all along
    assert np.max(np.abs(centre + 0.5 * (acceleration - MU * G) * t**2)) <= 1e-9


def test_frictionless_pendulum_swings_with_period_two_pi_root_r_over_g():
    """A rigid block on a friction pendulum (radius R, μ = 0) released from s0: s = s0 cos(√(g/R) t), period 2π √(R/g)."""
    radius, s0 = 2.24, 0.1
    scene = block(duration=6.0, dt=0.01)
    scene["building"][0]["base"].update(mu=0.0, radius=radius)
    scene["building"][0]["initial"] = {"base_displacement": s0}
    for method in ("exact", "ivp"):
        run = stochpound.simulate(stochpound.scene_from_dict(scene), method=method)
        t, s = run.time.values, run.sliding_displacement.sel(building="block").values
        np.testing.assert_allclose(s, s0 * np.cos(np.sqrt(G / radius) * t), rtol=0, atol=1e-9)


def test_radius_is_the_restoring_stiffness_w_over_r():
    """radius = R runs exactly as restoring_stiffness = W/R (W the weight of the base and its floors)."""
    radius, mu = 2.24, 0.05
    motion = {"record": "el_centro_1940_study", "duration": 10.0}
    pendulum = {"g": G, "building": [reference_building("B1", mu=mu)], "motion": motion}
    pendulum["building"][0]["base"]["radius"] = radius
    weight = G * (pendulum["building"][0]["base"]["mass"] + sum(REFERENCE_MASS))
    spring = {"g": G, "building": [reference_building("B1", mu=mu)], "motion": motion}
    spring["building"][0]["base"]["restoring_stiffness"] = weight / radius
    runs = [stochpound.simulate(stochpound.scene_from_dict(scene)) for scene in (pendulum, spring)]
    assert np.abs(runs[0].sliding_displacement).max() > 1e-3  # it slides
    np.testing.assert_allclose(runs[0].total_displacement.values, runs[1].total_displacement.values, rtol=0, atol=1e-10)


def test_radius_and_restoring_stiffness_together_are_refused():
    scene = block()
    scene["building"][0]["base"].update(radius=2.0, restoring_stiffness=1e5)
    with pytest.raises(stochpound.SceneError, match=r"building\[0\]\.base\.radius: give either radius"):
        stochpound.scene_from_dict(scene)
