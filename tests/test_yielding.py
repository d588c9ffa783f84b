"""Bilinear yielding storeys (docs/model.md, "Yielding storeys"): closed forms, energy, elastic limit, exact against ivp."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import stochpound
from stochpound._errors import SceneError
from stochpound.model import design_yield_shears
from stochpound.model.building import Building, InitialState
from stochpound.model.scene import Scene
from stochpound.model.system import build_system
from stochpound.motions.ground import SampledMotion
from stochpound.studies.agarwal2004 import reference_building, study_scene
from tests.helpers import with_gaps

# an elastic–perfectly-plastic SDOF (ω = 10 rad/s, d_y = 1 cm) thrown upwards under a constant ground acceleration
MASS, STIFFNESS, YIELD, LOAD, VELOCITY = 1.0, 100.0, 1.0, 0.5, 0.2  # kg, N/m, N, N (= −m a_g), m/s
DT, DURATION = 0.01, 0.7  # s: the unloading arc lasts less than its half period (no reloading)


def epp_closed_form(t: float) -> tuple[float, float]:
    """Displacement and plastic drift (m) of the SDOF at time t: elastic arc, plastic parabola, elastic unloading about the offset."""
    omega, d_y, static = math.sqrt(STIFFNESS / MASS), YIELD / STIFFNESS, LOAD / STIFFNESS

    def arc(s):
        return static * (1.0 - math.cos(omega * s)) + VELOCITY / omega * math.sin(omega * s)

    t1 = brentq(lambda s: arc(s) - d_y, 0.0, 0.5 * math.pi / omega)
    v1 = static * omega * math.sin(omega * t1) + VELOCITY * math.cos(omega * t1)
    deceleration = (YIELD - LOAD) / MASS
    t2 = t1 + v1 / deceleration
    offset = d_y + 0.5 * v1 * v1 / deceleration - d_y  # plastic drift once the parabola stops
    if t <= t1:
        return arc(t), 0.0
    if t <= t2:
        tau = t - t1
        return d_y + v1 * tau - 0.5 * deceleration * tau * tau, v1 * tau - 0.5 * deceleration * tau * tau
    return offset + static + (d_y - static) * math.cos(omega * (t - t2)), offset


def epp_scene() -> Scene:
    times = np.arange(0.0, DURATION + 0.5 * DT, DT)
    building = Building("B", (MASS,), (STIFFNESS,), (0.0,), initial=InitialState((0.0,), (VELOCITY,)), yield_force=(YIELD,))
    return Scene((building,), (), SampledMotion(DT, np.full(len(times), -LOAD / MASS)))


@pytest.mark.parametrize("method", ["exact", "ivp"])
def test_elastic_perfectly_plastic_sdof_under_a_step_matches_its_closed_form(method):
    run = stochpound.simulate(epp_scene(), method, rtol=1e-12, atol=1e-14)
    expected = np.array([epp_closed_form(t) for t in run.time.values])
    assert expected[-1, 1] > 0.03  # it yielded far (the closed form's offset), then unloaded
    np.testing.assert_allclose(run.relative_displacement.values[0, 0], expected[:, 0], rtol=0, atol=1e-10)
    np.testing.assert_allclose(run.storey_plastic_drift.values[0, 0], expected[:, 1], rtol=0, atol=1e-10)
    peak = expected[-1, 1] + YIELD / STIFFNESS  # where the parabola stops
    assert float(run.peak_storey_ductility[0, 0]) == pytest.approx(peak / (YIELD / STIFFNESS), rel=1e-9)
    assert float(run.residual_storey_drift[0, 0]) == pytest.approx(expected[-1, 1], abs=1e-10)
    assert float(run.energy_hysteretic[-1]) == pytest.approx(YIELD * expected[-1, 1], abs=1e-10)  # F_y Σ|Δz|, α = 0
    assert run.attrs["events_total"] == 2  # yield, unloading


def yielding_pair(mu1: float | None, hardening: float = 0.05) -> dict:
    """The study's pair at a 1 cm gap (El Centro), both buildings yielding at about a fifth of their elastic demand."""
    scene = study_scene(mu1, None, 2.0, gap=0.01)
    scene["building"][0].update(yield_force=[1.0e5, 0.7e5], hardening=hardening)
    scene["building"][1].update(yield_force=[2.0e5, 1.4e5], hardening=hardening)
    return scene


