"""The inelastic-demand benchmark's oscillator and building (benchmarks/inelastic_demand.py)."""

from __future__ import annotations

import functools
import tomllib

import numpy as np

from benchmarks import inelastic_demand


def test_c_r_of_the_exact_solver_equals_an_independent_newmark_integration():
    """Elastoplastic C_R at R = 2, 4, 6 under a short non-stationary motion: two integrators, one answer."""
    dt = 0.01
    t = np.arange(0.0, 4.0, dt)
    rng = np.random.default_rng(3)
    acceleration = 4.0 * np.sin(t * np.pi / 4.0) ** 2 * np.convolve(rng.standard_normal(t.size), np.ones(5) / 5.0, "same")
    exact = inelastic_demand.inelastic_ratios(acceleration, dt)
    newmark = inelastic_demand.inelastic_ratios(acceleration, dt, functools.partial(inelastic_demand.newmark_peak, substeps=10))
    assert exact[-1] > exact[0] > 0.5  # the oscillator yields
    np.testing.assert_allclose(exact, newmark, rtol=2e-3)


def test_the_building_is_the_flagship_s_building_1_on_a_fixed_base():
    definition = tomllib.loads(inelastic_demand.EXPERIMENT.read_text())["scene"]["building"][0]
    yielding, elastic = inelastic_demand.frame_scene(True), inelastic_demand.frame_scene(False)
    building = yielding.buildings[0]
    assert building.base is None and not yielding.contacts and len(yielding.buildings) == 1
    np.testing.assert_allclose(building.stiffness, definition["stiffness"])
    np.testing.assert_allclose(building.yield_force, definition["yield_force"])
    assert building.p_delta and building.hardening == definition["hardening"] and elastic.buildings[0].yield_force is None
