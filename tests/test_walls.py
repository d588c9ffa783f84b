"""Rigid walls moving with the ground: moat walls at the base, walls at a floor, in both solvers."""

import copy

import numpy as np
import pytest

import stochpound
from stochpound.studies.agarwal2004 import reference_building, study_contacts
from tests.helpers import assert_same_run

MOTION = {"record": "el_centro_1940_study", "duration": 20.0}


def moat(gap: float = 0.02, level: int = 0, mu: float = 0.1) -> dict:
    """The study's Building 1 on a sliding base between two walls (a moat) at ``level``."""
    walls = [{"building": "B1", "side": side, "level": level, "gap": gap, "stiffness": 5.0e8, "restitution": 0.5} for side in ("left", "right")]
    return {"g": 9.814, "building": [reference_building("B1", mu=mu)], "wall": walls, "motion": MOTION}


def run(scene: dict, method: str = "exact"):
    return stochpound.simulate(stochpound.scene_from_dict(scene), method=method)


@pytest.mark.parametrize("level", [0, 2])
def test_walls_match_between_the_exact_and_ivp_flows(level):
    exact, reference = run(moat(level=level)), run(moat(level=level), "ivp")
    assert reference.sizes["impact"] > 2 and set(reference.impact_wall.values) == {0, 1}
    assert np.all(reference.impact_contact.values == -1)
    assert_same_run(exact, reference)
    np.testing.assert_array_equal(exact.impact_wall.values, reference.impact_wall.values)


def test_an_unreachable_wall_changes_nothing():
    """Walls beyond the largest excursion leave the run as it was without them (to 1e-10 m), and record their closure."""
    alone = moat()
    del alone["wall"]
    far = moat(gap=1.0)
    without, with_walls = run(alone), run(far)
    assert with_walls.sizes["impact"] == 0
    np.testing.assert_allclose(with_walls.total_displacement.values, without.total_displacement.values, rtol=0, atol=1e-10)
    s = without.sliding_displacement.sel(building="B1")
    # the closure toward a wall is the base's displacement toward it; its peak is located on the solution (at least the sampled peak)
    np.testing.assert_allclose(with_walls.wall_closure.sel(wall=1).values, s.values, rtol=0, atol=1e-15)
    np.testing.assert_allclose(with_walls.wall_closure.sel(wall=0).values, -s.values, rtol=0, atol=1e-15)
    assert float(with_walls.peak_wall_closure.sel(wall=1)) >= float(s.max()) > 0.0
    assert float(with_walls.peak_wall_closure.sel(wall=0)) >= float(-s.min()) > 0.0


def test_a_wall_is_hit_exactly_when_the_wall_free_run_reaches_its_gap():
    free = moat(gap=np.inf)
    reach = float(run(free).peak_wall_closure.max())
    assert run(moat(gap=0.999 * reach)).sizes["impact"] > 0
    assert run(moat(gap=1.001 * reach)).sizes["impact"] == 0


def test_a_frictionless_block_bounces_off_a_moat_wall_with_its_restitution():
    """A rigid block launched at a wall: exit velocity −r times the entry velocity (the wall is infinitely massive)."""
    r, v0 = 0.6, 0.5
    scene = {"building": [{"name": "block", "mass": [], "stiffness": [], "base": {"mass": 1.0e4, "mu": 0.0}, "initial": {"base_velocity": v0}}],
             "wall": [{"building": "block", "side": "right", "level": 0, "gap": 0.1, "stiffness": 1.0e7, "restitution": r}],
             "motion": {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 0.001}}
    result = run(scene, "ivp")
    assert result.sizes["impact"] == 1 and bool(result.impact_complete[0])
    t, s = result.time.values, result.sliding_displacement.sel(building="block").values
    after = t > float(result.impact_end[0]) + 0.01
    velocity = np.polyfit(t[after], s[after], 1)[0]
    assert velocity == pytest.approx(-r * v0, rel=1e-6)


def test_walls_are_validated_with_the_field_named():
    bad = [({"level": 0}, "wall[0].level: 0 is the base, and building 'B2' has a fixed base"),
           ({"side": "up"}, "wall[0].side: must be 'left' or 'right'"),
           ({"level": 3}, r"wall\[0\].level: must be 0 \(the base\) or a floor number in 1..2"),
           ({"building": "B9"}, "wall[0].building: unknown building 'B9'")]
    for change, message in bad:
        scene = {"building": [reference_building("B1", mu=0.1), reference_building("B2")], "contact": study_contacts(0.02),
                 "wall": [{"building": "B2", "side": "right", "level": 1, "gap": 0.1, "stiffness": 1e8, "restitution": 0.5, **change}],
                 "motion": MOTION}
        with pytest.raises(stochpound.SceneError, match=message.replace("[", r"\[").replace("]", r"\]") if "\\" not in message else message):
            stochpound.scene_from_dict(copy.deepcopy(scene))