def test_with_hardening_the_energy_balance_closes():
    run = stochpound.simulate(stochpound.scene_from_dict(yielding_pair(None)), "exact")
    hysteretic = run.energy_hysteretic.values
    assert hysteretic[-1] > 0.2 * float(run.energy_input.max())  # yielding dissipates a good share of the input
    assert np.all(np.diff(hysteretic) >= 0.0)
    assert float(np.abs(run.energy_residual).max()) <= 1e-9 * float(np.abs(run.energy_input).max())


def test_a_yield_force_above_every_demand_gives_the_elastic_result():
    elastic = study_scene(None, None, 2.0, gap=0.01)
    strong = yielding_pair(None)
    for building in strong["building"]:
        building["yield_force"] = [1e9, 1e9]
    runs = [stochpound.simulate(stochpound.scene_from_dict(scene), "exact") for scene in (elastic, strong)]
    assert runs[0].sizes["impact"] == runs[1].sizes["impact"] > 0
    np.testing.assert_allclose(runs[1].total_displacement.values, runs[0].total_displacement.values, rtol=0, atol=1e-12)
    assert float(np.abs(runs[1].storey_plastic_drift).max()) == 0.0
    assert float(runs[1].peak_storey_ductility.max()) < 1e-3


@pytest.mark.parametrize("mu1", [None, 0.1], ids=["pounding", "pounding-and-sliding"])
def test_exact_matches_ivp_on_yielding_scenes(mu1):
    scene = stochpound.scene_from_dict(yielding_pair(mu1))
    exact = stochpound.simulate(scene, "exact")
    reference = stochpound.simulate(scene, "ivp", rtol=1e-12, atol=1e-14)
    assert exact.sizes["impact"] == reference.sizes["impact"] > 0
    assert exact.attrs["events_total"] == reference.attrs["events_total"]
    assert float(exact.peak_storey_ductility.max()) > 2.0  # the scene yields
    if mu1 is not None:
        assert float(np.abs(exact.sliding_displacement).max()) > 1e-3  # and slides
    np.testing.assert_allclose(exact.total_displacement.values, reference.total_displacement.values, rtol=0, atol=1e-8)
    np.testing.assert_allclose(exact.storey_plastic_drift.values, reference.storey_plastic_drift.values, rtol=0, atol=1e-8)
    np.testing.assert_allclose(exact.peak_storey_ductility.values, reference.peak_storey_ductility.values, rtol=1e-7)


def test_storey_shear_of_a_yielding_storey_is_its_bilinear_force():
    building = reference_building("B1", 1.0, None, yield_force=[1.0e5, 0.7e5], hardening=0.1, storey_height=[3.5, 3.0])
    building["damping"] = [0.0, 0.0]
    run = stochpound.simulate(stochpound.scene_from_dict({"building": [building], "motion": {"record": "el_centro_1940_study"}}), "exact",
                              demands=True)
    k = np.array(building["stiffness"])[:, None]
    drift, plastic = run.storey_drift.values[0], run.storey_plastic_drift.values[0]
    np.testing.assert_allclose(run.storey_shear.values[0], k * drift - 0.9 * k * plastic, rtol=0, atol=1e-6 * float(np.abs(run.storey_shear).max()))
    assert float(np.abs(run.storey_shear).max()) <= 1.0e5 * (1 + 1e-9) + 0.1 * 24516800.0 * float(np.abs(drift).max())
    np.testing.assert_allclose(run.residual_storey_drift_ratio.values[0], run.residual_storey_drift.values[0] / [3.5, 3.0], rtol=1e-15)


def test_an_elastic_scene_has_no_plastic_states():
    system = build_system(stochpound.scene_from_dict(study_scene(0.1, None, 2.0)))
    assert system.storeys == () and system.n_dof == 5
    run = stochpound.simulate(stochpound.scene_from_dict(study_scene(None, None, 2.0)), "exact")
    assert "energy_hysteretic" not in run and "storey_plastic_drift" not in run


