"""Scenario ensembles in the stochastic experiments: [synthetic.<name>] type = "scenario_motions" (issue 43, item 7)."""

from __future__ import annotations

import numpy as np
import pytest

from stochpound import open_store, simulate
from stochpound.experiment._runner import load_experiment, run_experiment
from stochpound.model.scene_file import scene_from_dict
from stochpound.motions import (
    SYNTHETIC_TYPES, normal_motion, realization_rng, scenario_distribution, scenario_motions, site_model_provenance, site_motions,
)
from stochpound.report.sections._description import StoreDefinition, _scenario_parameters, grid_paragraph, motions_table
from stochpound.store import MotionSource, with_motion
from tests.helpers import SITE_SCENE, write_experiment

SCENARIO = {"magnitude": 6.8, "distance_km": 15.0, "vs30": 450.0, "mechanism": "reverse"}
WINDOW = {"duration": 12.0, "dt": 0.02}


def test_realization_i_is_motion_i_of_site_motions_whatever_the_batch() -> None:
    full = site_motions(**SCENARIO, n=9, seed=5, **WINDOW)
    batch = scenario_motions(4, **WINDOW, **SCENARIO, seed=5, start=3)
    assert list(batch.realization.values) == [3, 4, 5, 6]
    np.testing.assert_array_equal(batch.values, full.acceleration.values[3:7])  # bit for bit
    np.testing.assert_array_equal(batch.f_corner.values, full.f_corner.values[3:7])
    for i in (3, 6):  # one at a time (another worker, another batch): the same bytes
        np.testing.assert_array_equal(scenario_motions(1, **WINDOW, **SCENARIO, seed=5, start=i).values[0], full.acceleration.values[i])
    assert batch.attrs["model_provenance"] == site_model_provenance() and batch.attrs["seed"] == 5


def test_the_scenario_kind_joins_the_map_from_standard_normals() -> None:
    """Issue 46: every synthetic kind is a = f(u); the seeded realization i is f(u_i), u_i its generator's first n normals."""
    assert "scenario_motions" in SYNTHETIC_TYPES
    motion = normal_motion({"type": "scenario_motions", **SCENARIO, **WINDOW, "seed": 5, "count": 3})
    assert motion.dimension == 7 + 12 + 601 and motion.dt == 0.02  # 7 parameters, 12 spectral-shape gains, 601 samples
    u = realization_rng(5, 2).standard_normal(motion.dimension)
    np.testing.assert_array_equal(motion(u), scenario_motions(1, **WINDOW, **SCENARIO, seed=5, start=2).values[0])
    with pytest.raises(ValueError, match=r"^motion\.vs30: must be within 200-1100 \(the site-motion model's calibrated range\), got 150\.0$"):
        normal_motion({"type": "scenario_motions", **SCENARIO, **WINDOW, "vs30": 150.0})


def _text(table: str) -> str:
    return f'[experiment]\nname = "scenario"\n{SITE_SCENE}\n[grid]\ngap = [0.005, "inf"]\n[synthetic.quake]\n{table}\n[solver]\nmethod = "exact"\n'


TABLE = 'type = "scenario_motions"\nmagnitude = 6.8\ndistance_km = 15.0\nvs30 = 450.0\nmechanism = "reverse"\ncount = 3\nseed = 5\ndt = 0.02\n'


def test_a_scenario_ensemble_runs_and_its_store_regenerates_its_motions(tmp_path) -> None:
    experiment = load_experiment(write_experiment(tmp_path, _text(TABLE + "start = 1\n"), "scenario.toml"))
    source = experiment.motions["quake"]
    window = site_motions(**SCENARIO, n=4, seed=5, dt=0.02)  # the window site_motions chooses for the 4 motions 0..3
    assert source.motion == {"type": "scenario_motions", **SCENARIO, "seed": 5, "dt": 0.02, "duration": float(window.time.values[-1]),
                             "model": "hazard_compatible", "calibration": site_model_provenance()}
    assert (source.start, source.count) == (1, 3)
    report = run_experiment(experiment, workers=0, progress=False)
    store = open_store(report.store).load()
    assert report.complete and list(store.realization.values) == [1, 2, 3]
    for i in (1, 3):
        regenerated = store.pound.scene(gap=0.005, record="quake", realization=i).motion
        np.testing.assert_array_equal(regenerated.values, window.acceleration.values[i])
    row = motions_table([StoreDefinition("scenario", store)]).frame.iloc[0]  # the report's table of ground motions, from the store
    assert row["definition"].startswith("Site-based stochastic motions of the scenario M 6.8, R_rup 15 km, Vs30 450 m/s, reverse")
    assert row["realizations"] == "3 (indices 1–3), seed 5" and row["step, duration"] == f"0.02 s, {source.motion['duration']:g} s"
    # what ran is that motion: the run's peak displacement is the one simulate gives under it
    scene = scene_from_dict(with_motion(experiment.structure(experiment.points("case")[0]), experiment.motion_table("quake", 2)))
    direct = simulate(scene, method="exact")
    assert float(store.peak_total_displacement.sel(gap=0.005, realization=2, building="B1").max()) == pytest.approx(
        float(np.abs(direct.total_displacement.sel(building="B1")).max()), rel=1e-9)


