"""A conditional-spectrum pool extended by simulated motions ([site] simulated_motions) and the selection's rules (issue 43)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stochpound import open_store
from stochpound.experiment._runner import load_experiment, run_experiment
from stochpound.experiment._sources import resolve_motions
from stochpound.experiment._spec import ExperimentError
from stochpound.motions import conditional_spectrum, select_motions, selection_pool, site_model_provenance, site_motions
from stochpound.motions.records import load_suite, load_suite_member
from stochpound.report.render import Paragraph
from stochpound.report.sections._intensity import intensity_section
from stochpound.report.sections._stripe_motions import stripe_motions_text
from stochpound.store import SimulatedMotions
from tests.helpers import SITE_SCENE as SCENE
from tests.helpers import write_experiment

MEMBERS = [f"fema_p695_far_field/{i:02d}{c}" for i in range(1, 4) for c in "ab"]
RECORDS = "".join(f'\n[[records]]\nrecord = "{name}"\nduration = 5.0\n' for name in MEMBERS)
SELECTION = 'measure = "psa"\nperiod = 0.5\nlevels = [0.4, 0.2]\nselection = "conditional_spectrum"\nmotions = 4\nmax_scale_factor = 5.0\nseed = 2\n'
SITE = '[site]\nvs30 = 400.0\nmagnitude = [7.0, 6.6]\ndistance_km = 20.0\nmechanism = "strike_slip"\nsimulated_motions = 6\n'


def _text(intensity: str = SELECTION, site: str = SITE) -> str:
    return f'[experiment]\nname = "pool"\n{SCENE}\n[grid]\ngap = ["inf"]\n{RECORDS}\n[intensity]\n{intensity}\n{site}\n[solver]\nmethod = "exact"\n'


ONE_SCENARIO = SITE.replace("magnitude = [7.0, 6.6]", "magnitude = 7.0")


@pytest.mark.parametrize("site", [SITE, ONE_SCENARIO], ids=["a scenario per level", "one scenario"])
def test_the_chosen_simulated_motions_are_the_ones_their_tables_regenerate(tmp_path, site) -> None:
    """With one scenario the stripes share the table, hence the motions (generated once, relabelled per stripe); a motion
    chosen in both stripes runs as its table regenerates it in each."""
    experiment = load_experiment(write_experiment(tmp_path, _text(site=site), "pool.toml"))
    selection = experiment.selection
    realizations = [source.motion["realization"] for source in selection.simulated.values()]
    assert site == SITE or len(set(realizations)) < len(realizations)  # one scenario: a motion chosen in both stripes
    assert list(experiment.motions) == MEMBERS + list(selection.simulated) and selection.simulated
    resolved = resolve_motions(experiment)
    for label, source in selection.simulated.items():
        table = experiment.motion_table(label)
        assert source.kind == "simulated" and table["type"] == "site_motions" and table["n"] == 6
        again = site_motions(table["magnitude"], table["distance_km"], table["vs30"], table["mechanism"], n=6, seed=2, dt=0.01)
        np.testing.assert_array_equal(resolved[label].motion.values, again.acceleration.values[table["realization"]])
    counts = selection.stripe_counts()
    for j, chosen in enumerate(selection.selections):
        labels = [str(m) for m in chosen.motion.values]
        n_sim = sum(label in selection.simulated for label in labels)
        assert int(counts["selection_simulated"].values[j]) == n_sim and int(counts["selection_recorded"].values[j]) == 4 - n_sim
        assert all(label.startswith(f"simulated {j + 1}.") for label in labels if label in selection.simulated)


@pytest.mark.slow
def test_simulated_motions_join_the_pool_and_regenerate_bit_for_bit_from_the_store(tmp_path) -> None:
    experiment = load_experiment(write_experiment(tmp_path, _text(), "pool.toml"))
    setting = experiment.intensity.selection.simulated
    assert setting == SimulatedMotions(6, "hazard_compatible", site_model_provenance(), 2, 0.01)
    assert experiment.definition.to_dict()["intensity"]["simulated_motions"] == {"count": 6, "model": "hazard_compatible",
                                                                                "calibration": site_model_provenance(), "seed": 2, "dt": 0.01}
    report = run_experiment(experiment, workers=0, progress=False)
    assert report.complete
    store = open_store(report.store).load()
    kinds = dict(zip(store.record.values, store.record_kind.values))
    simulated = [label for label, kind in kinds.items() if kind == "simulated"]
    assert simulated, "the chosen motions should include simulated ones (the records alone are 6 for 2 x 4 places)"
    ran_motions = resolve_motions(experiment)
    for label in simulated:  # regenerated from what the store records, compared with what ran
        table = json.loads(str(store.record_motion.sel(record=label).values))
        motion = site_motions(table["magnitude"], table["distance_km"], table["vs30"], table["mechanism"], n=table["n"], seed=table["seed"],
                              dt=table["dt"], model=table["model"]).acceleration.values[table["realization"]]
        assert table["calibration"] == site_model_provenance(table["model"])
        stripe = int(np.flatnonzero(np.isfinite(store.selection_scale_factor.sel(record=label).values))[0])
        ran = store.isel(intensity=stripe, realization=0).sel(gap=np.inf, record=label)
        scale = float(ran.scale_factor)
        np.testing.assert_array_equal(ran_motions[label].motion.values, motion)
        assert float(ran.motion_pga) == pytest.approx(np.max(np.abs(motion)), rel=1e-12)
        assert scale == pytest.approx(float(ran.selection_scale_factor), rel=1e-12)
        level = float(store.intensity.values[stripe])
        replayed = store.pound.scene(gap=np.inf, intensity=level, record=label, realization=0).motion  # the case's scene, from its table
        np.testing.assert_array_equal(replayed.values, motion * scale)
    # each stripe states its recorded and simulated motions and its earthquakes (a simulated motion its own)
    for j in range(2):
        chosen = store.record.values[np.isfinite(store.selection_scale_factor.isel(intensity=j).values)]
        n_sim = sum(kinds[c] == "simulated" for c in chosen)
        assert int(store.selection_simulated[j]) == n_sim and int(store.selection_recorded[j]) == len(chosen) - n_sim == 4 - n_sim
        events = {str(store.record_event.sel(record=c).values) if kinds[c] == "record" else c for c in chosen}
        assert int(store.selection_earthquakes[j]) == len(events)
    # issue 45: the Methods' counts and the motion table give the simulated motions that ran (the definition lists the records only)
    from stochpound.report.sections._description import StoreDefinition, grid_paragraph, motions_table
    ran_simulated = [label for label in simulated if bool((store["case_status"].sel(record=label) == 1).any())]
    recorded = sum(1 for label, kind in kinds.items() if kind == "record" and bool((store["case_status"].sel(record=label) == 1).any()))
    described = StoreDefinition("pool", store)
    assert (f"under the {recorded + len(ran_simulated)} motions that ran ({recorded} of the 6 the experiment defines, and "
            f"{len(ran_simulated)} simulated for the stripes' scenarios)") in grid_paragraph(described).text
    table = motions_table([described])
    assert table.frame["motion"].iloc[-1].endswith(f"({len(ran_simulated)} simulated)") and len(table.frame) == recorded + 1
    text = " ".join(block.text for block in intensity_section("pool", store).blocks if isinstance(block, Paragraph))
    assert "from a pool of 6 records and 6 simulated motions of each stripe's scenario" in stripe_motions_text(store)
    assert f"0.2 g: {int(store.selection_recorded[0])} recorded and {int(store.selection_simulated[0])} simulated from" in text


def test_the_simulated_motions_are_part_of_the_identity(tmp_path) -> None:
    with_them = load_experiment(write_experiment(tmp_path, _text(), "a.toml"))
    without = load_experiment(write_experiment(tmp_path, _text(site=SITE.replace("simulated_motions = 6\n", "")), "b.toml"))
    other = load_experiment(write_experiment(tmp_path, _text(site=SITE.replace("= 6", "= 7")), "c.toml"))
    assert len({with_them.sha256, without.sha256, other.sha256}) == 3
    assert without.intensity.selection.simulated is None and without.intensity.selection.max_per_earthquake is None
    entry = without.definition.to_dict()["intensity"]
    assert "simulated_motions" not in entry and "max_per_earthquake" not in entry


def test_tolerance_first_is_a_rule_of_the_definition_and_the_store_says_which_stripes_it_chose(tmp_path) -> None:
    """``[intensity] tolerance_first = true`` is in the definition and the identity (absent, nothing is); the selection's store
    variables say per stripe whether it chose the set; a value that is not a boolean is a one-line error naming the field."""
    ruled = load_experiment(write_experiment(tmp_path, _text(SELECTION + "tolerance_first = true\n"), "t.toml"))
    plain = load_experiment(write_experiment(tmp_path, _text(), "p.toml"))
    assert ruled.definition.to_dict()["intensity"]["tolerance_first"] is True and "tolerance_first" not in plain.definition.to_dict()["intensity"]
    assert ruled.sha256 != plain.sha256 and ruled.intensity.selection.rules["tolerance_first"] is True
    chosen_by = ruled.selection.coordinates()["selection_tolerance_first"]
    expected = [int(s.attrs["chosen_by"] == "tolerance") for s in ruled.selection.selections]
    assert chosen_by.dims == ("intensity",) and chosen_by.values.tolist() == expected
    with pytest.raises(ExperimentError, match=r"^intensity.tolerance_first: ") as error:
        load_experiment(write_experiment(tmp_path, _text(SELECTION + 'tolerance_first = "yes"\n'), "y.toml"))
    assert "\n" not in str(error.value)


def _pool(names: list[str], periods: np.ndarray) -> object:
    return selection_pool([load_suite_member(name) for name in names], periods, "psa", 0.5)


def test_the_rules_cap_earthquakes_keep_recordings_distinct_and_drop_pulses() -> None:
    periods = np.geomspace(0.1, 2.0, 8)
    records = load_suite("fema_p695_near_field")
    pool = selection_pool(records, periods, "psa", 0.5)
    assert int(pool.pulse.sum()) == 28  # FEMA P695 lists 14 of the 28 near-field records (2 components each) as pulses
    target = conditional_spectrum("psa", 0.5, level=0.5, periods=periods, magnitude=7.0, distance_km=10.0, vs30=400.0, mechanism="strike_slip")
    free = select_motions(pool, target, 8, 5.0, seed=1)
    ruled = select_motions(pool, target, 8, 5.0, seed=1, max_per_earthquake=1, exclude_pulses=True)
    events = dict(zip(pool.motion.values, pool.earthquake.values))
    pulses = dict(zip(pool.motion.values, pool.pulse.values))
    assert len(set(ruled.earthquake.values)) == 8 and not any(pulses[m] for m in ruled.motion.values)
    assert [events[m] for m in ruled.motion.values] == list(ruled.earthquake.values)
    assert max(np.unique(free.earthquake.values, return_counts=True)[1]) > 1  # the rule changed something here
    # the same recording twice in the pool (two suites) never enters a set twice
    twice = selection_pool(records[:8] + load_suite("fema_p695_near_field_pulse")[:8], periods, "psa", 0.5)
    chosen = select_motions(twice, target, 6, 10.0, seed=1).motion.values
    recordings = dict(zip(twice.motion.values, twice.recording.values))
    assert len({recordings[m] for m in chosen}) == 6


def test_a_pool_that_cannot_meet_the_rules_is_a_one_line_error_naming_the_fields(tmp_path) -> None:
    experiment = load_experiment(write_experiment(tmp_path, _text(SELECTION + "max_per_earthquake = 1\n", SITE.replace("simulated_motions = 6\n", "")), "r.toml"))
    with pytest.raises(ExperimentError) as error:
        experiment.selection
    message = str(error.value)
    assert "\n" not in message and message.startswith("intensity.motions:") and "max_per_earthquake = 1" in message and "max_scale_factor" in message
    with pytest.raises(ExperimentError, match=r"^intensity.max_per_earthquake: .*>= 1, got 0$"):
        load_experiment(write_experiment(tmp_path, _text(SELECTION + "max_per_earthquake = 0\n"), "z.toml"))
    with pytest.raises(ExperimentError, match=r"^site.simulated_motions: .*got -1$"):
        load_experiment(write_experiment(tmp_path, _text(site=SITE.replace("= 6", "= -1")), "n.toml"))


def test_a_subset_of_site_motions_is_bit_for_bit_the_same_rows_and_a_scene_runs_one() -> None:
    from stochpound.model.scene_file import scene_from_dict

    full = site_motions(6.6, 20.0, 400.0, "strike_slip", n=5, seed=4)
    part = site_motions(6.6, 20.0, 400.0, "strike_slip", n=5, seed=4, realizations=[3, 1])
    np.testing.assert_array_equal(part.acceleration.values, full.acceleration.values[[3, 1]])
    assert list(part.realization.values) == [3, 1] and part.attrs["n"] == 5
    building = {"name": "B1", "mass": [1.0e5], "stiffness": [1.5e7], "damping_ratio": 0.05}
    table = {"type": "site_motions", "magnitude": 6.6, "distance_km": 20.0, "vs30": 400.0, "mechanism": "strike_slip", "n": 5, "seed": 4,
             "realization": 3, "scale": 1.5, "calibration": site_model_provenance()}
    motion = scene_from_dict({"building": [building], "motion": table}).motion
    np.testing.assert_array_equal(motion.values, full.acceleration.values[3] * 1.5)
    with pytest.raises(Exception, match=r"^motion.calibration: "):
        scene_from_dict({"building": [building], "motion": {**table, "calibration": "another"}})
    with pytest.raises(Exception, match=r"^motion.realization: "):
        scene_from_dict({"building": [building], "motion": {**table, "realization": 5}})


def test_a_scenario_outside_the_site_motion_model_is_a_one_line_error(tmp_path) -> None:
    site = SITE.replace("magnitude = [7.0, 6.6]", "magnitude = [7.0, 5.2]")  # within the NGA-West2 models, below the site-motion model's 5.5
    experiment = load_experiment(write_experiment(tmp_path, _text(site=site), "m.toml"))
    with pytest.raises(ExperimentError, match=r"^site.simulated_motions: the stripe 0.2 g's scenario: magnitude: .*5.5") as error:
        experiment.selection
    assert "\n" not in str(error.value)
