"""The law registry (stochpound.model.laws): every law answers the same questions, and no code outside it compares law names."""

import importlib
import re
from pathlib import Path

import numpy as np
import pytest

import stochpound
from stochpound.model import laws
from stochpound.model.fields import TomlTable
from stochpound.model.friction import Base, SlidingBase
from stochpound.model.law import ElementParameters
from stochpound.studies.agarwal2004 import reference_building

ELEMENT = ElementParameters(stiffness=2.75e9, damping=0.0, restitution=0.5, tensile=True, mass=1.0e5)


@pytest.mark.parametrize("name, expected", [
    ("hertz", "Hertz, k_h = 2.75e+09 N/m^1.5, elastic"),
    ("hertz_damp", "Hertz-damp (Muthukumar & DesRoches 2006), k_h = 2.75e+09 N/m^1.5, c_h from e = 0.5 per impact"),
    ("hertz_damp_ye", "Hertz-damp (Ye, Li & Zhu 2009), k_h = 2.75e+09 N/m^1.5, c_h from e = 0.5 per impact"),
    ("jankowski", "Jankowski (2005, 2006), β = 2.75e+09 N/m^1.5, ξ = 0.6818 from e = 0.5 while approaching"),
])
def test_nonlinear_contact_laws_describe_themselves_with_their_units(name, expected):
    law = laws.contact_law(name)
    assert law.describe(ELEMENT) == expected
    assert not law.piecewise_linear and "Kelvin" not in law.describe(ELEMENT) and "never pulls" in law.separation(ELEMENT)


def test_kelvin_describes_its_dashpot_given_or_from_a_restitution():
    kelvin = laws.contact_law("kelvin")
    from_e = ElementParameters(1.0e8, 2.0e5, 0.5, False, 1.0e4)
    given = from_e._replace(restitution=None)
    assert kelvin.describe(from_e) == "Kelvin–Voigt, k = 1e+08 N/m (√(k/m_eff) = 100 rad/s), c = 2e+05 N·s/m from e = 0.5"
    assert kelvin.describe(given).endswith("c = 2e+05 N·s/m given")
    assert kelvin.piecewise_linear and kelvin.separation(from_e).startswith("non-tensile")


@pytest.mark.parametrize("name", list(laws.CONTACT_LAWS))
def test_every_contact_law_has_consistent_force_partials_and_power(name):
    """∂F/∂δ and ∂F/∂δ̇ against central differences of F; power = F δ̇; rescaling multiplies k_h (and a given c) by the mass ratio."""
    law = laws.contact_law(name)
    element = ELEMENT._replace(damping=1.0e5, restitution=0.5)
    delta, rate, onset, h = np.array([1e-4, 3e-3]), np.array([0.3, -0.2]), 0.4, 1e-9
    along, across = law.partials(element, delta, rate, onset)
    np.testing.assert_allclose(along, (law.force(element, delta + h, rate, onset) - law.force(element, delta - h, rate, onset)) / (2 * h), rtol=1e-5)
    np.testing.assert_allclose(across, (law.force(element, delta, rate + 1e-6, onset) - law.force(element, delta, rate - 1e-6, onset)) / 2e-6, rtol=1e-5)
    np.testing.assert_array_equal(law.power(element, delta, rate, onset), law.force(element, delta, rate, onset) * rate)
    assert law.energy_term == "impact"
    table = {"law": name, "stiffness": 2.0, **({"damping": 3.0} if "damping" in law.keys else {})}
    assert law.rescaled(TomlTable(table), 1.5) == {"stiffness": 3.0, **({"damping": 4.5} if "damping" in law.keys else {})}


