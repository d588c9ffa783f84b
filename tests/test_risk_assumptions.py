"""What a risk answer rests on, listed in the design summary: each assumption said where it applies and not where it does not (issue 45).

Scenes are built from the flagship's isolated scene (tests.helpers.ISOLATED:
B1 on a friction pendulum beside a fixed B2) with its storeys, walls and base
changed one at a time; every expected number is read off the scene.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import tomllib


from stochpound.model.scene_file import scene_from_dict
from stochpound.risk._assumptions import scene_assumptions, simulated_motions_text
from stochpound.risk._design_rules import design_assumptions
from stochpound.store import Design, DesignIsolation
from tests.helpers import ISOLATED

MOTION = {"type": "harmonic", "amplitude": 1.0, "omega": 5.0, "duration": 1.0, "dt": 0.01}
WALL = {"building": "B1", "side": "left", "level": 0, "gap": 0.6, "stiffness": 42747262.6, "restitution": 0.5}
DESIGN = Design(sds=1.32925, sd1=0.80204, tl=8.0, r=8.0, cd=5.5, omega0=3.0, ie=1.0)


def _scene(edit=None):
    table = copy.deepcopy(tomllib.loads(ISOLATED)["scene"])
    table["motion"] = MOTION
    if edit is not None:
        edit(table)
    return scene_from_dict(table)


def _yielding(table):
    for building in table["building"]:
        building.update(storey_height=[3.0, 3.5], yield_force=[2.0e5, 1.2e5], hardening=0.02, p_delta=True)


def _fixed(table):
    table["building"][0].pop("base")


def _walls(table):
    table["wall"] = [WALL]


def test_the_storeys_say_heights_and_no_collapse_model_where_they_yield_and_linear_storeys_where_they_do_not():
    elastic = scene_assumptions({(): _scene()})["storeys"]
    assert "B1: no storey heights (no drift ratios), damping ratio 5 %, linear elastic storeys (no yielding)" in elastic
    assert elastic.endswith("The storeys stay linear at any amplitude (no yielding, strength loss or collapse)")
    assert "collapses (no such model)" not in elastic
    scene = _scene(_yielding)
    yielding = scene_assumptions({(): scene})["storeys"]
    weight = scene.g * sum(scene.buildings[0].mass)
    assert (f"B1: storey heights 3, 3.5 m (the drift ratios, their limit states and P-Δ rest on them), damping ratio 5 %, bilinear "
            f"storeys, F_y = 200, 120 kN (first storey {2.0e5 / weight:.3g} W), hardening 2 %, P-Δ") in yielding
    assert "No storey loses strength, degrades or collapses (no such model)" in yielding and "stay linear" not in yielding


def test_coulomb_friction_and_the_pendulum_are_said_for_a_sliding_base_only():
    scene = _scene()
    base = scene.buildings[0].base
    said = scene_assumptions({(0.05,): scene, (0.08,): _scene(lambda t: t["building"][0]["base"].update(mu=0.08))})["sliding base"]
    period = 2 * math.pi * math.sqrt(base.radius / scene.g)
    assert said == (f"B1: Coulomb friction, μ = 0.05, 0.08, the same at every velocity, pressure and temperature (no heating, wear or "
                    f"velocity dependence), on a friction pendulum of radius 2.24 m (T = {period:.3g} s), base mass 13134 kg")
    assert "sliding base" not in scene_assumptions({(): _scene(_fixed)})
    fast = scene_assumptions({(): _scene(lambda t: t["building"][0]["base"].update(mu={"slow": 0.03, "fast": 0.08, "rate": 20.0}))})
    assert "velocity-dependent friction, μ = 0.03 (slow) to 0.08 (fast), rate 20 s/m" in fast["sliding base"]
    assert "Coulomb" not in fast["sliding base"]


def test_the_moat_walls_stiffness_is_said_with_its_frequency_where_the_scene_has_walls():
    without = scene_assumptions({("none",): _scene()})
    assert "moat walls" not in without and "moat wall is reached" not in without["gap identity"]
    walled = scene_assumptions({("none",): _scene(), ("wall",): _scene(_walls)})
    omega = math.sqrt(WALL["stiffness"] / 13134.0)
    assert walled["moat walls"] == (f"B1 at the base, clearance 0.6 m, stiffness 4.27e+07 N/m (√(k/m) = {omega:.3g} rad/s on 13134 kg), "
                                    "restitution 0.5, law kelvin (each an impact element against a rigid wall moving with the ground)")
    assert walled["gap identity"].endswith("likewise a moat wall is reached if and only if the wall-free run's base displacement "
                                           "reaches its clearance")


def test_the_gap_identity_is_always_said():
    for scenes in ({}, {(): _scene()}):
        assert scene_assumptions(scenes)["gap identity"].startswith("a run with gap g pounds if and only if its contact-free twin's peak "
                                                                    "closure reaches g")


def test_the_code_design_and_chapter_17_s_defaults_are_said_for_a_pendulum_only():
    assert design_assumptions(None, {(): _scene()}) == {}
    fixed = design_assumptions(DESIGN, {(): _scene(_fixed)})
    assert list(fixed) == ["code design"] and fixed["code design"].startswith(
        "ASCE 7-16: S_DS = 1.329 g, S_D1 = 0.802 g, T_L = 8 s, R = 8, C_d = 5.5, Ω0 = 3, I_e = 1, as the [design] gives them")
    square = design_assumptions(DESIGN, {(): _scene()})["chapter 17 (B1)"]
    # no site SA given: S_MS = 1.5 S_DS and S_M1 = 1.5 S_D1; no plan: the square plan's D_TM = 1.15 D_M; the property-modification defaults
    assert square.startswith("MCE_R spectrum S_MS = 1.5 S_DS of the [design]; S_M1 = 1.5 S_D1 of the [design]")
    assert "square plan assumed (no [design.isolation] plan)" in square and "λ_max = 1.8, λ_min = 0.6 assumed on μ" in square
    isolation = DesignIsolation(plan=(12.0, 18.0), lambda_max=1.6, lambda_min=0.7)
    planned = design_assumptions(dataclasses.replace(DESIGN, isolation=isolation), {(): _scene()})["chapter 17 (B1)"]
    assert "e = 0.05 d = 0.9 m assumed (accidental only)" in planned and "y = d/2 = 9 m assumed (the far corner)" in planned
    assert "square plan" not in planned and "λ_max = 1.8" not in planned


def test_simulated_motions_are_said_where_they_ran():
    assert simulated_motions_text(0, 40, "hazard_compatible", "nga_west2_calibration_3") == ""
    assert simulated_motions_text(266, 277, "hazard_compatible", "nga_west2_calibration_3") == (
        "266 simulated motions of the 277 that ran (hazard_compatible site-motion model, calibration nga_west2_calibration_3): their "
        "spectra, durations and variability are the model's as calibrated, not recorded ones")
