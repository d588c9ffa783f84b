"""Intensity-conditioned experiments: the [intensity] table, suites in [[records]], stripes and IDA.

* a fixed-base scene's contact-free closures and scale factors scale exactly with the level;
* the IDA capacities agree with brute-force runs: a run pounds iff its scale
  reaches g / D_i (checked just below and just above it);
* errors name the field; files without the new tables keep their definitions.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.stats import binomtest

from stochpound import open_store
from stochpound.experiment._runner import load_experiment, run_experiment
from stochpound.experiment._sources import resolve_motions
from stochpound.experiment._spec import ExperimentError, load_definition, parse_experiment
from stochpound.model.scene_file import scene_from_dict
from stochpound.report.render._document import FigureItem, Table
from stochpound.report.sections._intensity import intensity_section
from stochpound.solvers.simulate import simulate
from tests.helpers import SITE_SCENE as SCENE
from tests.helpers import write_experiment

REPOSITORY = Path(__file__).resolve().parent.parent
MOTIONS = ["fema_p695_far_field/01a", "fema_p695_far_field/03b", "fema_p695_far_field/12a"]
RECORDS = "".join(f'\n[[records]]\nrecord = "{name}"\nduration = 4.0\n' for name in MOTIONS)


def _experiment(grid: str, intensity: str, scene: str = SCENE, records: str = RECORDS) -> str:
    return f'[experiment]\nname = "im"\n{scene}\n[grid]\n{grid}\n{records}\n[intensity]\n{intensity}\n[output]\nimpacts = true\n[solver]\nmethod = "exact"\n'


def test_stripes_scale_exactly_with_the_level(tmp_path):
    text = _experiment('gap = ["inf"]', 'measure = "psa"\nperiod = 0.5\nlevels = [0.1, 0.25, 0.6]')
    report = run_experiment(load_experiment(write_experiment(tmp_path, text, "stripes.toml")), workers=0, progress=False)
    assert report.complete
    store = open_store(report.store).load()
    levels = store.intensity.values
    closure = store.peak_contact_closure.sel(gap=np.inf).isel(realization=0, contact=0)
    scale = store.scale_factor.sel(gap=np.inf).isel(realization=0)
    im = store.motion_intensity.sel(gap=np.inf).isel(realization=0)
    for j, level in enumerate(levels):
        np.testing.assert_allclose(scale.isel(intensity=j), level / im.isel(intensity=j), rtol=1e-15)
        np.testing.assert_allclose(closure.isel(intensity=j) / level, closure.isel(intensity=0) / levels[0], rtol=1e-10)
        np.testing.assert_allclose(scale.isel(intensity=j) / level, scale.isel(intensity=0) / levels[0], rtol=1e-14)
    # the stored unscaled measures are the motion's own, whatever the level
    from stochpound.motions import response_spectrum
    from stochpound.motions.records import load_record

    record = load_record(MOTIONS[1])
    a = record.acceleration(9.81)[: int(round(4.0 / record.dt)) + 1]
    psa = response_spectrum(a, record.dt, [0.5]).psa.item() / 9.81
    assert float(im.sel(record=MOTIONS[1]).isel(intensity=2)) == pytest.approx(psa, rel=1e-14)
    assert list(store.record_event.values[:1]) == ["Northridge 1994"] and store.record_magnitude.values[1] == 7.1
    assert store.motion_psa.dims[-1] == "spectrum_period" and store.reference_status.dims[0] == "intensity"
    # the report's stripe table: counts of runs that pounded and their Clopper-Pearson interval
    section = intensity_section("im", store)
    table = next(block for block in section.blocks if isinstance(block, Table)).frame
    assert list(table["runs"]) == [3, 3, 3] and list(table["pounded"]) == [0, 0, 0]  # contact-free: nobody pounds
    assert table["upper"].iloc[0] == pytest.approx(binomtest(0, 3).proportion_ci(0.95, method="exact").high, rel=1e-12)


def test_ida_capacities_agree_with_brute_force(tmp_path):
    gaps = [0.005, 0.02]
    text = _experiment(f"gap = {gaps}", 'measure = "pga"\nlevels = [0.3]\nmethod = "ida"')
    experiment = load_experiment(write_experiment(tmp_path, text, "ida.toml"))
    assert experiment.intensity.ran == "ida" and "intensity" not in [d.name for d in experiment.dims]
    report = run_experiment(experiment, workers=0, progress=False)
    store = open_store(report.store).load()
    capacity = store.ida_capacity.isel(realization=0)
    assert capacity.dims == ("gap", "record")
    closure = store.peak_contact_closure.isel(realization=0, contact=0)
    xr_pga = store.motion_intensity.isel(realization=0)
    np.testing.assert_allclose(capacity, xr_pga * store.gap / closure, rtol=1e-15)
    np.testing.assert_array_equal(closure.isel(gap=0), closure.isel(gap=1))  # one contact-free run per motion
    structure = tomllib.loads(SCENE)["scene"]
    for record in MOTIONS:
        for gap in gaps:
            threshold = float(capacity.sel(record=record, gap=gap) / xr_pga.sel(record=record, gap=gap))  # the scale g / D
            for factor, pounds in ((1 - 1e-9, False), (1 + 1e-9, True)):
                scene = {**structure, "contact": [{**structure["contact"][0], "gap": gap}]}
                scene["motion"] = {"record": record, "duration": 4.0, "scale": threshold * factor}
                run = simulate(scene_from_dict(scene), "exact")
                assert (run.sizes["impact"] > 0) == pounds, (record, gap, factor)
    assert any(isinstance(block, FigureItem) and block.key == "intensity-ida-im" for block in intensity_section("im", store).blocks)


def test_ida_falls_back_to_stripes_on_a_sliding_base(tmp_path):
    scene = SCENE.replace('name = "B1"\n', 'name = "B1"\nbase = { mass = 1.0e5, mu = 0.1 }\n')
    definition = parse_experiment(tomllib.loads(_experiment("gap = [0.01]", 'measure = "pga"\nlevels = [0.2]\nmethod = "ida"', scene=scene)), tmp_path)
    assert definition["intensity"]["ran"] == "stripes" and "sliding base" in definition["intensity"]["note"]


def test_ida_on_a_yielding_scene_is_an_error_that_says_to_run_stripes(tmp_path):
    scene = SCENE.replace('name = "B1"\n', 'name = "B1"\nyield_force = [4.0e5, 3.0e5]\n')
    with pytest.raises(ExperimentError, match=r'^intensity.method: ida needs elastic storeys, scene has yield_force .*run method = "stripes"$'):
        parse_experiment(tomllib.loads(_experiment("gap = [0.01]", 'measure = "pga"\nlevels = [0.2]\nmethod = "ida"', scene=scene)), tmp_path)


@pytest.mark.parametrize(
    ("intensity", "message"),
    [
        ('measure = "pgd"\nlevels = [0.1]', "^intensity.measure: must be one of"),
        ('measure = "pga"\nlevels = [0.1, 0.0]', r"^intensity.levels\[1\]: must be > 0"),
        ('measure = "pga"\nlevels = []', "^intensity.levels: must be a non-empty list"),
        ('measure = "psa"\nlevels = [0.1]', "^intensity.period: missing"),
        ('measure = "pga"\nlevels = [0.1]\nunits = "m/s"', "^intensity.units: must be one of g, m/s2"),
        ('measure = "pga"\nlevels = [0.1]\nmethod = "cloud"', "^intensity.method: must be one of stripes, ida"),
    ],
)
def test_intensity_errors_name_the_field(intensity, message, tmp_path):
    with pytest.raises(ExperimentError, match=message):
        parse_experiment(tomllib.loads(_experiment("gap = [0.01]", intensity)), tmp_path)


def test_unknown_suite_and_unresolvable_period(tmp_path):
    records = '\n[[records]]\nsuite = "fema_p695_middle_field"\n'
    with pytest.raises(ExperimentError, match=r"^records\[0\].suite: unknown suite"):
        parse_experiment(tomllib.loads(_experiment("gap = [0.01]", 'measure = "pga"\nlevels = [0.1]', records=records)), tmp_path)
    path = write_experiment(tmp_path, _experiment("gap = [0.01]", 'measure = "psa"\nperiod = 0.015\nlevels = [0.1]'), "short.toml")
    with pytest.raises(ExperimentError, match=r"^intensity.period: 0.015 s is shorter than 2·dt = 0.02 s of records\[0\]"):
        resolve_motions(load_experiment(path))


def test_suite_expands_into_its_motions(tmp_path):
    records = '\n[[records]]\nsuite = "fema_p695_near_field_pulse"\nduration = 2.0\n'
    definition = parse_experiment(tomllib.loads(_experiment("gap = [0.01]", 'measure = "pga"\nlevels = [0.1]', records=records)), tmp_path)
    labels = [m["label"] for m in definition["motions"]]
    assert len(labels) == 28 and labels[0] == "fema_p695_near_field_pulse/01a"
    assert definition["motions"][0]["motion"] == {"record": labels[0], "duration": 2.0, "type": "record", "file_sha256": None}


def test_files_without_the_new_tables_keep_their_definitions():
    definition, _ = load_definition(REPOSITORY / "experiments" / "quickstart.toml")
    assert "intensity" not in definition and all("suite" not in m for m in definition["motions"])
    assert math.isfinite(definition["mu"]["values"][0])


@pytest.mark.parametrize("synthetic", ["each", "expected"])
def test_synthetic_ensembles_scaled_each_or_by_their_mean(synthetic, tmp_path):
    ensemble = '\n[synthetic.kt]\ntype = "kanai_tajimi"\ncount = 4\nseed = 5\nomega_g = 15.0\nzeta_g = 0.6\npga = 3.0\nenvelope = "jennings"\nduration = 4.0\ndt = 0.01\n'
    text = _experiment('gap = ["inf"]', f'measure = "pga"\nlevels = [0.1, 0.3]\nsynthetic = "{synthetic}"', records=ensemble)
    report = run_experiment(load_experiment(write_experiment(tmp_path, text, f"{synthetic}.toml")), workers=0, progress=False)
    store = open_store(report.store).load().isel(gap=0, record=0)
    im, scale = store.motion_intensity, store.scale_factor
    np.testing.assert_allclose(im.isel(intensity=0), store.motion_pga.isel(intensity=0) / 9.81, rtol=1e-15)
    for j, level in enumerate(store.intensity.values):
        if synthetic == "each":
            np.testing.assert_allclose(scale.isel(intensity=j) * im.isel(intensity=j), level, rtol=1e-14)
        else:
            np.testing.assert_allclose(scale.isel(intensity=j), level / float(im.isel(intensity=j).mean()), rtol=1e-13)


def test_analytic_motions_cannot_be_scaled(tmp_path):
    motions = '\n[[motions]]\nname = "sine"\ntype = "harmonic"\namplitude = 1.0\nomega = 6.0\nduration = 2.0\ndt = 0.01\n'
    path = write_experiment(tmp_path, _experiment("gap = [0.01]", 'measure = "pga"\nlevels = [0.1]', records=motions), "sine.toml")
    with pytest.raises(ExperimentError, match=r"^motions\[0\]: a HarmonicMotion cannot be scaled"):
        resolve_motions(load_experiment(path))
