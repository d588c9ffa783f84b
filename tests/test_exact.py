"""The exact solver against the ivp path (rtol 1e-12), closed forms and the numerical traps of docs/model.md."""

import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import stochpound
from stochpound.motions.ground import GroundMotion, HarmonicMotion, SampledMotion
from stochpound.solvers.propagators import UnsupportedMotionError, exosystem, interval_forcing, propagator_library, sample_ground
from stochpound.model.system import build_system
from stochpound.studies.agarwal2004 import reference_building, study_contacts, study_scene
from tests.helpers import HARD_CASES, assert_same_run, interpreted_scene


def both(scene: dict) -> tuple:
    """The same scene run by the exact solver and by ivp (DOP853, rtol 1e-12)."""
    parsed = stochpound.scene_from_dict(scene)
    exact = stochpound.simulate(parsed, method="exact")
    reference = stochpound.simulate(parsed, method="ivp", rtol=1e-12, atol=1e-14)
    return exact, reference


STUDY_SCENES = {
    "fixed-fixed, B2 flexible, gap 2 cm": study_scene(None, None, 2.0),
    "fixed-fixed, B2 stiff, gap 1 cm": study_scene(None, None, 0.5, gap=0.01),
    "B1 isolated mu=0.2, B2 flexible fixed, gap 2 cm": study_scene(0.2, None, 2.0),
    "B1 isolated mu=0.2, B2 stiff fixed, gap 1 cm": study_scene(0.2, None, 0.5, gap=0.01),
    "both isolated mu=0.1, B2 stiff, gap 1 cm": study_scene(0.1, 0.1, 0.5, gap=0.01),
}


@pytest.mark.parametrize("name", list(STUDY_SCENES))
def test_study_scenes_match_ivp(name):
    exact, reference = both(STUDY_SCENES[name])
    assert reference.sizes["impact"] > 0
    assert_same_run(exact, reference)


def test_zero_gap_fixed_buildings():
    exact, reference = both(study_scene(None, None, 0.5, gap=0.0, motion={"record": "el_centro_1940_study", "duration": 20.0}))
    assert reference.sizes["impact"] > 10
    assert_same_run(exact, reference)


def test_zero_gap_isolated_building_settles_against_its_neighbour():
    """Chattering contact of a frictionless building pushed against a fixed one: progress, and the same impacts."""
    scene = {
        "building": [reference_building("B1", mu=0.0), reference_building("B2", 2.0)],
        "contact": study_contacts(0.0, mass_factor=2.0),
        "motion": {"type": "constant", "acceleration": -0.5, "duration": 20.0, "dt": 0.02},
    }
    exact, reference = both(scene)
    assert reference.sizes["impact"] > 50
    assert_same_run(exact, reference)


def test_frictionless_base():
    exact, reference = both(study_scene(0.0, None, 2.0, motion={"record": "el_centro_1940_study", "duration": 20.0}))
    assert float(exact.energy_friction[-1]) == 0.0
    assert_same_run(exact, reference)


def test_very_stiff_contacts():
    """Contacts 10× shorter than a sample interval (stiffness × 100): sub-steps and the Hermite screen find them all."""
    scene = study_scene(None, None, 2.0, motion={"record": "el_centro_1940_study", "duration": 10.0})
    for contact in scene["contact"]:
        contact["stiffness"] *= 100.0
    exact, reference = both(scene)
    assert float(reference.impact_duration.max()) < 0.01
    assert_same_run(exact, reference)


@pytest.mark.parametrize("excess", [1e-6, 1e-3])
def test_block_slips_just_above_mu_g_under_harmonic_input(excess):
    mu, g = 0.2, 9.81
    scene = {
        "g": g,
        "building": [{"name": "block", "mass": [], "stiffness": [], "base": {"mass": 1000.0, "mu": mu}}],
        "motion": {"type": "harmonic", "amplitude": mu * g * (1 + excess), "omega": 2 * np.pi, "duration": 5.0, "dt": 0.01},
    }
    exact, reference = both(scene)
    assert exact.attrs["events_total"] >= 10
    assert_same_run(exact, reference, tolerance=1e-12)


