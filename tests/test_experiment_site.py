"""Experiments whose stripes run motions chosen for the site: [intensity] selection = "conditional_spectrum" and [site]."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from stochpound import open_store
from stochpound.analysis import HazardCurve
from stochpound.risk import store_risk
from stochpound.experiment._runner import load_experiment, run_experiment
from stochpound.experiment._spec import ExperimentError, parse_experiment
from stochpound.motions import TRUNCATION_EPSILON, conditional_spectrum, misses_target, select_motions, selection_periods, selection_pool
from stochpound.motions.records import Record, load_suite_member
from stochpound.report.render import FigureItem, Paragraph
from stochpound.report.sections._intensity import intensity_section
from stochpound.risk import selection_misses
from tests.helpers import SITE_SCENE as SCENE
from tests.helpers import write_experiment

MEMBERS = [f"fema_p695_far_field/{i:02d}{c}" for i in range(1, 7) for c in "ab"]
RECORDS = "".join(f'\n[[records]]\nrecord = "{name}"\nduration = 5.0\n' for name in MEMBERS)
SELECTION = 'measure = "psa"\nperiod = 0.5\nlevels = [0.4, 0.2]\nselection = "conditional_spectrum"\nmotions = 4\nmax_scale_factor = 5.0\nseed = 2\n'
SITE = '[site]\nvs30 = 400.0\nmagnitude = [7.0, 6.6]\ndistance_km = 20.0\nmechanism = "strike_slip"\n'


def _text(intensity: str | None = SELECTION, site: str = SITE) -> str:
    table = "" if intensity is None else f"[intensity]\n{intensity}\n"  # None: no [intensity] table
    return f'[experiment]\nname = "site"\n{SCENE}\n[grid]\ngap = ["inf"]\n{RECORDS}\n{table}{site}\n[solver]\nmethod = "exact"\n'


def test_each_stripe_runs_its_chosen_motions_and_the_store_keeps_the_selection(tmp_path) -> None:
    experiment = load_experiment(write_experiment(tmp_path, _text(), "site.toml"))
    scenarios = experiment.intensity.selection.scenarios
    assert [s.magnitude for s in scenarios] == [6.6, 7.0]  # one per level, in the order of the sorted levels
    # the structure's first-mode periods; the range 0.2 T_min - 3 T_max with T* added
    m1, m2, k1, k2 = 2.0e5, 1.5e5, 1.2e8, 0.9e8  # B1's first mode: det(K - ω² M) = 0, the smaller root
    b, c = (k1 + k2) / m1 + k2 / m2, k1 * k2 / (m1 * m2)
    omega = math.sqrt((b - math.sqrt(b * b - 4 * c)) / 2)
    assert experiment.selection.structure == pytest.approx(sorted([2 * math.pi / omega, 2 * math.pi * math.sqrt(1.0e5 / 1.5e7)]), rel=1e-10)
    report = run_experiment(experiment, workers=0, progress=False)
    assert report.complete and experiment.n_cases == 2 * 4 * 2  # cases and their references: 4 motions per stripe
    store = open_store(report.store).load()
    # a store's grid reads the choice from the store (nothing chosen again): the run's motions, cases and ids
    grid = store.pound.grid
    assert list(grid.motions) == list(experiment.motions) and grid.motions == experiment.motions
    for kind in ("case", "reference"):
        np.testing.assert_array_equal(grid.in_grid(kind), experiment.in_grid(kind))
        np.testing.assert_array_equal(grid.grid_case_ids(kind), experiment.grid_case_ids(kind))
    assert [c.case_id for c in grid.cases] == [c.case_id for c in experiment.cases]
    periods = selection_periods(experiment.selection.structure, [0.5])
    np.testing.assert_allclose(store.selection_period.values, periods)
    records = []
    for name in MEMBERS:  # the pool rebuilt here: the 5 s the cases run
        record = load_suite_member(name)
        n = int(round(5.0 / record.dt)) + 1
        records.append(Record(name, record.dt, record.acceleration(9.81)[:n], "m/s2"))
    pool = selection_pool(records, periods, "psa", 0.5)
    for j, (level, magnitude) in enumerate([(0.2, 6.6), (0.4, 7.0)]):
        target = conditional_spectrum("psa", 0.5, level=level, periods=periods, magnitude=magnitude, distance_km=20.0, vs30=400.0, mechanism="strike_slip")
        expected = select_motions(pool, target, 4, 5.0, seed=2)
        stripe = store.isel(intensity=j, realization=0).sel(gap=np.inf)
        chosen = list(stripe.record.values[np.isfinite(stripe.selection_scale_factor.values)])
        assert sorted(chosen) == sorted(expected["motion"].values)
        replayed = stripe.pound.scene(record=chosen[0]).motion  # one stripe of the store: its grid reads that stripe's choice
        np.testing.assert_array_equal(replayed.values, store.pound.scene(gap=np.inf, intensity=level, record=chosen[0], realization=0).motion.values)
        assert list(stripe.record.values[stripe.case_status.values == 1]) == chosen  # the others are not in the grid (-1)
        assert set(stripe.case_status.values) == {1, -1}
        ran = stripe.scale_factor.sel(record=chosen).values
        np.testing.assert_allclose(ran, level / stripe.motion_intensity.sel(record=chosen).values, rtol=1e-14)
        np.testing.assert_allclose(ran, stripe.selection_scale_factor.sel(record=chosen).values, rtol=1e-12)
        assert np.all(ran <= 5.0)
        np.testing.assert_allclose(store.target_median.isel(intensity=j), target["median"].values, rtol=1e-12)
        np.testing.assert_allclose(store.selection_mean_ln.isel(intensity=j), expected["mean_ln"].values, rtol=1e-12)
        assert store.site_magnitude.values[j] == magnitude and store.site_mechanism.values[j] == "strike_slip"
        miss = misses_target(expected["mean_ln"].values, expected["std_ln"].values, target["median"].values, target["sigma_ln"].values)
        assert store.selection_misses_target.values[j] == int(miss)
        assert store.selection_target_reachable.values[j] == expected.attrs["target_reachable"]
    # the report shows every stripe's target against its chosen set, and the stripes that miss it
    section = intensity_section("site", store)
    assert any(isinstance(block, FigureItem) and block.key == "intensity-selection-site" for block in section.blocks)
    text = " ".join(block.text for block in section.blocks if isinstance(block, Paragraph))
    missed = selection_misses(store)
    assert "chosen for the site" in text and ("misses its target" in text) == bool(missed)
    # a stripe whose scenario needs more than 3σ to reach its level is named as beyond the hazard models' truncation
    assert np.all(store.target_epsilon.values <= TRUNCATION_EPSILON) and "truncate" not in text
    beyond = store.assign(target_epsilon=store.target_epsilon.copy(data=[1.0, 3.4]))
    text = " ".join(block.text for block in intensity_section("site", beyond).blocks if isinstance(block, Paragraph))
    assert "At the stripe 0.4 g the scenario's ε is beyond 3, where hazard models truncate the ground motion" in text
    assert "and the stripe stands for larger or nearer ones than the scenario." in text
    # the risk chain counts the chosen motions of each stripe only
    risk = store_risk(store, HazardCurve.power_law(1e-4, 2.5), bootstrap=0)
    assert risk.motions == 4 and np.all(risk.fragility["runs"].values == 4)


def test_the_default_selection_adds_nothing_to_the_definition(tmp_path) -> None:
    plain = 'measure = "psa"\nperiod = 0.5\nlevels = [0.4, 0.2]\n'
    definition = parse_experiment(tomllib.loads(_text(plain, "")), tmp_path)
    explicit = parse_experiment(tomllib.loads(_text(plain + 'selection = "scale"\n', "")), tmp_path)
    assert definition == explicit and "selection" not in definition["intensity"] and "site" not in definition["intensity"]


@pytest.mark.parametrize(
    "intensity, site, field",
    [
        (SELECTION, "", "site:"),
        (SELECTION, SITE.replace("magnitude = [7.0, 6.6]", "magnitude = [7.0, 6.6, 6.0]"), "site.magnitude:"),
        (SELECTION, SITE.replace("mechanism = \"strike_slip\"", "mechanism = \"oblique\""), "site.mechanism:"),
        (SELECTION, SITE.replace("magnitude = [7.0, 6.6]", "magnitude = [7.0, 9.6]"), "site.magnitude[1]:"),
        (SELECTION, SITE.replace("vs30 = 400.0", "vs30 = 50.0"), "site.vs30:"),
        (SELECTION, SITE.replace("distance_km = 20.0\n", ""), "site.distance_km:"),
        (SELECTION.replace("motions = 4", "motions = 1"), SITE, "intensity.motions:"),
        (SELECTION.replace("max_scale_factor = 5.0\n", ""), SITE, "intensity.max_scale_factor:"),
        (SELECTION.replace("period = 0.5", "period = 12.0"), SITE, "intensity.period:"),
        (SELECTION.replace('selection = "conditional_spectrum"', 'selection = "best"'), SITE, "intensity.selection:"),
        ('measure = "pgv"\nlevels = [0.2]\nselection = "conditional_spectrum"\nmotions = 4\nmax_scale_factor = 5.0', SITE, "intensity.measure:"),
        ('measure = "psa"\nperiod = 0.5\nlevels = [0.2]', SITE, "site:"),
        ('measure = "psa"\nperiod = 0.5\nlevels = [0.2]\nmotions = 4', "", "intensity.motions:"),
        (None, SITE, "site:"),
    ],
)
def test_bad_input_is_one_line_naming_the_field(tmp_path, intensity: str, site: str, field: str) -> None:
    with pytest.raises(ExperimentError) as error:
        parse_experiment(tomllib.loads(_text(intensity, site)), tmp_path)
    assert str(error.value).startswith(field) and "\n" not in str(error.value)


def test_a_pool_too_small_for_the_limit_names_the_field(tmp_path) -> None:
    text = _text(SELECTION.replace("max_scale_factor = 5.0", "max_scale_factor = 1.0").replace("motions = 4", "motions = 10"))
    experiment = load_experiment(write_experiment(tmp_path, text, "small.toml"))
    with pytest.raises(ExperimentError, match=r"^intensity\.motions: only \d+ of the pool's 12 motions reach the level"):
        experiment.selection