@pytest.mark.parametrize(
    "extra, message",
    [
        ({"hardening": 0.1}, "building[0].hardening: only a building with yield_force"),
        ({"yield_force": [1e5]}, "building[0].yield_force"),
        ({"yield_force": [1e5, -1.0]}, "building[0].yield_force"),
        ({"yield_force": [1e5, 1e5], "hardening": 1.0}, "building[0].hardening"),
        ({"yield_force": [1e5, 1e5], "initial": {"displacement": [0.001, 0.02]}}, "building[0].initial.displacement: storey 2's drift"),
    ],
)
def test_bad_yielding_keys_are_named(extra, message):
    scene = {"building": [reference_building("B1", 1.0, None, **extra)], "motion": {"record": "el_centro_1940_study"}}
    with pytest.raises(SceneError, match=message.replace("[", r"\[").replace("]", r"\]")):
        stochpound.scene_from_dict(scene)


@pytest.mark.parametrize("period", [0.4, 1.5])
def test_design_yield_shears_follow_asce7_16_section_12_8_by_hand(period):
    """Two storeys, S_DS = 1.0 g, S_D1 = 0.6 g, S_1 = 0.6 g, R = 8, I_e = 1.25, Ω0 = 3, T_L = 8 s."""
    mass, heights, g = [2.0e5, 1.5e5], [3.5, 3.0], 9.81
    shears = design_yield_shears(mass, heights, period=period, sds=1.0, sd1=0.6, s1=0.6, r=8.0, importance=1.25, overstrength=3.0, g=g)
    weight = g * 3.5e5
    cs = min(1.0 / (8.0 / 1.25), 0.6 / (period * 8.0 / 1.25))  # Eq. 12.8-2 capped by Eq. 12.8-3 (T < T_L)
    cs = max(cs, 0.044 * 1.0 * 1.25, 0.01, 0.5 * 0.6 / (8.0 / 1.25))  # Eqs. 12.8-5 and 12.8-6
    assert cs == pytest.approx(0.15625 if period == 0.4 else 0.6 / (1.5 * 6.4))
    k = 1.0 if period <= 0.5 else 1.0 + (period - 0.5) / 2.0  # §12.8.3
    w1h1, w2h2 = 2.0e5 * 3.5**k, 1.5e5 * 6.5**k
    top = cs * weight * w2h2 / (w1h1 + w2h2)  # Eqs. 12.8-11, 12.8-12
    np.testing.assert_allclose(shears, [3.0 * cs * weight, 3.0 * top], rtol=1e-13)


@pytest.mark.parametrize(("field", "options"), [("r", {"r": 0.0}), ("overstrength", {"overstrength": 0.5}), ("period", {"period": -1.0})])
def test_design_yield_shears_name_a_bad_argument(field, options):
    arguments = {"period": 0.5, "sds": 1.0, "sd1": 0.6, "r": 8.0, "overstrength": 3.0} | options
    with pytest.raises(ValueError, match=f"^{field}: must be"):
        design_yield_shears([1e5], [3.0], **arguments)


def test_p_delta_softens_a_storey_by_its_weight_over_its_height():
    """An SDOF released from u0 with P-Δ vibrates at ω² = (k − m g / h) / m."""
    mass, stiffness, height, g, u0 = 1000.0, 2.0e5, 0.1, 9.81, 0.01
    times = np.arange(0.0, 2.0 + 0.5 * DT, DT)
    building = Building("B", (mass,), (stiffness,), (0.0,), initial=InitialState((u0,), (0.0,)), storey_height=(height,), p_delta=True)
    run = stochpound.simulate(Scene((building,), (), SampledMotion(DT, np.zeros(len(times))), g=g), "exact")
    omega = math.sqrt((stiffness - mass * g / height) / mass)
    np.testing.assert_allclose(run.relative_displacement.values[0, 0], u0 * np.cos(omega * times), rtol=0, atol=1e-12)
    assert float(np.abs(run.energy_residual).max()) <= 1e-12 * 0.5 * stiffness * u0**2


def test_exact_matches_ivp_on_a_yielding_scene_with_p_delta():
    scene = yielding_pair(None)
    for building in scene["building"]:
        building.update(storey_height=[3.5, 3.0], p_delta=True)
    parsed = stochpound.scene_from_dict(scene)
    exact, reference = stochpound.simulate(parsed, "exact"), stochpound.simulate(parsed, "ivp", rtol=1e-12, atol=1e-14)
    assert exact.sizes["impact"] == reference.sizes["impact"] > 0
    np.testing.assert_allclose(exact.total_displacement.values, reference.total_displacement.values, rtol=0, atol=1e-8)
    elastic = stochpound.simulate(stochpound.scene_from_dict(yielding_pair(None)), "exact")
    assert not np.allclose(exact.total_displacement.values, elastic.total_displacement.values, atol=1e-6)  # P-Δ changes the run
    assert float(np.abs(exact.energy_residual).max()) <= 1e-9 * float(np.abs(exact.energy_input).max())