def test_block_under_constant_acceleration_just_above_mu_g():
    """Constant a_g = μg(1 + 1e-6): the block slips from t = 0 with relative acceleration 1e-6 μg."""
    mu, g = 0.2, 9.81
    scene = {
        "g": g,
        "building": [{"name": "block", "mass": [], "stiffness": [], "base": {"mass": 1000.0, "mu": mu}}],
        "motion": {"type": "constant", "acceleration": mu * g * (1 + 1e-6), "duration": 2.0, "dt": 0.01},
    }
    exact, reference = both(scene)
    s = exact.sliding_displacement.values[0]
    np.testing.assert_allclose(s, -0.5 * 1e-6 * mu * g * exact.time.values**2, rtol=1e-9, atol=1e-15)
    assert_same_run(exact, reference, tolerance=1e-12)


def test_near_threshold_stick_slip_of_a_building():
    scene = {
        "g": 9.81,
        "building": [reference_building("B1", mu=0.05)],
        "motion": {"type": "harmonic", "amplitude": 0.35, "omega": 8.0, "duration": 10.0, "dt": 0.01},
    }
    exact, reference = both(scene)
    states = exact.base_state.values
    assert np.any(states != 0) and np.any(states == 0)
    assert_same_run(exact, reference)


def test_spline_interpolated_record_is_exact_too():
    motion = {"record": "el_centro_1940_study", "duration": 10.0, "interpolation": "spline"}
    exact, reference = both(study_scene(0.2, None, 2.0, motion=motion))
    assert_same_run(exact, reference)


# ---------------------------------------------------------------- propagators


def test_exosystem_reproduces_the_motion_inside_an_interval():
    """exp(S τ) w(t_k) is the interpolating polynomial (or the sine) at t_k + τ."""
    from scipy.linalg import expm

    sampled = SampledMotion(0.02, np.sin(np.arange(30) * 0.7), interpolation="spline")
    harmonic = HarmonicMotion(3.0, 7.0, 1.0, 0.02, phase=0.3)
    for motion in (sampled, harmonic):
        w = interval_forcing(motion)
        for k, tau in ((3, 0.013), (17, 0.02)):
            expected = motion.derivatives(motion.times[k] + tau, k)
            np.testing.assert_allclose(expm(exosystem(motion) * tau) @ w[k], expected, rtol=1e-12, atol=1e-12)
        ground = [motion.acceleration(t, min(k, len(motion.times) - 2)) for k, t in enumerate(motion.times)]
        np.testing.assert_array_equal(sample_ground(motion), ground)


@pytest.mark.parametrize("method", ["exact", "ivp"])
def test_unsupported_motion_is_named(method):
    class Other(GroundMotion):
        times = np.arange(5) * 0.1

    scene = stochpound.scene_from_dict(study_scene())
    with pytest.raises(UnsupportedMotionError, match="sampled .* and harmonic ground motions, not Other"):
        stochpound.simulate(dataclasses.replace(scene, motion=Other()), method=method)


def test_propagators_are_cached_across_runs_and_hold_stuck_bases_exactly():
    scene = stochpound.scene_from_dict(study_scene(0.2, None, 2.0, motion={"record": "el_centro_1940_study", "duration": 5.0}))
    first = stochpound.simulate(scene, method="exact")
    library = propagator_library(build_system(scene), scene.motion)
    built = len(library)
    assert built == first.attrs["modes_visited"]
    again = stochpound.simulate(scene, method="exact")
    assert len(library) == built
    np.testing.assert_array_equal(first.total_displacement.values, again.total_displacement.values)
    stuck = scene.motion.dt * 0 + first.base_state.sel(building="B1").values == 0
    velocity_free = np.diff(first.sliding_displacement.sel(building="B1").values)
    assert np.all(velocity_free[stuck[:-1] & stuck[1:]] == 0.0)  # s constant to the last bit while stuck


# ---------------------------------------------------------------- hard cases, and the engine run by Python


@pytest.mark.parametrize("name", list(HARD_CASES))
def test_hard_cases_match_ivp(name):
    """The exact flow and DOP853's (rtol 1e-12) through the one event engine: the same events, impacts and outputs."""
    exact, reference = both(HARD_CASES[name])
    assert exact.attrs["events_total"] == reference.attrs["events_total"]
    assert exact.attrs["events_chatter_cycles"] == reference.attrs["events_chatter_cycles"]
    assert_same_run(exact, reference)


