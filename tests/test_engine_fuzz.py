"""Fuzz of the event engine over contact stiffness, gap, restitution, tensile or not, and contact law (deterministic seeds).

Stiffness 1e5 … 1e10 (N/m for ``kelvin``, N/m^1.5 for ``hertz_damp`` and
``jankowski``), gaps 0, 1e-9, 1e-6, 1e-3 and 0.02 m: zero and nearly zero
gaps start a collision within the first step, where a guard starts within its
tolerance of zero (the bracket of Brent's root search failed there once, on
a zero-gap collision through a stiff tensile Kelvin element). Two kinds of
cases:

* one collision of two free masses, against its closed form (Kelvin–Voigt,
  tensile: r = exp(−ξπ/√(1 − ξ²)); non-tensile: it opens where the force
  k δ + c δ̇ returns to 0, at ω_d t = π − atan(2ξ√(1 − ξ²)/(1 − 2ξ²))) or
  against the relative motion integrated here on its own from the law's
  force (scipy's DOP853 with its own event): realised restitution, largest
  penetration, one impact, energy balance;
* two buildings pounding under a short ground motion: the run completes,
  the energy balance closes, the largest penetration stays below what the
  energy put in can store in the element, and a Kelvin–Voigt scene gives the
  same impacts and closures on the exact and the ivp path.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import stochpound
from stochpound.model import laws
from stochpound.model.laws.contract import ElementParameters

STIFFNESSES = (1e5, 1e6, 1e7, 1e8, 1e9, 1e10)
GAPS = (0.0, 1e-9, 1e-6, 1e-3, 0.02)
NONLINEAR = ("hertz_damp", "jankowski")
M1, M2 = 20000.0, 30000.0  # kg
M_EFF = M1 * M2 / (M1 + M2)
RESIDUAL = 1e-6  # largest energy residual over the largest input (or kinetic energy), as on the study scenes


def free_collision(law: str, stiffness: float, gap: float, restitution: float, tensile: bool, speed: float, duration: float) -> dict:
    """Two free one-floor masses on a still ground, the first approaching the second at ``speed`` (m/s) across ``gap`` (m)."""

    def mass(name, m, v):
        return {"name": name, "mass": [m], "stiffness": [0.0], "damping": [0.0], "initial": {"velocity": [v]}}

    contact = {"between": [["A", 1], ["B", 1]], "gap": gap, "stiffness": stiffness, "restitution": restitution, "law": law}
    if law == "kelvin":
        contact["tensile"] = tensile
    return {"building": [mass("A", M1, speed), mass("B", M2, 0.0)], "contact": [contact],
            "motion": {"type": "constant", "acceleration": 0.0, "duration": duration, "dt": duration / 200}}


def kelvin_collision(stiffness: float, restitution: float, tensile: bool, speed: float) -> tuple[float, float, float]:
    """(duration, largest penetration, realised restitution) of a Kelvin–Voigt collision of the two masses, closed form."""
    omega = math.sqrt(stiffness / M_EFF)
    log_r = math.log(restitution)
    xi = -log_r / math.sqrt(math.pi**2 + log_r**2)
    omega_d = omega * math.sqrt(1.0 - xi**2)
    t_peak = math.atan2(math.sqrt(1.0 - xi**2), xi) / omega_d  # δ̇ = 0
    penetration = speed / omega_d * math.exp(-xi * omega * t_peak) * math.sin(omega_d * t_peak)
    if tensile:
        end = math.pi / omega_d
    else:
        end = (math.pi - math.atan(2.0 * xi * math.sqrt(1.0 - xi**2) / (1.0 - 2.0 * xi**2))) / omega_d  # δ̈ = 0: F = 0
    exit_rate = speed * math.exp(-xi * omega * end) * (math.cos(omega_d * end) - xi * omega / omega_d * math.sin(omega_d * end))
    return end, penetration, -exit_rate / speed


def integrated_collision(law: str, stiffness: float, restitution: float, speed: float) -> tuple[float, float, float]:
    """(duration, largest penetration, realised restitution) of m_eff δ̈ = −F(δ, δ̇) integrated on its own from the law's force."""
    element = ElementParameters(stiffness, 0.0, restitution, True, M_EFF)
    contact = laws.contact_law(law)

    def rate(t, y):
        return [y[1], -float(contact.force(element, np.array(y[0]), np.array(y[1]), speed)) / M_EFF]

    def separated(t, y):
        return y[0]

    def turning(t, y):
        return y[1]

    separated.terminal, separated.direction = True, -1
    scale = (5.0 * M_EFF * speed**2 / (4.0 * stiffness)) ** 0.4 / speed  # the elastic Hertz impact's time scale
    solution = solve_ivp(rate, (0.0, 100.0 * scale), [0.0, speed], method="DOP853", rtol=1e-12, atol=1e-14 * speed * scale,
                         events=[separated, turning], first_step=1e-3 * scale)
    return float(solution.t_events[0][-1]), float(solution.y_events[1][0][0]), -float(solution.y_events[0][-1][1]) / speed


def relative_residual(run, reference: str) -> float:
    return float(np.abs(run.energy_residual).max() / np.abs(run[reference]).max())


