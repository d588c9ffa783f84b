"""A single collision of two free masses through the Kelvin–Voigt element (docs/model.md §3)."""

import math

import numpy as np
import pytest

import stochpound

M1, M2 = 20000.0, 30000.0  # kg
K_IMPACT = 5.0e7  # N/m
V0 = 0.4  # m/s, mass 1 towards mass 2
GAP = 0.01  # m


def free_masses(tensile: bool = True, restitution: float = 0.5, gap: float = GAP, duration: float = 0.3, dt: float = 0.005) -> dict:
    """Two one-floor buildings with no storey spring or dashpot: free masses on a still ground."""

    def mass(name, m, v):
        return {"name": name, "mass": [m], "stiffness": [0.0], "damping": [0.0], "initial": {"velocity": [v]}}

    return {
        "building": [mass("A", M1, V0), mass("B", M2, 0.0)],
        "contact": [{"between": [["A", 1], ["B", 1]], "gap": gap, "stiffness": K_IMPACT, "restitution": restitution, "tensile": tensile}],
        "motion": {"type": "constant", "acceleration": 0.0, "duration": duration, "dt": dt},
    }


def velocities_after(run) -> tuple[float, float]:
    """Velocities of both masses after the impact, from their (linear) displacement at the last two samples."""
    y = run.total_displacement.sel(floor=1).values
    t = run.time.values
    return tuple((y[:, -1] - y[:, -2]) / (t[-1] - t[-2]))


@pytest.mark.parametrize("restitution", [0.5, 0.8, 1.0])
def test_restitution_law_and_contact_duration(restitution):
    run = stochpound.simulate(stochpound.scene_from_dict(free_masses(restitution=restitution)), method="ivp", rtol=1e-12, atol=1e-15)
    assert run.sizes["impact"] == 1
    assert bool(run.impact_complete[0])
    v_a, v_b = velocities_after(run)
    entry = float(run.impact_onset_velocity[0])
    assert entry == pytest.approx(V0, abs=1e-12)
    assert (v_a - v_b) / entry == pytest.approx(-restitution, abs=1e-8)
    effective_mass = M1 * M2 / (M1 + M2)
    omega = math.sqrt(K_IMPACT / effective_mass)
    zeta = -math.log(restitution) / math.sqrt(math.pi**2 + math.log(restitution) ** 2)
    duration = math.pi / (omega * math.sqrt(1.0 - zeta**2))
    assert float(run.impact_duration[0]) == pytest.approx(duration, abs=1e-10)
    assert float(run.impact_start[0]) == pytest.approx(GAP / V0, abs=1e-12)
    # momentum is exchanged, not created
    assert M1 * v_a + M2 * v_b == pytest.approx(M1 * V0, rel=1e-10)
    # energy: what the dashpot took is what the masses lost
    kinetic_loss = 0.5 * M1 * V0**2 - 0.5 * M1 * v_a**2 - 0.5 * M2 * v_b**2
    assert float(run.energy_impact[-1]) == pytest.approx(kinetic_loss, rel=1e-9, abs=1e-9)
    assert not bool(run.impact_in_phase[0])  # B is at rest at onset: not moving the same way


def test_peak_force_is_located_between_samples():
    run = stochpound.simulate(stochpound.scene_from_dict(free_masses(dt=0.02)), method="ivp", rtol=1e-12, atol=1e-15)
    effective_mass = M1 * M2 / (M1 + M2)
    omega = math.sqrt(K_IMPACT / effective_mass)
    damping = float(run.contact_damping[0])
    zeta = damping / (2 * math.sqrt(K_IMPACT * effective_mass))
    omega_d = omega * math.sqrt(1 - zeta**2)
    # F(τ) = k δ + c δ̇ with δ = V0/ω_d e^{−ζωτ} sin ω_d τ: maximise on a fine grid as the reference
    tau = np.linspace(0.0, math.pi / omega_d, 200001)
    envelope = V0 / omega_d * np.exp(-zeta * omega * tau)
    delta = envelope * np.sin(omega_d * tau)
    delta_rate = envelope * (omega_d * np.cos(omega_d * tau) - zeta * omega * np.sin(omega_d * tau))
    reference_peak = np.max(K_IMPACT * delta + damping * delta_rate)
    assert float(run.impact_peak_force[0]) == pytest.approx(reference_peak, rel=1e-9)
    assert float(run.impact_peak_force[0]) > float(run.impact_force.max()) - 1e-6


def test_non_tensile_element_never_pulls():
    tensile = stochpound.simulate(stochpound.scene_from_dict(free_masses(tensile=True, dt=0.0005)), method="ivp", rtol=1e-12, atol=1e-15)
    non_tensile = stochpound.simulate(stochpound.scene_from_dict(free_masses(tensile=False, dt=0.0005)), method="ivp", rtol=1e-12, atol=1e-15)
    assert float(tensile.impact_force.min()) < -1.0  # the tensile element pulls before separation
    assert float(non_tensile.impact_force.min()) >= 0.0
    assert non_tensile.sizes["impact"] == 1
    # it separates earlier (when the force returns to zero), so the impact is shorter
    assert float(non_tensile.impact_duration[0]) < float(tensile.impact_duration[0])
    v_a, v_b = velocities_after(non_tensile)
    assert M1 * v_a + M2 * v_b == pytest.approx(M1 * V0, rel=1e-10)
    residual = float(abs(non_tensile.energy_residual).max())
    assert residual <= 1e-8 * float(non_tensile.energy_input.max() + 0.5 * M1 * V0**2)


def test_event_on_a_sample_time():
    """The collision starts exactly at a sample (gap / V0 = 0.025 s = 5 samples)."""
    run = stochpound.simulate(stochpound.scene_from_dict(free_masses(gap=V0 * 0.025, dt=0.005)), method="ivp", rtol=1e-12, atol=1e-15)
    assert run.sizes["impact"] == 1
    assert float(run.impact_start[0]) == pytest.approx(0.025, abs=1e-12)
    v_a, v_b = velocities_after(run)
    assert (v_a - v_b) / V0 == pytest.approx(-0.5, abs=1e-8)