def test_the_friction_laws_and_the_friction_pendulum_describe_themselves():
    pendulum = Base(mass=1.0e5, mu=0.05, mu_static=0.05, radius=2.236412)
    assert laws.friction_law(pendulum.friction_law).describe(pendulum) == "Coulomb friction, μ = 0.05, μ_s = 0.05"
    assert pendulum.describe_restoring(9.81) == "friction pendulum, R = 2.236 m (k_r = W/R, T_b = 2π √(R/g) = 3 s)"
    assert Base(1.0e5, 0.05, 0.05).describe_restoring(9.81) == "flat slider (no restoring force)"
    assert Base(1.0e5, 0.05, 0.05, restoring_stiffness=2e6).describe_restoring(9.81) == "restoring stiffness k_r = 2e+06 N/m"
    velocity = Base(1.0e5, 0.06, 0.06, mu_fast=0.12, mu_rate=20.0)
    law = laws.friction_law(velocity.friction_law)
    assert not law.piecewise_linear and laws.friction_law("coulomb").piecewise_linear
    assert "μ_slow = 0.06, μ_fast = 0.12, a = 20 s/m" in law.describe(velocity)
    sliding = SlidingBase(building=0, dof=3, weight=1.0e6, mu=0.06, mu_static=0.06, mu_fast=0.12, mu_rate=20.0)
    speed = np.array([0.0, 0.05, 1.0])
    for state in (1, -1):  # the force opposes the sliding, its work is negative, its slope matches a central difference
        force = law.force(sliding, state, speed)
        np.testing.assert_allclose(-state * force / sliding.weight, [0.06, 0.12 - 0.06 * np.exp(-1.0), 0.12 - 0.06 * np.exp(-20.0)], rtol=1e-14)
        assert np.all(law.power(sliding, state, speed)[1:] < 0.0)
        h = 1e-7
        np.testing.assert_allclose(law.partial(sliding, speed[1:]), state * (law.force(sliding, state, speed[1:] + h) - law.force(sliding, state, speed[1:] - h)) / (2 * h), rtol=1e-6, atol=1e-2)
    coulomb = laws.friction_law("coulomb")
    np.testing.assert_array_equal(coulomb.force(sliding, -1, speed), 0.06 * 1.0e6)
    assert not coulomb.partial(sliding, speed).any() and coulomb.energy_term == law.energy_term == "friction"


def test_a_scenes_nonlinear_laws_come_from_the_registry():
    scene = {"g": 9.81, "building": [reference_building("B1", mu=0.1), reference_building("B2")],
             "contact": [{"between": [["B1", 1], ["B2", 1]], "gap": 0.01, "law": "hertz", "stiffness": 1e9}],
             "wall": [{"building": "B1", "side": "left", "level": 0, "gap": 0.1, "stiffness": 1e9, "restitution": 0.5}],
             "motion": {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 0.1}}
    assert stochpound.scene_from_dict(scene).nonlinear_laws() == ["contact[0].law = 'hertz'"]
    scene["wall"][0]["law"] = "hertz_damp_ye"
    assert stochpound.scene_from_dict(scene).nonlinear_laws()[1] == "wall[0].law = 'hertz_damp_ye'"


def test_no_code_outside_the_registry_compares_law_names():
    package = Path(stochpound.__file__).parent
    comparison = re.compile(r"""(?<!for )(\blaw\w*|\.law)\s*(==|!=|\bin\b|\bnot in\b)\s*[("']|["'](kelvin|hertz\w*|jankowski|coulomb)["']\s*(==|!=|\bin\b)""")
    found = [f"{path.relative_to(package)}:{number}" for path in package.rglob("*.py")
             for number, line in enumerate(path.read_text().splitlines(), 1) if comparison.search(line)]
    assert found == []


@pytest.mark.parametrize("old, new", [("law", "contract"), *((name, name) for name in ("kelvin", "hertz", "hertz_damp_ye", "hertz_damp_exact",
                                                                                      "jankowski", "coulomb", "velocity_friction"))])
def test_the_law_modules_old_paths_are_the_moved_modules(old, new):
    """The law modules moved into stochpound.model.laws; code that imports them by their old paths gets the same modules."""
    assert importlib.import_module(f"stochpound.model.{old}") is importlib.import_module(f"stochpound.model.laws.{new}")


@pytest.mark.parametrize("mu, law", [(0.1, "coulomb"), ({"slow": 0.05, "fast": 0.1, "rate": 20.0}, "velocity")])
def test_a_bases_friction_law_is_the_one_its_mu_is_written_for(mu, law):
    assert laws.base_friction_law(TomlTable({"mass": 1.0, "mu": mu})) is laws.friction_law(law)
    assert {name for name, other in laws.FRICTION_LAWS.items() if other.spells(mu)} == {law}
