"""A scenario is one frozen value: checked naming the field, equal by its numbers, and the public functions give the same
result bit for bit from it as from their loose keywords."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import xarray as xr

from stochpound import SiteError
from stochpound.analysis import RuptureSite, bundled_rupture_sites, scenario_hazard
from stochpound.motions import Scenario, conditional_spectrum, scenario_distribution, site_motions, site_motions_from_normals

LOOSE = {"magnitude": 6.5, "distance_km": 20.0, "vs30": 400.0, "mechanism": "reverse"}
GEOMETRY = {"ztor_km": 2.0, "dip": 45.0, "distance_jb_km": 15.0}


def test_a_scenario_is_equal_and_hashed_by_its_numbers_and_frozen():
    assert Scenario(7, 10, 760, "strike_slip") == Scenario(7.0, 10.0, 760.0, "strike_slip")
    assert hash(Scenario(7, 10, 760, "strike_slip")) == hash(Scenario(np.float64(7.0), 10.0, 760.0, "strike_slip"))
    assert isinstance(Scenario(7, 10, 760, "strike_slip").magnitude, float)
    assert Scenario(**LOOSE, ztor_km=2.0) != Scenario(**LOOSE)
    assert len({Scenario(**LOOSE), Scenario(**LOOSE, dip=None), Scenario(6.5, 20, 400, "reverse")}) == 1
    with pytest.raises(dataclasses.FrozenInstanceError):
        Scenario(**LOOSE).magnitude = 7.0  # type: ignore[misc]
    quake = Scenario.of(**LOOSE, geometry=GEOMETRY)
    assert quake.geometry == {"distance_jb_km": 15.0, "ztor_km": 2.0, "dip": 45.0} and quake.loose() == LOOSE


@pytest.mark.parametrize("make, message", [
    (lambda: Scenario(7.0, 10.0, -1.0, "strike_slip"), "^vs30: must be a finite number > 0, got -1.0$"),
    (lambda: Scenario(float("nan"), 10.0, 760.0, "strike_slip"), "^magnitude: must be a finite number, got nan$"),
    (lambda: Scenario(7.0, 10.0, 760.0, "oblique"), "^mechanism: must be one of strike_slip, reverse, normal, got 'oblique'$"),
    (lambda: Scenario(7.0, 10.0, 760.0, "reverse", dip="steep"), "^dip: must be a finite number, got 'steep'$"),
    (lambda: Scenario(9.0, 10.0, 760.0, "reverse").check(), r"^magnitude: must be within 3.5-8.5 \(the NGA-West2 models' range\), got 9.0$"),
    (lambda: Scenario(7.0, 10.0, 760.0, "reverse", distance_jb_km=12.0).check(),
     r"^distance_jb_km: must be within 0-10 \(at most the rupture distance, the NGA-West2 models' range\), got 12.0$"),
    (lambda: Scenario.of(7.0, 10.0, 2000.0, "reverse", names={"vs30": "site.vs30"}),
     r"^site.vs30: must be within 180-1000 \(the NGA-West2 models' range\), got 2000.0$"),
    (lambda: Scenario.of(7.0, 10.0, 760.0, "reverse", {"depth_km": 3.0}), "^geometry: unknown field"),
])
def test_a_bad_scenario_is_refused_naming_its_field(make, message):
    with pytest.raises(SiteError, match=message):
        make()


def test_the_conditional_spectrum_and_the_distribution_are_the_same_from_a_scenario():
    quake = Scenario.of(**LOOSE, geometry=GEOMETRY)
    arguments = {"level": 0.4, "periods": [0.1, 0.5, 1.0, 2.0]}
    loose = conditional_spectrum("psa", 1.0, **arguments, **LOOSE, geometry=GEOMETRY)
    valued = conditional_spectrum("psa", 1.0, **arguments, scenario=quake)
    xr.testing.assert_identical(loose, valued)
    assert loose.attrs == valued.attrs and loose.attrs["ztor_km"] == 2.0
    averaged = [0.5, 1.0, 2.0]
    assert scenario_distribution("sa_avg", averaged, **LOOSE, geometry=GEOMETRY) == scenario_distribution("sa_avg", averaged, scenario=quake)


def test_the_scenario_hazard_is_the_same_from_a_scenario_and_is_a_site_of_one_rupture():
    loose = scenario_hazard("pga", **LOOSE, rate=0.01)
    valued = scenario_hazard("pga", scenario=Scenario(**LOOSE), rate=0.01)
    assert loose.im.tobytes() == valued.im.tobytes() and loose.rate.tobytes() == valued.rate.tobytes() and loose.source == valued.source
    quake = Scenario.of(**LOOSE, geometry=GEOMETRY)
    site = RuptureSite.from_scenarios([(quake, 0.01)])
    assert site.hazard_curve("pga").rate.tobytes() == scenario_hazard("pga", scenario=quake, rate=0.01).rate.tobytes()
    estimated = RuptureSite.from_scenarios([(Scenario(**LOOSE), 0.01)])
    assert (estimated.distance_jb_km, estimated.distance_x_km, estimated.ztor_km, estimated.dip) == ((20.0,), (-20.0,), (0.0,), (40.0,))


def test_site_motions_are_the_same_from_a_scenario_and_checked_against_the_calibration():
    loose = site_motions(**LOOSE, n=2, seed=3, duration=5.0)
    valued = site_motions(n=2, seed=3, duration=5.0, scenario=Scenario(**LOOSE))
    xr.testing.assert_identical(loose, valued)
    normals = np.random.default_rng(2).standard_normal((2, 7 + 300))
    xr.testing.assert_identical(site_motions_from_normals(normals, **LOOSE), site_motions_from_normals(normals, scenario=Scenario(**LOOSE)))
    with pytest.raises(SiteError, match=r"^distance_km: must be within 5-100 \(the site-motion model's calibrated range\), got 150.0$"):
        site_motions(n=1, seed=1, scenario=Scenario(7.0, 150.0, 760.0, "reverse"))
    with pytest.raises(SiteError, match="^scenario: the published model takes magnitude, distance_km, vs30 and mechanism only"):
        site_motions(n=1, seed=1, scenario=Scenario(**LOOSE, ztor_km=1.0), model="rezaeian_2010")
    assert site_motions(n=1, seed=1, duration=5.0, scenario=Scenario(**LOOSE, ztor_km=1.0)).attrs["ztor_km"] == 1.0  # the calibrated model takes it


def test_a_scenario_is_given_once_at_the_door():
    with pytest.raises(SiteError, match="^scenario: give either scenario= or magnitude"):
        conditional_spectrum("pga", level=0.3, periods=[1.0], **LOOSE, scenario=Scenario(**LOOSE))
    with pytest.raises(SiteError, match=r"^vs30: missing \(give magnitude, distance_km, vs30 and mechanism, or scenario=\)$"):
        scenario_distribution("pga", magnitude=7.0, distance_km=10.0, mechanism="reverse")
    with pytest.raises(SiteError, match="^scenario: must be a stochpound.motions.Scenario, got"):
        scenario_distribution("pga", scenario=LOOSE)  # type: ignore[arg-type]


@pytest.mark.parametrize("name", bundled_rupture_sites())
def test_a_site_of_ruptures_iterates_as_its_scenarios_and_is_rebuilt_from_them(name):
    site = RuptureSite.bundled(name)
    ruptures = list(site)
    assert len(ruptures) == len(site) and all(scenario == site.scenario(i) for i, (scenario, _) in enumerate(ruptures))
    assert [rate for _, rate in ruptures] == list(site.rate)
    first, _ = ruptures[0]
    assert (first.magnitude, first.distance_km, first.dip, first.vs30) == (site.magnitude[0], site.distance_rup_km[0], site.dip[0], site.vs30)
    rebuilt = RuptureSite.from_scenarios(ruptures)
    assert list(rebuilt) == ruptures and dataclasses.replace(rebuilt, names=site.names) == site
