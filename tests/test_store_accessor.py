"""The store layer's door, ``ds.pound``, on a real store; and the hazard outside the runs' identity (#35).

A fixed-base pair with a gap axis (2 cm and contact-free) and intensity
stripes of PGA, one record, its hazard a CSV file. The accessor's
definition, intensity and hazard are checked against the experiment file and
the hazard file; a case's scene against the store by running it again; then
the hazard file is edited and the experiment run again: its runs are kept,
the new curve is recorded.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping
import os
import re
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
import xarray as xr

import stochpound
from stochpound.experiment import ExperimentError, load_experiment, run_experiment
from stochpound.motions import Measure
from stochpound.store import Definition, Hazard, Intensity, canonical_json, definition_sha256, open_store, read_definition
from tests.helpers import write_experiment

EXPERIMENT = """
[experiment]
name = "door"
studied = "B1"

[scene]
g = 9.81

[[scene.building]]
name = "B1"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping_ratio = 0.02

[[scene.building]]
name = "B2"
mass = [13134.0, 8756.0]
stiffness = [24516800.0, 17512000.0]
damping_ratio = 0.02

[[scene.contact]]
between = [["B1", 1], ["B2", 1]]
gap = 0.02
stiffness = 42747262.6
restitution = 0.5

[grid]
gap = [0.005, inf]

[[records]]
name = "el_centro"
record = "el_centro_1940_study"
duration = 3.0

[intensity]
measure = "pga"
levels = [0.2, 0.6]
units = "g"

[hazard]
file = "site.csv"
"""
HAZARD = "# Site: a made-up curve for the test\n# Measure: PGA, in g\nim, rate\n0.05, 0.02\n0.1, 0.008\n0.3, 0.001\n0.6, 0.0002\n1.0, 0.00005\n"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The experiment run once: (folder, experiment file, store path)."""
    folder = tmp_path_factory.mktemp("door")
    (folder / "site.csv").write_text(HAZARD)
    path = write_experiment(folder, EXPERIMENT, "door.toml")
    report = run_experiment(load_experiment(path), workers=0, progress=False)
    assert report.complete
    return folder, path, report.store


@pytest.fixture
def ds(run):
    with open_store(run[2]) as store:
        yield store


def test_the_definition_is_typed_and_parsed_once(ds):
    definition = ds.pound.definition
    assert isinstance(definition, Definition)
    assert definition.to_dict() == read_definition(ds.attrs["definition"]).to_dict()
    assert ds.pound.definition is definition and ds.isel(record=0).pound.definition is definition  # one parse per stored text
    assert definition.sha256 == ds.pound.sha256 == ds.attrs["definition_sha256"]
    assert [axis.name for axis in definition.gaps] == ["gap"] and definition.gaps[0].values == (0.005, math.inf)


def test_intensity_and_hazard_are_typed(ds, run):
    intensity = ds.pound.intensity
    assert isinstance(intensity, Intensity)
    assert (intensity.measure, intensity.units, intensity.levels, intensity.ran) == (Measure("pga"), "g", (0.2, 0.6), "stripes")
    assert intensity.measure.kind == "pga" and intensity.description == "PGA" and not isinstance(intensity, Mapping)  # a record, not a dict
    assert intensity.entry()["levels"] == [0.2, 0.6] and ds.pound.definition.to_dict()["intensity"] == intensity.entry()
    hazard = ds.pound.hazard
    assert isinstance(hazard, Hazard)
    assert (hazard.source, hazard.file, hazard.units) == ("file", "site.csv", "g")
    assert hazard.file_sha256 == hashlib.sha256((run[0] / "site.csv").read_bytes()).hexdigest()
    assert hazard.im == (0.05, 0.1, 0.3, 0.6, 1.0) and hazard.rate == (0.02, 0.008, 0.001, 0.0002, 0.00005)
    assert hazard.provenance == "Site: a made-up curve for the test\nMeasure: PGA, in g"
    assert hazard.measure == intensity.measure and not isinstance(hazard, Mapping)


