"""Experiments over laws: variants that replace contacts' laws or add walls, the automatic solver, demand summaries."""

from __future__ import annotations

import copy
import re

import numpy as np
import pytest

import stochpound
from stochpound.experiment import ExperimentError, load_experiment, open_store, run_experiment
from stochpound.store import CASE
from stochpound.model import laws
from stochpound.studies.agarwal2004 import reference_building
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


# ---------------------------------------------------------------- grid axes against every law's parameters

CONTACT_TABLES = {
    **{name: {"law": name, "stiffness": 2.0e9, **({"restitution": 0.5} if "restitution" in law.keys else {})}
       for name, law in laws.CONTACT_LAWS.items() if law.stiffness_unit != "N/m"},
    "kelvin": {"law": "kelvin", "stiffness": 8.0e7, "restitution": 0.5},
    "kelvin_damping": {"law": "kelvin", "stiffness": 8.0e7, "damping": 2.0e5, "tensile": False},
}
"""One impact-element table per contact law (Kelvin–Voigt with a restitution and with a given dashpot)."""
BASES = {
    "coulomb": {"mu": 0.1},
    "coulomb_static": {"mu": 0.1, "mu_static": 0.15},
    "velocity": {"mu": {"slow": 0.05, "fast": 0.1, "rate": 20.0}},
    "velocity_static": {"mu": {"slow": 0.05, "fast": 0.1, "rate": 20.0}, "mu_static": 0.08},
}
"""One base per friction law, with and without a static coefficient of its own."""
AXES = """
[variants.neighbour.same]
[variants.neighbour.heavy.building.B1]
mass_factor = 1.5
[variants.neighbour.heavy.building.B2]
mass_factor = 2.0
[variants.neighbour.stiff.building.B2]
stiffness = [3.0e7, 2.0e7]

[grid]
gap = [0.01, 0.03]
gap_wall = { values = [0.05, inf], walls = [0] }
mu = { values = [0.06, 0.2, inf], buildings = ["B1"] }

[[motions]]
name = "pulse"
type = "harmonic"
amplitude = 3.0
omega = 6.0
duration = 1.0
dt = 0.01
"""


def _toml(value) -> str:
    """``value`` as a TOML value (inline tables, arrays, numbers with inf, strings, booleans)."""
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{key} = {_toml(item)}" for key, item in value.items()) + " }"
    if isinstance(value, list):
        return "[" + ", ".join(_toml(item) for item in value) + "]"
    if isinstance(value, bool):
        return str(value).lower()
    return f'"{value}"' if isinstance(value, str) else repr(value)


def _axes_experiment(folder, contact: dict, base: dict, mu_values: str = "[0.06, 0.2, inf]"):
    """B1 on a sliding base with ``base``'s friction, B2 fixed, one contact and a wall beside B1 with ``contact``'s law."""
    b1 = reference_building("B1", 1.0, base={"mass": 13134.0, **base})
    b2 = reference_building("B2", 1.0)
    scene = {"building": [b1, b2],
             "contact": [{"between": [["B1", 1], ["B2", 1]], "gap": 0.02, **contact}],
             "wall": [{"building": "B1", "side": "left", "level": 1, "gap": 0.1, **contact}]}
    lines = ['[experiment]\nname = "axes"\nstudied = "B1"\n\n[scene]\ng = 9.81']
    for kind, tables in scene.items():
        lines += [f"[[scene.{kind}]]\n" + "\n".join(f"{key} = {_toml(value)}" for key, value in table.items()) for table in tables]
    text = "\n\n".join(lines) + AXES.replace("[0.06, 0.2, inf]", mu_values)
    return load_experiment(write_experiment(folder, text, "axes.toml"))


def _element_invariants(element, mass: float) -> tuple:
    """What a grid axis must keep of an impact element whose collision has effective mass ``mass`` (kg): law, k/m_eff, c/m_eff, e, tensile."""
    return element.law, element.stiffness / mass, element.damping / mass, element.restitution, element.tensile


def _assert_kept(after: tuple, before: tuple) -> None:
    """Each number of ``after`` equals ``before``'s to 1e-12 (round-off of the rescaling), everything else exactly."""
    for new, old in zip(after, before, strict=True):
        assert new == (pytest.approx(old, rel=1e-12) if isinstance(old, float) else old), (after, before)