@pytest.mark.parametrize(("edit", "message"), [
    (("magnitude = 6.8", "magnitude = 9.0"), r"synthetic\.quake\.magnitude: must be within 5\.5-8 \(the site-motion model's calibrated range\), got 9\.0"),
    (("distance_km = 15.0", "distance_km = 150.0"), r"synthetic\.quake\.distance_km: must be within 5-100 \(the site-motion model's calibrated range\)"),
    (('mechanism = "reverse"', 'mechanism = "oblique"'), r"synthetic\.quake\.mechanism: must be one of strike_slip, reverse, normal, got 'oblique'"),
    (("vs30 = 450.0\n", ""), r"synthetic\.quake\.vs30: missing \(the scenario: magnitude, distance_km, vs30, mechanism\)"),
    (("dt = 0.02", "dt = 0.05"), r"synthetic\.quake\.dt: must be .*0\.02"),
    (("dt = 0.02", "dt = 0.02\nduration = 0.1"), r"synthetic\.quake\.duration: must be within 0\.2-600 s, got 0\.1"),
    (("seed = 5", "seed = 5\nomega_g = 15.0"), r"synthetic\.quake\.omega_g: unknown field"),
    (("seed = 5", 'seed = 5\nmodel = "boore"'), r"synthetic\.quake\.model: must be one of hazard_compatible, rezaeian_2010, got 'boore'"),
    (("seed = 5", 'seed = 5\ncalibration = "old"'), r"synthetic\.quake\.calibration: 'old' is not the calibration of model 'hazard_compatible' here"),
    (("seed = 5\n", ""), r"synthetic\.quake\.seed: missing"),
])
def test_a_scenario_table_out_of_range_is_one_line_naming_the_field(tmp_path, edit, message) -> None:
    with pytest.raises(ValueError, match=message) as caught:
        load_experiment(write_experiment(tmp_path, _text(TABLE.replace(*edit)), "scenario.toml"))
    assert "\n" not in str(caught.value)


def test_the_motions_table_says_what_the_motions_are() -> None:
    """Read from the motions as run: the corner they have (fixed in this calibration, not drawn), their intensity beside the
    NGA-West2 average's, and where the model is not valid (it said "high-pass corner drawn" and gave no intensity)."""
    entry = {"type": "scenario_motions", **SCENARIO, "seed": 5, "dt": 0.02, "duration": 30.0, "model": "hazard_compatible",
             "calibration": site_model_provenance()}
    source = MotionSource("quake", "synthetic", "synthetic.quake", entry, start=2, count=6)
    text, grid = _scenario_parameters(source)
    assert text.startswith("Site-based stochastic motions of the scenario M 6.8, R_rup 15 km, Vs30 450 m/s, reverse (Rezaeian & Der Kiureghian 2010, "
                           f"calibrated to the NGA-West2 models: {site_model_provenance()})")
    ran = site_motions(**SCENARIO, n=8, seed=5, dt=0.02, duration=30.0).isel(realization=slice(2, 8))  # the 6 motions, drawn here
    corners = np.unique(ran.f_corner.values)
    assert corners.size == 1 and f"its corner fixed at {corners[0]:.3g} Hz" in text and "corner drawn" not in text
    assert "random gains at 12 periods (0.05–5 s) are set so that the motions' median and σ of ln PSA follow" in text
    pga = np.log(np.abs(ran.acceleration.values).max(axis=1) / 9.81)  # g as the calibration's check takes it
    median, sigma = scenario_distribution("pga", magnitude=6.8, distance_km=15.0, vs30=450.0, mechanism="reverse")
    assert (f"Intensity, the median over the 6 motions as run: PGA {np.exp(np.median(pga)):.3g} g, σ_ln {np.std(pga, ddof=1):.2f} "
            f"(NGA-West2 average {median:.3g} g, σ_ln {sigma:.2f}); PSA(1 s) ") in text
    assert "Not valid for: near-fault velocity pulses, directivity, basin effects" in text
    assert grid == {"dt": 0.02, "duration": 30.0}


def test_a_scenario_ensembles_table_has_no_psd_convention_and_counts_its_realizations(tmp_path) -> None:
    """The PSD convention belongs to Kanai–Tajimi-type ensembles, and one ensemble of 3 motions is not "1 motion(s)"."""
    experiment = load_experiment(write_experiment(tmp_path, _text(TABLE), "scenario.toml"))
    store = open_store(run_experiment(experiment, workers=0, progress=False).store).load()
    definition = StoreDefinition("scenario", store)
    assert "PSD" not in motions_table([definition]).note
    assert "under 1 synthetic ensemble of 3 realizations, listed in the Table of motions" in grid_paragraph(definition).text