INTERPRETED_PROBE = """
import json
import stochpound
from tests.helpers import interpreted_scene

scene = interpreted_scene()
runs = {method: stochpound.simulate(stochpound.scene_from_dict(scene), method=method) for method in ("exact", "ivp")}
print(json.dumps({method: {"y": run.total_displacement.values[:, :, ::10].ravel().tolist(), "starts": run.impact_start.values.tolist(),
                           "events": run.attrs["events_total"]} for method, run in runs.items()}))
"""


@pytest.mark.slow
def test_interpreted_engine_gives_the_compiled_results():
    """NUMBA_DISABLE_JIT (the debugging path: the engine's code run by Python) reproduces the compiled engine, exact and ivp."""
    import json

    scene = interpreted_scene()
    environment = dict(os.environ, NUMBA_DISABLE_JIT="1")
    result = subprocess.run([sys.executable, "-c", INTERPRETED_PROBE], cwd=Path(__file__).parents[1], env=environment,
                            capture_output=True, text=True, timeout=600, check=False)
    assert result.returncode == 0, result.stderr[-2000:]
    interpreted = json.loads(result.stdout.splitlines()[-1])
    for method in ("exact", "ivp"):
        compiled = stochpound.simulate(stochpound.scene_from_dict(scene), method=method)
        assert compiled.sizes["impact"] > 0
        assert interpreted[method]["events"] == compiled.attrs["events_total"]
        np.testing.assert_allclose(interpreted[method]["starts"], compiled.impact_start.values, rtol=0, atol=1e-12)
        np.testing.assert_allclose(interpreted[method]["y"], compiled.total_displacement.values[:, :, ::10].ravel(), rtol=0, atol=1e-13)


def test_a_sub_step_product_gives_the_next_state_and_its_guards():
    """One product of z(t0) with a mode's ``propagate`` rows: z(t0 + h), then (past the forms) the guards' and monitors' values and rates there."""
    from stochpound.solvers import engine, tables

    scene = stochpound.scene_from_dict(study_scene(0.2, 0.1, 2.0, motion={"record": "el_centro_1940_study", "duration": 5.0}))
    stochpound.simulate(scene)
    library = propagator_library(build_system(scene), scene.motion)
    slots = tables.slots_of(library)
    size, n_contacts = 2 * library.system.n_dof, library.system.n_elements
    padded = slots.arrays["guard"].shape[1]
    rng = np.random.default_rng(5)
    for mode in library:
        propagator = library[mode]
        dynamics = propagator.dynamics
        z0 = np.concatenate([rng.normal(scale=0.05, size=size), rng.normal(size=4), [1.0]])
        out = z0 @ slots.arrays["propagate"][slots.slot(mode)]
        z1 = propagator.transition @ z0
        x1, ground, ground_rate = z1[:size], z1[size], z1[size + 1]
        n = len(dynamics.guard_kind)
        values_at = 5 * len(z0) + n_contacts
        values, rates = out[values_at : values_at + n], out[values_at + padded : values_at + padded + n]
        np.testing.assert_allclose(out[: len(z0)], z1, rtol=1e-13, atol=1e-15)
        np.testing.assert_allclose(values, dynamics.guards(x1, ground), rtol=1e-12, atol=1e-12)
        expected = dynamics.guard_matrix @ dynamics.rate(x1, ground) + dynamics.guard_ground * ground_rate
        np.testing.assert_allclose(rates, expected, rtol=1e-12, atol=1e-12)
        monitors_at, m = values_at + 2 * padded, len(dynamics.monitor_constant)
        closure = dynamics.monitor_matrix @ x1 + dynamics.monitor_ground * ground + dynamics.monitor_constant
        np.testing.assert_allclose(out[monitors_at : monitors_at + m], closure, rtol=1e-12, atol=1e-14)
        expected = dynamics.monitor_matrix @ dynamics.rate(x1, ground) + dynamics.monitor_ground * ground_rate
        np.testing.assert_allclose(out[monitors_at + m : monitors_at + 2 * m], expected, rtol=1e-12, atol=1e-14)
        assert out.shape[0] % engine.LANES == 0 and not np.any(out[monitors_at + 2 * m :])