def _friction_invariants(base) -> tuple:
    """What a μ axis must keep of a base: its law, the ratios of its coefficients to the one the axis sets, its rate."""
    reference = base.mu if base.mu_fast is None else base.mu_fast
    return base.friction_law, base.mu / reference, base.mu_static / reference, base.mu_rate


@pytest.mark.parametrize("base_name", list(BASES))
@pytest.mark.parametrize("contact_name", list(CONTACT_TABLES))
def test_every_grid_axis_keeps_each_laws_parameters(tmp_path, contact_name, base_name):
    """Gap axes (contacts and walls), a μ axis and variant axes (mass factors, another field) change only what they own.

    The gap axes set gaps; a mass factor keeps every element's law, k/m_eff,
    c/m_eff, restitution and tensility (and the friction coefficients); the μ
    axis sets the coefficient its law names (Coulomb ``mu``, velocity-dependent
    ``fast``), keeps the law, the other coefficients' ratios to it and the rate,
    and inf removes the base. Checked on the scene every grid point runs.
    """
    experiment = _axes_experiment(tmp_path, CONTACT_TABLES[contact_name], BASES[base_name])
    base_scene = stochpound.scene_from_dict({**experiment.definition.scene, "motion": {"type": "constant", "acceleration": 0.0, "duration": 1.0, "dt": 1.0}})
    before_base = base_scene.buildings[0].base

    def contact_mass(scene):  # the contact joins the first floors of B1 and B2
        m1, m2 = scene.buildings[0].mass[0], scene.buildings[1].mass[0]
        return m1 * m2 / (m1 + m2)

    points = experiment.points(CASE)
    assert len(points) == 3 * 2 * 2 * 3
    for point in points:
        labels = dict(point.labels)
        scene = stochpound.scene_from_dict(experiment.structure(point))
        contact, wall, base = scene.contacts[0], scene.walls[0], scene.buildings[0].base
        assert (contact.gap, wall.gap) == (labels["gap"], labels["gap_wall"])
        _assert_kept(_element_invariants(contact, contact_mass(scene)), _element_invariants(base_scene.contacts[0], contact_mass(base_scene)))
        _assert_kept(_element_invariants(wall, scene.buildings[0].mass[0]), _element_invariants(base_scene.walls[0], base_scene.buildings[0].mass[0]))
        if np.isinf(labels["mu"]):
            assert base is None
            continue
        _assert_kept(_friction_invariants(base), _friction_invariants(before_base))
        assert (base.mu if base.mu_fast is None else base.mu_fast) == labels["mu"]


@pytest.mark.parametrize("base, field", [
    (BASES["velocity"], "building[0].base.mu.fast: a μ axis sets fast, which must be > 0 for velocity-dependent friction; got 0"),
    ({"mu": 0.0, "mu_static": 0.05}, "building[0].base.mu_static: a μ axis keeps mu_static/mu, which mu = 0 leaves undefined"),
], ids=["velocity_mu_0", "coulomb_no_ratio"])
def test_a_mu_axis_that_a_friction_law_cannot_take_is_refused_naming_the_field(tmp_path, base, field):
    with pytest.raises(ExperimentError, match=re.escape(field)):
        _axes_experiment(tmp_path, CONTACT_TABLES["kelvin"], base, mu_values="[0.0, 0.1]")


def test_a_mu_axis_scales_velocity_dependent_friction_as_the_docs_say(tmp_path):
    """docs/experiments.md: μ sets ``fast``; ``slow`` and ``mu_static`` keep their ratios to it, ``rate`` is kept; inf is a fixed base.

    Read from the store the run wrote (what each grid point ran), not from the scene edit.
    """
    experiment = _axes_experiment(tmp_path, CONTACT_TABLES["kelvin"], BASES["velocity_static"], mu_values="[0.06, inf]")
    report = run_experiment(experiment, workers=0, progress=False)
    assert report.complete and not report.failed
    with open_store(report.store) as store:
        names = ["base_mu", "base_mu_static", "base_mu_fast", "base_mu_rate"]
        ran = store[names].sel(building="B1", neighbour="same", gap=0.01, gap_wall=0.05)
        sliding = {name: float(ran[name].sel(mu=0.06)) for name in names}
        assert sliding == pytest.approx({"base_mu": 0.03, "base_mu_static": 0.048, "base_mu_fast": 0.06, "base_mu_rate": 20.0}, rel=1e-12)
        assert np.isinf(float(ran["base_mu"].sel(mu=np.inf))) and np.isnan(float(ran["base_mu_fast"].sel(mu=np.inf)))