def test_p_delta_needs_storey_heights():
    scene = {"building": [reference_building("B1", 1.0, None, p_delta=True)], "motion": {"record": "el_centro_1940_study"}}
    with pytest.raises(SceneError, match=r"^building\[0\].p_delta: needs storey_height"):
        stochpound.scene_from_dict(scene)


def test_the_fixed_base_twin_of_a_yielding_building_yields():
    """An experiment's fixed-base reference of a yielding building is its run through the event engine, not a linear recursion."""
    from stochpound.solvers.twin import fixed_base_displacements

    building = reference_building("B1", 1.0, None, yield_force=[1.0e5, 0.7e5], hardening=0.05)
    scene = stochpound.scene_from_dict({"building": [building], "motion": {"record": "el_centro_1940_study"}})
    motions = [scene.motion, SampledMotion(scene.motion.dt, 0.5 * np.asarray(scene.motion.values))]
    twins = fixed_base_displacements(scene, motions)
    for twin, motion in zip(twins, motions):
        run = stochpound.simulate(Scene(scene.buildings, (), motion), "exact")
        np.testing.assert_array_equal(twin, run.relative_displacement.values[0])
    assert float(run.peak_storey_ductility.max()) > 1.0  # the halved record still yields


KANAI_TAJIMI = {"type": "kanai_tajimi", "omega_g": 15.0, "zeta_g": 0.6, "pga": 3.4, "envelope": "jennings", "seed": 3, "duration": 10.0, "dt": 0.01}
SHARP = 1e-8  # m: gaps this far from the contact-free peak closure D


@pytest.mark.parametrize("mu1", [None, 0.2], ids=["fixed", "sliding"])
def test_the_gap_identity_holds_with_yielding_storeys(mu1):
    """A yielding pair pounds at gap g exactly when its contact-free twin's located peak closure D reaches g, hit for hit.

    Yielding makes the runs path-dependent but not the identity: the gap-g run
    is the contact-free run until its first contact, so its first impact is at
    the contact-free peak's time when only that peak reaches the gap. Gaps 10 nm
    either side of D, and each contact its own gap, check it realization by
    realization; the runs yield (ductility > 1), and the grid separates them.
    """
    pounded, reached = [], []
    for realization in range(3):
        scene = yielding_pair(mu1)
        scene["contact"] = [dict(contact, gap=math.inf) for contact in scene["contact"]]
        scene["motion"] = dict(KANAI_TAJIMI, realization=realization)
        free_scene = stochpound.scene_from_dict(scene)
        free = stochpound.simulate(free_scene)
        assert free.sizes["impact"] == 0 and float(free.peak_storey_ductility.max()) > 1.5
        closure = free["peak_contact_closure"].values
        assert np.all(closure >= free["contact_closure"].max("time").values)
        top = int(np.argmax(closure))
        cases = [((closure.max() - SHARP,) * 2, top), ((closure.max() + SHARP,) * 2, None),
                 ((closure[0] - SHARP, closure[1] + SHARP), 0), ((closure[0] + SHARP, closure[1] - SHARP), 1)]
        cases += [((g, g), "grid") for g in (0.01, 0.03, 0.06)]
        for gaps, touched in cases:
            run = stochpound.simulate(with_gaps(free_scene, gaps))
            hit = run.sizes["impact"] > 0
            assert hit == bool(np.any(closure >= np.array(gaps))), (realization, gaps, closure)
            if isinstance(touched, int):  # the first impact is at that contact's contact-free peak
                assert int(run["impact_contact"][0]) == touched
                assert float(run["impact_start"][0]) == pytest.approx(float(free["peak_contact_closure_time"][touched]), abs=1e-3)
            if touched == "grid":
                pounded.append(hit)
                reached.append(bool(closure.max() >= gaps[0]))
    assert pounded == reached and 0 < sum(pounded) < len(pounded)