def collision_cases() -> list:
    """Every stiffness × gap, tensile and not (Kelvin) or each nonlinear law, with a seeded restitution and speed.

    The nonlinear laws run on the ivp path (~0.3 s a case): one gap per stiffness in turn is quick, the rest are marked slow.
    """
    rng = np.random.default_rng(2026)
    cases = []
    for k, stiffness in enumerate(STIFFNESSES):
        for g, gap in enumerate(GAPS):
            for law, tensile in (("kelvin", True), ("kelvin", False), *((law, False) for law in NONLINEAR)):
                case = (law, stiffness, gap, float(rng.uniform(0.3, 0.95)), tensile, float(rng.uniform(0.05, 1.5)))
                quick = law == "kelvin" or g == k % len(GAPS)
                cases.append(pytest.param(*case, marks=() if quick else pytest.mark.slow))
    return cases


@pytest.mark.parametrize(("law", "stiffness", "gap", "restitution", "tensile", "speed"), collision_cases())
def test_one_collision_of_free_masses_matches_its_reference(law, stiffness, gap, restitution, tensile, speed):
    if law == "kelvin":
        duration, penetration, realised = kelvin_collision(stiffness, restitution, tensile, speed)
    else:
        duration, penetration, realised = integrated_collision(law, stiffness, restitution, speed)
    run = stochpound.simulate(stochpound.scene_from_dict(free_collision(law, stiffness, gap, restitution, tensile, speed,
                                                                         gap / speed + 3.0 * duration)), rtol=1e-12, atol=1e-15)
    assert run.attrs["solver"] == ("exact" if law == "kelvin" else "ivp")
    assert run.sizes["impact"] == 1 and bool(run.impact_complete[0])
    assert float(run.impact_start[0]) == pytest.approx(gap / speed, abs=1e-12)
    assert float(run.impact_duration[0]) == pytest.approx(duration, rel=1e-6)
    y, t = run.total_displacement.sel(floor=1).values, run.time.values
    after = (y[:, -1] - y[:, -2]) / (t[-1] - t[-2])
    assert -(after[0] - after[1]) / speed == pytest.approx(realised, abs=1e-7)
    assert float(run.peak_contact_closure[0]) - gap == pytest.approx(penetration, rel=1e-7, abs=1e-15)
    assert relative_residual(run, "energy_kinetic") <= 1e-8


def pounding_cases(count: int = 24) -> list:
    """Seeded two-building scenes: law, stiffness, gap, restitution, tensile and motion drawn per case (nonlinear laws: slow)."""
    rng = np.random.default_rng(17)
    cases = []
    for case in range(count):
        law = ("kelvin", *NONLINEAR)[case % 3]
        tensile = law == "kelvin" and bool(rng.random() < 0.5)
        drawn = (case, law, float(rng.choice(STIFFNESSES)), float(rng.choice(GAPS)), float(rng.uniform(0.3, 0.95)), tensile,
                 int(rng.integers(0, 1000)))
        cases.append(pytest.param(*drawn, marks=() if law == "kelvin" else pytest.mark.slow))
    return cases


def two_buildings(law: str, stiffness: float, gap: float, restitution: float, tensile: bool, seed: int) -> dict:
    """A one-storey and a two-storey building with a contact at floor 1 under 2 s of a Kanai–Tajimi motion (pga 4 m/s²)."""
    contact = {"between": [["B1", 1], ["B2", 1]], "gap": gap, "stiffness": stiffness, "restitution": restitution, "law": law}
    if law == "kelvin":
        contact["tensile"] = tensile
    return {
        "g": 9.81,
        "building": [{"name": "B1", "mass": [3.0e4], "stiffness": [3.0e7], "damping_ratio": 0.05},
                     {"name": "B2", "mass": [2.0e4, 2.0e4], "stiffness": [1.5e7, 1.5e7], "damping_ratio": 0.02}],
        "contact": [contact],
        "motion": {"type": "kanai_tajimi", "omega_g": 12.0, "zeta_g": 0.4, "pga": 4.0, "seed": seed, "duration": 2.0, "dt": 0.005},
    }


def element_energy(law: str, stiffness: float, penetration: float) -> float:
    """Elastic energy an element stores at ``penetration`` (J): ½ k δ² (Kelvin–Voigt), (2/5) k_h δ^{5/2} (Hertz family)."""
    return 0.5 * stiffness * penetration**2 if law == "kelvin" else 0.4 * stiffness * penetration**2.5


@pytest.mark.parametrize(("case", "law", "stiffness", "gap", "restitution", "tensile", "seed"), pounding_cases())
def test_two_buildings_pound_within_the_energy_put_in(case, law, stiffness, gap, restitution, tensile, seed):
    """Starting at rest, what the element stores can never exceed the input so far (kinetic, strain and dissipated energies are ≥ 0);
    the input is read at the output times (5 ms apart), hence the margin of 1.5."""
    scene = stochpound.scene_from_dict(two_buildings(law, stiffness, gap, restitution, tensile, seed))
    run = stochpound.simulate(scene, rtol=1e-10, atol=1e-12)
    assert run.sizes["impact"] > 0, "the scene should pound"
    assert relative_residual(run, "energy_input") <= RESIDUAL
    penetration = float(run.peak_contact_closure[0]) - gap
    assert element_energy(law, stiffness, penetration) <= 1.5 * float(run.energy_input.max())
    if law == "kelvin":
        reference = stochpound.simulate(scene, method="ivp", rtol=1e-12, atol=1e-15)
        assert reference.sizes["impact"] == run.sizes["impact"]
        np.testing.assert_allclose(run.impact_start.values, reference.impact_start.values, rtol=0, atol=1e-7)
        assert float(run.peak_contact_closure[0]) == pytest.approx(float(reference.peak_contact_closure[0]), abs=1e-9)
        scale = max(1.0, float(np.abs(reference.total_displacement).max()))
        np.testing.assert_allclose(run.total_displacement.values, reference.total_displacement.values, rtol=0, atol=1e-8 * scale)