def test_gap_axes_and_selections(ds):
    assert ds.pound.gap_dims == ds.pound.contact_gap_dims == ["gap"] and ds.pound.wall_gap_dims == []
    assert ds.pound.has_contact_free and not ds.pound.has_wall_free and not ds.pound.has_fixed_base_twins
    free = ds.pound.contact_free()
    assert "gap" not in free.dims
    xr.testing.assert_identical(free["peak_contact_closure"], ds["peak_contact_closure"].sel(gap=np.inf, drop=True))


def test_a_case_names_its_motion(ds):
    from stochpound.store import Case

    cases = ds.pound.grid.cases
    assert cases and {case.record for case in cases} == {"el_centro"}
    assert all(case.realization == int(dict(case.labels)["realization"]) for case in cases)
    assert Case("0" * 16, "case", (("record", "r1"),), (0,)).realization is None


@pytest.mark.parametrize("gap", [0.005, math.inf])
def test_a_case_scene_runs_what_the_store_holds(ds, gap):
    """The scene of a case, run again on its own, gives the store's numbers (scaled to the stripe's level)."""
    labels = {"gap": gap, "intensity": 0.6, "record": "el_centro"}
    scene = ds.pound.scene(**labels)
    assert scene.contacts[0].gap == gap
    factor = float(ds["scale_factor"].sel(gap=gap, intensity=0.6, record="el_centro").squeeze())
    assert factor != pytest.approx(1.0) and scene.motion.description.endswith(f"x {factor:g}, first 3 s")
    again = stochpound.simulate(scene)
    stored = ds.sel(gap=gap, intensity=0.6, record="el_centro").squeeze().compute()
    assert int(stored["impacts"]) == again.sizes["impact"] and (again.sizes["impact"] == 0) == (gap == math.inf)
    peak = float(np.abs(again["total_displacement"].sel(building="B1")).max())
    assert float(stored["peak_total_displacement"].sel(building="B1")) == pytest.approx(peak, rel=1e-9)
    assert float(stored["response_std"]) == pytest.approx(float(again["total_displacement"].sel(building="B1").isel(floor=-1).std()), rel=1e-9)


def test_impacts_of_a_case(ds):
    impacts = ds.pound.impacts(gap=0.005, intensity=0.6, record="el_centro")
    assert impacts.sizes["impact"] == int(ds["impacts"].sel(gap=0.005, intensity=0.6, record="el_centro").squeeze()) > 0
    assert set(impacts["impact_case_id"].values) == {ds.pound.case_id(gap=0.005, intensity=0.6, record="el_centro")}
    assert ds.pound.impacts(gap=np.inf).sizes["impact"] == 0


def test_the_hazard_is_not_part_of_the_runs_identity(tmp_path):
    """Editing the hazard keeps the store's runs (no --restart) and records the new curve; another intensity is another experiment."""
    (tmp_path / "site.csv").write_text(HAZARD)
    path = write_experiment(tmp_path, EXPERIMENT, "door.toml")
    first = load_experiment(path)
    store = run_experiment(first, workers=0, progress=False).store
    with open_store(store) as ds:
        before = ds["peak_contact_closure"].load()
    (tmp_path / "site.csv").write_text(HAZARD.replace("0.001", "0.002"))
    edited = load_experiment(path)
    assert edited.sha256 == first.sha256 and edited.definition.hazard.rate != first.definition.hazard.rate
    said = []
    report = run_experiment(edited, workers=0, progress=False, say=said.append)
    assert report.nothing_to_run and report.done_now == 0
    assert any("the hazard changed" in line for line in said)
    with open_store(store) as ds:
        assert ds.pound.hazard.file_sha256 == hashlib.sha256((tmp_path / "site.csv").read_bytes()).hexdigest()
        assert ds.pound.hazard.rate[2] == 0.002
        xr.testing.assert_identical(ds["peak_contact_closure"].load(), before)
    # a store written while the hazard was hashed with the runs (its attribute the full definition's sha256) is recognised
    with h5py.File(store, "r+") as handle:
        definition = handle.attrs["definition"]
        full = hashlib.sha256(str(definition.decode() if isinstance(definition, bytes) else definition).encode()).hexdigest()
        handle.attrs["definition_sha256"] = full
    assert full != edited.sha256
    assert run_experiment(edited, workers=0, progress=False).nothing_to_run
    write_experiment(tmp_path, EXPERIMENT.replace("levels = [0.2, 0.6]", "levels = [0.2, 0.7]"), "door.toml")
    with pytest.raises(ExperimentError, match="different experiment definition"):
        run_experiment(load_experiment(path), workers=0, progress=False)