def test_demands_leave_the_walls_peak_closures_and_impacts_as_they_are():
    """With demands the run also monitors floor accelerations, drifts and shears; the walls' located peaks are still theirs."""
    scene = stochpound.scene_from_dict(moat())
    plain, with_demands = stochpound.simulate(scene), stochpound.simulate(scene, demands=True)
    assert with_demands.sizes["wall"] == 2 and with_demands.sizes["impact"] == plain.sizes["impact"] > 0
    for name in ("peak_wall_closure", "peak_wall_closure_time", "peak_contact_closure"):
        np.testing.assert_allclose(with_demands[name].values, plain[name].values, rtol=0, atol=1e-12, err_msg=name)


@pytest.mark.parametrize("method, rel", [("exact", 1e-9), ("ivp", 1e-6)])
def test_the_largest_wall_penetration_is_the_closed_form_of_one_kelvin_collision(method, rel):
    """A frictionless block at v0 into a Kelvin wall: δ(t) = v0/ω_d e^(−ζωt) sin(ω_d t) while closed, whose peak is
    (v0/ω) exp(−ζ arccos(ζ)/√(1−ζ²)); the summary takes it from the located peak closure, not from the coarse samples."""
    from stochpound.stats.kernels import wall_penetration

    m, k, gap, v0 = 1.0e4, 1.0e7, 0.115, 0.5
    scene = {"building": [{"name": "block", "mass": [], "stiffness": [], "base": {"mass": m, "mu": 0.0}, "initial": {"base_velocity": v0}}],
             "wall": [{"building": "block", "side": "right", "level": 0, "gap": gap, "stiffness": k, "restitution": 0.5},
                      {"building": "block", "side": "left", "level": 0, "gap": 0.5, "stiffness": k, "restitution": 0.5}],
             "motion": {"type": "constant", "acceleration": 0.0, "duration": 0.6, "dt": 0.05}}
    result = run(scene, method)
    assert result.sizes["impact"] == 1
    omega = np.sqrt(k / m)
    zeta = float(result.wall_damping[0]) / (2.0 * np.sqrt(k * m))
    expected = v0 / omega * np.exp(-zeta * np.arccos(zeta) / np.sqrt(1.0 - zeta**2))
    penetration = float(wall_penetration(result.peak_wall_closure.values, result.wall_gap.values))
    assert penetration == pytest.approx(expected, rel=rel)
    sampled = float(result.sliding_displacement.max()) - gap
    assert sampled < 0.9 * expected  # the samples (dt 0.05 s against a 0.1 s impact) miss the peak the monitor locates


def test_a_case_s_wall_penetration_is_its_walls_located_peak_beyond_the_gap():
    """Hit walls: the peak closure beyond the gap; unreached walls: 0; no walls: NaN (the summary of a case, both ways)."""
    from stochpound.experiment._summary import case_summary, case_values

    hit, far = run(moat(gap=0.02)), run(moat(gap=1.0))
    alone = moat()
    del alone["wall"]
    twin = np.zeros(hit.sizes["time"])
    assert hit.sizes["impact"] > 0
    expected = float((hit.peak_wall_closure - hit.wall_gap).max())
    assert expected > 0.0
    assert case_values(hit, "B1", twin)["peak_wall_penetration"] == pytest.approx(expected, rel=1e-12)
    assert float(case_summary(hit, "B1", hit.total_displacement.sel(building="B1").isel(floor=-1) * 0.0)["peak_wall_penetration"]) == pytest.approx(expected, rel=1e-12)
    assert case_values(far, "B1", twin)["peak_wall_penetration"] == 0.0
    assert np.isnan(case_values(run(alone), "B1", twin)["peak_wall_penetration"])


def test_a_case_s_largest_wall_closure_is_the_clearance_it_needed():
    """The largest located closure toward a wall over the walls, whatever their gap (inf included): a wall at a clearance
    below it is hit, one above it is not (the same motion); NaN without walls."""
    from stochpound.experiment._summary import case_summary, case_values

    free = run(moat(gap=np.inf))
    twin = np.zeros(free.sizes["time"])
    for wall in moat(gap=np.inf)["wall"]:
        assert np.isinf(wall["gap"])
    needed = float(free.peak_wall_closure.max())
    assert free.sizes["impact"] == 0 and needed > 0.0
    assert case_values(free, "B1", twin)["largest_wall_closure"] == pytest.approx(needed, rel=1e-12)
    assert float(case_summary(free, "B1", free.total_displacement.sel(building="B1").isel(floor=-1) * 0.0)["largest_wall_closure"]) == pytest.approx(needed, rel=1e-12)
    assert run(moat(gap=0.98 * needed)).sizes["impact"] > 0 and run(moat(gap=1.02 * needed)).sizes["impact"] == 0
    alone = moat()
    del alone["wall"]
    assert np.isnan(case_values(run(alone), "B1", twin)["largest_wall_closure"])
