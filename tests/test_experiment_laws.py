"""Experiments over laws: variants that replace contacts' laws or add walls, the automatic solver, demand summaries."""

from __future__ import annotations

import copy

import numpy as np
import pytest

import stochpound
from stochpound.experiment import ExperimentError, load_experiment, open_store, run_experiment
from stochpound.experiment._grid import CASE
from tests.helpers import laws_pair_text, write_experiment


def test_variants_replace_the_contact_law_and_add_a_wall(laws_store):
    path, _ = laws_store
    experiment = load_experiment(path)
    structures = {(dict(c.labels)["law"], dict(c.labels)["moat"]): experiment.structure(c) for c in experiment.points(CASE)}
    by_law = {law: s for (law, moat), s in structures.items() if moat == "none"}
    kelvin, hertz = by_law["kelvin"]["contact"], by_law["hertz_damp"]["contact"]
    assert [c["gap"] for c in hertz] == [0.005, 0.005] and all("law" not in c for c in kelvin)
    for before, after in zip(kelvin, hertz):  # the law replaces the element; the flexible B2 keeps its contacts' ends and gap
        assert after["between"] == before["between"] and after["law"] == "hertz_damp" and after["restitution"] == 0.5
        assert after["stiffness"] == pytest.approx(2.75e9)
    assert all(s["wall"][0]["gap"] == 0.002 for (_, moat), s in structures.items() if moat == "near")
    assert all("wall" not in s for (_, moat), s in structures.items() if moat == "none")


def test_store_equals_direct_runs_with_the_automatic_solver_and_demands(laws_store):
    path, store = laws_store
    experiment = load_experiment(path)
    pounded: dict[str, int] = {}
    with open_store(store) as ds:
        assert ds.attrs["solver"] == "auto"
        for case in experiment.points(CASE):
            labels = dict(case.labels)
            scene_dict = copy.deepcopy(experiment.structure(case))
            scene_dict["motion"] = {"type": "harmonic", "amplitude": 3.0, "omega": 6.0, "duration": 3.0, "dt": 0.01}
            run = stochpound.simulate(stochpound.scene_from_dict(scene_dict), demands=True)
            assert run.attrs["solver"] == ("ivp" if labels["law"] == "hertz_damp" else "exact")
            cell = ds.sel({**{k: v for k, v in labels.items() if k in ds.dims}, "record": "pulse", "realization": 0, "building": "B1"})
            assert int(cell.impacts) == run.sizes["impact"]
            pounded[labels["law"]] = pounded.get(labels["law"], 0) + run.sizes["impact"]
            np.testing.assert_allclose(float(cell.peak_floor_acceleration), float(run.peak_total_acceleration.sel(building="B1").max()), rtol=1e-12)
            np.testing.assert_allclose(float(cell.peak_interstorey_drift), float(run.peak_storey_drift.sel(building="B1").max()), rtol=1e-12)
            np.testing.assert_allclose(float(cell.peak_base_shear), float(run.peak_base_shear.sel(building="B1")), rtol=1e-12)
            walls = int((run.impact_wall >= 0).sum()) if "impact_wall" in run else 0
            assert (walls > 0) == (labels["moat"] == "near")
            if labels["moat"] == "near":  # the scene has walls: the store keeps each case's largest penetration
                np.testing.assert_allclose(float(cell.peak_wall_penetration), float((run.peak_wall_closure - run.wall_gap).max()), rtol=1e-12)
                assert float(cell.peak_wall_penetration) > 0.0
            else:
                assert np.isnan(float(cell.peak_wall_penetration))
    assert pounded["kelvin"] > 0 and pounded["hertz_damp"] > 0


def test_bad_contact_overrides_name_the_field(tmp_path):
    text = laws_pair_text()
    for bad, message in (
        ('[variants.law.hertz_damp.contact]\nlaw = "hertz_damp"\nstiffnes = 1.0', "variants.law.hertz_damp.contact.stiffnes"),
        ('[[variants.law.hertz_damp.contact]]\nlaw = "hertz"\nstiffness = 1.0', "variants.law.hertz_damp.contact: a list must have one table per contact of the scene (2), got 1"),
    ):
        broken = text.replace('[variants.law.hertz_damp.contact]\nlaw = "hertz_damp"\nstiffness = 2.75e9\nrestitution = 0.5', bad)
        with pytest.raises(ExperimentError, match=message.replace("(", r"\(").replace(")", r"\)").replace(".", r"\.")):
            load_experiment(write_experiment(tmp_path, broken, "bad.toml"))
    with pytest.raises(ExperimentError, match=r"output\.demands: must be true or false"):
        load_experiment(write_experiment(tmp_path, text.replace("demands = true", 'demands = "yes"'), "bad.toml"))
    with pytest.raises(ExperimentError, match=r"solver\.method: must be one of auto, exact, ivp"):
        load_experiment(write_experiment(tmp_path, text + '\n[solver]\nmethod = "fast"\n', "bad.toml"))


def test_a_walled_store_from_before_the_wall_summary_asks_for_a_restart(tmp_path):
    """Cases computed without ``peak_wall_penetration`` (an earlier stochpound) are not silently kept: the store file and its
    parts each name the summary and --restart, which recomputes them."""
    import h5py

    text = laws_pair_text().replace('name = "laws"', 'name = "walled"')
    path = write_experiment(tmp_path, text, "walled.toml")
    report = run_experiment(load_experiment(path), workers=0, progress=False)
    with h5py.File(report.store, "a") as handle:  # the store file as an earlier version wrote it
        del handle["peak_wall_penetration"]
    with pytest.raises(ExperimentError, match="written by an earlier stochpound without peak_wall_penetration.*--restart"):
        run_experiment(load_experiment(path), workers=0, progress=False)
    for part in (tmp_path / "walled.nc.parts").glob("part-*.npz"):  # and its parts
        with np.load(part) as data:
            kept = {key: data[key] for key in data.files if not key.endswith("s:peak_wall_penetration")}
        np.savez(part, **kept)
    report.store.unlink()
    with pytest.raises(ExperimentError, match="peak_wall_penetration: the finished cases in the store's parts folder .* --restart"):
        run_experiment(load_experiment(path), workers=0, progress=False)
    restarted = run_experiment(load_experiment(path), workers=0, progress=False, restart=True)
    with open_store(restarted.store) as ds:
        assert float(ds["peak_wall_penetration"].sel(moat="near").max()) > 0.0
