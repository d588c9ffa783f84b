"""Energy balance on the study scenes and the numerical traps of docs/model.md."""

import numpy as np
import pytest

import stochpound
from stochpound.studies.agarwal2004 import reference_building, study_contacts, study_scene


def simulate(scene: dict, **options):
    options.setdefault("rtol", 1e-10)
    options.setdefault("atol", 1e-12)
    return stochpound.simulate(stochpound.scene_from_dict(scene), method="ivp", **options)


def relative_residual(run) -> float:
    return float(np.abs(run.energy_residual).max() / np.abs(run.energy_input).max())


STUDY_SCENES = {
    "fixed-fixed, B2 flexible": study_scene(None, None, 2.0),
    "fixed-fixed, B2 stiff": study_scene(None, None, 0.5),
    "B1 isolated mu=0.2, B2 flexible fixed": study_scene(0.2, None, 2.0),
    "both isolated mu=0.1, B2 stiff, gap 1 cm": study_scene(0.1, 0.1, 0.5, gap=0.01),
}


@pytest.mark.parametrize("name", list(STUDY_SCENES))
def test_energy_balance_on_the_study_scenes(name):
    run = simulate(STUDY_SCENES[name])
    assert run.sizes["impact"] > 0
    assert relative_residual(run) <= 1e-6
    for term in ("damping", "friction", "impact"):
        assert float(run[f"energy_{term}"][-1]) >= 0.0  # dissipation only
    assert run.attrs["events_chatter_cycles"] == 0


def test_frictionless_base_runs_and_conserves_energy():
    """B1 on a frictionless base stays still in absolute space while the ground (and fixed B2) move under it."""
    run = simulate(study_scene(0.0, None, 2.0))
    assert run.sizes["impact"] > 0
    assert float(run.energy_friction[-1]) == 0.0
    assert relative_residual(run) <= 1e-6
    assert set(np.unique(run.base_state.values)) <= {-1, 0, 1}


def test_slip_onset_just_above_threshold_is_resolved():
    """A block under a_g = A sin Ωt with A = μg(1 + 1e-6): slip starts where F_req grazes μW."""
    mu, g, omega = 0.2, 9.81, 2 * np.pi
    amplitude = mu * g * (1 + 1e-6)
    scene = {
        "g": g,
        "building": [{"name": "block", "mass": [], "stiffness": [], "base": {"mass": 1000.0, "mu": mu}}],
        "motion": {"type": "harmonic", "amplitude": amplitude, "omega": omega, "duration": 5.0, "dt": 0.01},
    }
    run = simulate(scene, rtol=1e-12, atol=1e-15)
    s = run.sliding_displacement.values[0]
    # it slips a little at each peak (|a_g| > μg for a short while), never much
    assert 0.0 < np.max(np.abs(s)) < 1e-6
    assert run.attrs["events_total"] >= 10
    assert relative_residual(run) <= 1e-6


def test_near_threshold_stick_slip_of_a_building():
    """The reference building on its base, harmonic input with peak base shear just above μW."""
    mu = 0.05
    scene = {
        "g": 9.81,
        "building": [reference_building("B1", mu=mu)],
        "motion": {"type": "harmonic", "amplitude": 0.35, "omega": 8.0, "duration": 10.0, "dt": 0.01},
    }
    run = simulate(scene)
    assert np.any(run.base_state.values != 0) and np.any(run.base_state.values == 0)
    assert relative_residual(run) <= 1e-6


@pytest.mark.parametrize("factor", [100.0, 1e4])
def test_very_stiff_contacts_miss_no_impact_at_loose_tolerance(factor):
    """Contacts far shorter than the integrator's steps: located by the interior-extremum check."""
    scene = study_scene(None, None, 2.0, motion={"record": "el_centro_1940_study", "duration": 10.0})
    for contact in scene["contact"]:
        contact["stiffness"] *= factor
    tight = simulate(scene)
    loose = simulate(scene, rtol=1e-4, atol=1e-7)
    durations = tight.impact_duration.values
    assert durations.max() < 0.02  # shorter than a sample interval
    big = tight.impact_peak_force.values > 0.01 * tight.impact_peak_force.values.max()
    loose_big = loose.impact_peak_force.values > 0.01 * tight.impact_peak_force.values.max()
    assert loose_big.sum() == big.sum()
    assert relative_residual(tight) <= 1e-6


