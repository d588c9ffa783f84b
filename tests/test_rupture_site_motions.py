"""Stripes' pools of simulated motions of a site's causal ruptures: ``[site] simulated_motions`` with ``[site] ruptures`` (issue 44)."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest
from scipy.stats import norm

from stochpound import open_store
from stochpound.analysis import RuptureSite
from stochpound.experiment._runner import load_experiment, run_experiment
from stochpound.experiment._stripe_pools import largest_remainders, rupture_allotment
from stochpound.experiment._sources import resolve_motions
from stochpound.experiment._spec import ExperimentError, parse_experiment
from stochpound.motions import GEOMETRY_FIELDS, Scenario, site_model_provenance, site_motions
from tests.helpers import SITE_SCENE, write_experiment

HEADER = "name,magnitude,distance_rup_km,distance_jb_km,distance_x_km,ztor_km,dip,mechanism,rate\n"
TWO = f"# vs30: 400\n{HEADER}big,7.5,30.0,30.0,-30.0,0.0,90,strike_slip,0.01\nnear,6.2,8.0,6.0,5.0,2.0,45,reverse,0.01\n"
LEVELS = [0.1, 0.5]
COUNT = 10


def _experiment(site: str, records: str = "") -> str:
    return (f'[experiment]\nname = "ruptures"\n{SITE_SCENE}\n[grid]\ngap = ["inf"]\n{records}\n[intensity]\nmeasure = "psa"\nperiod = 0.5\n'
            f'levels = {LEVELS}\nselection = "conditional_spectrum"\nmotions = 4\nmax_scale_factor = 5.0\nseed = 2\n{site}\n[solver]\nmethod = "exact"\n')


SITE = f'[site]\nruptures = "two.csv"\nsimulated_motions = {COUNT}\n'


@pytest.fixture
def folder(tmp_path):
    (tmp_path / "two.csv").write_text(TWO)
    return tmp_path


def test_largest_remainders_apportion_the_count_with_ties_to_the_earlier_entry() -> None:
    assert largest_remainders(10, np.array([0.55, 0.45])).tolist() == [6, 4]  # 5.5 and 4.5: the tie to the first
    assert largest_remainders(7, np.array([0.5, 0.3, 0.2])).tolist() == [4, 2, 1]  # 3.5, 2.1, 1.4: one more to the largest remainder
    assert largest_remainders(5, np.array([0.0, 0.97, 0.03])).tolist() == [0, 5, 0]
    shares = np.random.default_rng(3).dirichlet(np.ones(9))
    assert int(largest_remainders(101, shares).sum()) == 101


def test_each_stripes_pool_follows_the_disaggregation_weights_of_its_level(folder) -> None:
    site = RuptureSite.from_file(folder / "two.csv")
    mean, sigma = site.moments("psa", 0.5)
    density = np.asarray(site.rate) * norm.pdf(np.log(LEVELS)[:, None], mean, sigma)  # ν_r f(ln x | r), summed over the ruptures here
    weights = density / density.sum(axis=1, keepdims=True)
    assert weights[0, 0] > 0.5 > weights[1, 0]  # the levels differ in their causal rupture: the test can fail
    allotment = rupture_allotment(site, "psa", 0.5, LEVELS, COUNT)
    for row, w in zip(allotment, weights):
        exact = COUNT * w
        assert row.sum() == COUNT and np.all(np.abs(row - exact) < 1.0)
        assert row.tolist() == largest_remainders(COUNT, w).tolist()
    experiment = load_experiment(write_experiment(folder, _experiment(SITE), "two.toml"))
    selection = experiment.selection
    for stripe, chosen in enumerate(selection.selections):
        labels = [str(m) for m in chosen.motion.values]
        assert len(labels) == 4 and all(label.startswith(f"simulated {stripe + 1}.") for label in labels)
        for label in labels:  # a chosen motion is one of its rupture's first allotment[stripe, r] realizations
            table = selection.simulated[label].motion
            r = site.names.index(table["rupture"])
            assert table["realization"] < allotment[stripe, r] and table["n"] == allotment[:, r].max()
            assert (table["magnitude"], table["distance_km"], table["mechanism"]) == (site.magnitude[r], site.distance_rup_km[r], site.mechanism[r])


def test_a_site_of_ruptures_takes_simulated_motions_beside_records_and_into_its_identity(folder) -> None:
    records = '[[records]]\nrecord = "fema_p695_far_field/01a"\n[[records]]\nrecord = "fema_p695_far_field/02a"\n'
    base = '[site]\nruptures = "two.csv"\n'
    definitions = [parse_experiment(tomllib.loads(_experiment(site, records)), folder) for site in (base, SITE)]
    assert "simulated_motions" not in definitions[0]["intensity"]
    assert definitions[1]["intensity"]["simulated_motions"] == {"count": COUNT, "model": "hazard_compatible",
                                                                "calibration": site_model_provenance(), "seed": 2, "dt": 0.01}
    assert [m["label"] for m in definitions[1]["motions"]] == ["fema_p695_far_field/01a", "fema_p695_far_field/02a"]
    assert parse_experiment(tomllib.loads(_experiment(SITE)), folder)["motions"] == []  # the pool may be the simulated motions alone


@pytest.mark.parametrize(
    "site, records, message",
    [
        (SITE.replace(f"= {COUNT}", "= 0"), "", r"^site\.simulated_motions: .*1-100000, got 0$"),
        (SITE.replace(f"= {COUNT}", '= "ten"'), "", r"^site\.simulated_motions: .*got 'ten'$"),
        ('[site]\nruptures = "two.csv"\n', "", r"^records: no motion "),
    ],
)
def test_bad_simulated_motions_at_a_site_of_ruptures_are_one_line_naming_the_field(folder, site, records, message) -> None:
    with pytest.raises(ExperimentError, match=message) as error:
        parse_experiment(tomllib.loads(_experiment(site, records)), folder)
    assert "\n" not in str(error.value)


def test_a_causal_rupture_outside_the_site_motion_model_is_refused_naming_it(folder) -> None:
    (folder / "low.csv").write_text(TWO.replace("near,6.2,", "near,5.2,"))  # within the NGA-West2 models, below the site-motion model's 5.5
    experiment = load_experiment(write_experiment(folder, _experiment(SITE.replace("two.csv", "low.csv")), "low.toml"))
    with pytest.raises(ExperimentError, match=r"^site\.simulated_motions: the stripe 0\.1 g's rupture near: magnitude: .*5\.5") as error:
        experiment.selection
    assert "\n" not in str(error.value)


def test_a_site_motion_table_takes_a_ruptures_geometry_and_refuses_a_bad_one() -> None:
    from stochpound.model.scene_file import scene_from_dict

    building = {"name": "B1", "mass": [1.0e5], "stiffness": [1.5e7], "damping_ratio": 0.05}
    geometry = {"distance_jb_km": 6.0, "distance_x_km": 5.0, "ztor_km": 2.0, "dip": 45.0}
    table = {"type": "site_motions", "magnitude": 6.2, "distance_km": 8.0, "vs30": 400.0, "mechanism": "reverse", **geometry, "rupture": "near",
             "n": 3, "seed": 5, "realization": 2}
    hanging = site_motions(n=3, seed=5, scenario=Scenario(6.2, 8.0, 400.0, "reverse", **geometry)).acceleration.values[2]
    estimated = site_motions(6.2, 8.0, 400.0, "reverse", n=3, seed=5).acceleration.values[2]
    motion = scene_from_dict({"building": [building], "motion": table}).motion
    np.testing.assert_array_equal(motion.values, hanging)
    assert not np.array_equal(hanging[: estimated.size], estimated[: hanging.size])  # the geometry changes the motion: the check can fail
    with pytest.raises(Exception, match=r"^motion\.dip: "):
        scene_from_dict({"building": [building], "motion": {**table, "dip": 5.0}})


@pytest.mark.slow
def test_the_stores_simulated_motions_keep_their_rupture_and_regenerate_bit_for_bit_whatever_the_workers(folder) -> None:
    site = RuptureSite.from_file(folder / "two.csv")
    stores = []
    for workers, name in ((0, "serial.toml"), (2, "parallel.toml")):
        experiment = load_experiment(write_experiment(folder, _experiment(SITE), name))
        report = run_experiment(experiment, workers=workers, progress=False)
        assert report.complete
        stores.append(open_store(report.store).load())
    store = stores[0]
    for name in ("peak_contact_closure", "scale_factor", "selection_scale_factor"):
        if name in store:
            np.testing.assert_array_equal(store[name].values, stores[1][name].values)
    ran = resolve_motions(experiment)
    assert set(store.record_kind.values) == {"simulated"}
    for label in store.record.values:
        table = json.loads(str(store.record_motion.sel(record=label).values))
        r = site.names.index(table["rupture"])
        own = site.scenario(r)
        assert table["calibration"] == site_model_provenance(table["model"]) and table["seed"] != 2  # the rupture's own stream
        assert float(store.record_magnitude.sel(record=label)) == own.magnitude and float(store.record_distance.sel(record=label)) == own.distance_km
        scenario = Scenario(**{key: table[key] for key in ("magnitude", "distance_km", "vs30", "mechanism", *GEOMETRY_FIELDS) if key in table})
        assert scenario == own
        again = site_motions(scenario=scenario, n=table["n"], seed=table["seed"], dt=table["dt"], model=table["model"]).acceleration.values
        np.testing.assert_array_equal(ran[str(label)].motion.values, again[table["realization"]])
        stripe = int(np.flatnonzero(np.isfinite(store.selection_scale_factor.sel(record=label).values))[0])
        level = float(store.intensity.values[stripe])
        replayed = store.pound.scene(gap=np.inf, intensity=level, record=str(label), realization=0).motion
        scale = float(store.selection_scale_factor.sel(record=label).values[stripe])
        np.testing.assert_allclose(replayed.values, again[table["realization"]] * scale, rtol=1e-12, atol=0.0)


def test_a_simulated_motions_epsilon_is_taken_in_its_own_rupture() -> None:
    """The sufficiency test's ε of a simulated motion of a site's rupture: its rupture's mechanism and geometry, not the stripe's."""
    import xarray as xr

    from stochpound.analysis._sufficiency import _simulated_ruptures

    geometry = {"distance_jb_km": 6.0, "distance_x_km": 5.0, "ztor_km": 2.0, "dip": 45.0}
    tables = [{"type": "site_motions", "magnitude": 6.2, "distance_km": 8.0, "vs30": 400.0, "mechanism": "reverse", **geometry, "rupture": "near"},
              {"type": "record", "record": "fema_p695_far_field/01a"}]
    store = xr.Dataset(coords={"record": ["simulated 1.2.0", "01a"], "record_motion": ("record", [json.dumps(t) for t in tables])})
    assert _simulated_ruptures(store) == [("reverse", geometry), (None, {})]