def test_identity_leaves_out_the_hazard_only():
    definition = {"format": 1, "name": "x", "gaps": [{"values": [math.inf]}]}
    plain = hashlib.sha256(canonical_json(definition).encode()).hexdigest()
    assert definition_sha256(definition) == plain  # without a hazard: the sha256 of the canonical JSON, as always
    assert definition_sha256({**definition, "hazard": {"source": "bundled"}}) == plain
    assert definition_sha256({**definition, "intensity": {"levels": [1.0]}}) != plain


QUICK_PAIR = """
[experiment]
name = "quick_pair"
studied = "B1"

[scene]
g = 9.814

[[scene.building]]
name = "B1"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping = [23634.2, 16881.57]
base = { mass = 13134.0, mu = 0.2 }

[[scene.building]]
name = "B2"
mass = [26268.0, 17512.0]
stiffness = [24516800.0, 17512000.0]
damping_ratio = 0.01

[[scene.contact]]
between = [["B1", 1], ["B2", 1]]
gap = 0.02
stiffness = 42747262.6
restitution = 0.5

[variants.neighbour.stiff.building.B2]
mass_factor = 0.5

[grid]
gap = [0.02]
mu = { values = [0.2, inf], buildings = ["B1"] }

[[records]]
name = "el_centro"
record = "el_centro_1940_study"
duration = 4.0

[output]
impacts = true

[solver]
method = "exact"
"""
"""The quick start's pair, cut down to the case the documentation reads (neighbour, gap, μ and record as docs/experiments.md names them)."""


def documented_example() -> str:
    """The code of docs/experiments.md's "Reading a store" (its first Python block there), as a reader runs it."""
    text = (Path(__file__).parents[1] / "docs" / "experiments.md").read_text()
    section = text[text.index("## Reading a store"):]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_the_documented_store_example_runs_in_a_fresh_interpreter(tmp_path):
    """``import stochpound; stochpound.open_store(p).pound.scene(...)`` with nothing else imported first: the grid is the store layer's.

    The documented block runs as written (on a store made here, of the
    documented case); the scene it returns, run again, gives the store's numbers.
    """
    store = run_experiment(load_experiment(write_experiment(tmp_path, QUICK_PAIR, "quick_pair.toml")), workers=0, progress=False).store
    code = documented_example().replace("experiments/quickstart.nc", str(store))
    code = re.sub(r"^ds\.pound\.scene\(", "scene = ds.pound.scene(", code, count=1, flags=re.M)
    assert "scene = ds.pound.scene(" in code and code.startswith("import stochpound\n")
    code += (
        "import json, sys\n"
        "run = stochpound.simulate(scene)\n"
        "print(json.dumps({'peak': float(abs(run['total_displacement'].sel(building='B1')).max()), 'impacts': int(run.sizes['impact']),"
        " 'gap': scene.contacts[0].gap, 'experiment_imported': 'stochpound.experiment' in sys.modules}))\n"
    )
    root = str(Path(stochpound.__file__).parents[1])  # the package under test, and nothing of the test's process
    environment = {**os.environ, "PYTHONPATH": os.pathsep.join([root, *filter(None, [os.environ.get("PYTHONPATH")])])}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, cwd=tmp_path, env=environment)
    assert done.returncode == 0, done.stderr[-2000:]
    said = json.loads(done.stdout.strip().splitlines()[-1])
    with open_store(store) as ds:
        case = ds.sel(neighbour="stiff", gap=0.02, mu=0.2, record="el_centro", realization=0).compute()
    assert said["gap"] == 0.02 and said["impacts"] == int(case["impacts"])
    assert said["peak"] == pytest.approx(float(case["peak_total_displacement"].sel(building="B1")), rel=1e-9)
    assert not said["experiment_imported"], "reading a store needs nothing above the store layer"