def test_zero_gap_fixed_buildings():
    run = simulate(study_scene(None, None, 0.5, gap=0.0))
    assert run.sizes["impact"] > 10
    assert relative_residual(run) <= 1e-6


def test_zero_gap_isolated_building_settles_against_its_neighbour():
    """A frictionless isolated building pushed against a fixed one: chattering, then at rest in contact."""
    scene = {
        "building": [reference_building("B1", mu=0.0), reference_building("B2", 2.0)],
        "contact": study_contacts(0.0, mass_factor=2.0),
        "motion": {"type": "constant", "acceleration": -0.5, "duration": 60.0, "dt": 0.02},
    }
    run = simulate(scene)
    assert run.sizes["impact"] > 100  # the top floors chatter for tens of seconds
    force = run.impact_force.values[:, -1]
    # at rest in contact, the contacts carry the building's inertial load 0.5 m/s² × its mass
    total_mass = 26268.0 + 17512.0 + 13134.0
    assert force.sum() == pytest.approx(0.5 * total_mass, rel=1e-3)
    assert relative_residual(run) <= 1e-6


@pytest.mark.parametrize("integrator", ["RK45", "Radau", "BDF", "LSODA"])
def test_every_integrator_runs_and_agrees(integrator):
    """Each scipy integrator of the ivp path runs the isolated study scene (El Centro's first 6 s, its strong motion: the base
    sticks and slips) and agrees with DOP853."""
    scene = study_scene(0.2, None, 2.0, motion={"record": "el_centro_1940_study", "duration": 6.0})
    reference = simulate(scene, rtol=1e-11, atol=1e-13)
    run = simulate(scene, integrator=integrator, rtol=1e-8, atol=1e-10)
    assert run.attrs["events_total"] > 10  # stick-slip transitions within the 6 s (24 with DOP853)
    difference = np.abs(run.total_displacement - reference.total_displacement).max()
    assert float(difference) < 1e-4
    assert relative_residual(run) <= 1e-4


@pytest.mark.parametrize("stiffness", [3.3e8, 3.5e8, 3.525e8])
def test_a_zero_gap_collision_whose_guard_starts_within_tolerance_is_located(stiffness):
    """Two free 26.3 t masses through a stiff tensile Kelvin element at zero gap (c fixed, so ζ varies with k).

    At k = 3.5e8 N/m the closing guard started a step within its tolerance above zero, and the event
    search stopped on "f(a) and f(b) must have different signs"; the realised restitution must be
    the closed form of the free collision, e^(−ζπ/√(1−ζ²)), at every stiffness.
    """
    import math

    mass, damping, velocity = 26268.0, 923882.2117691986, 1.0
    effective = mass / 2.0
    zeta = damping / (2.0 * math.sqrt(stiffness * effective))
    omega = math.sqrt(stiffness / effective)
    duration = 3.0 * math.pi / (omega * math.sqrt(1.0 - zeta**2))

    def body(name, speed):
        return {"name": name, "mass": [mass], "stiffness": [0.0], "damping": [0.0], "initial": {"velocity": [speed]}}

    scene = stochpound.scene_from_dict({
        "building": [body("A", velocity), body("B", 0.0)],
        "contact": [{"between": [["A", 1], ["B", 1]], "gap": 0.0, "stiffness": stiffness, "damping": damping, "tensile": True}],
        "motion": {"type": "constant", "acceleration": 0.0, "duration": duration, "dt": duration / 300},
    })
    run = stochpound.simulate(scene, method="exact")
    y, t = run["total_displacement"].sel(floor=1).values, run["time"].values
    v_a, v_b = (y[:, -1] - y[:, -2]) / (t[-1] - t[-2])
    assert (v_b - v_a) / velocity == pytest.approx(math.exp(-zeta * math.pi / math.sqrt(1.0 - zeta**2)), abs=1e-9)
