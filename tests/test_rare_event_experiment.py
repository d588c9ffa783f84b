"""Rare-event experiments (issue 46, item 3): the [rare_event] table, its resumable store, bit for bit whatever the workers."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from stochpound._errors import ExperimentError
from stochpound.analysis import subset_simulation
from stochpound.experiment import (
    is_rare_event_file, is_rare_event_store, load_rare_event, open_rare_event_store, rare_event_results, rare_event_sampler, run_rare_event,
)
from stochpound.experiment._rare_event_run import RUNS_PER_BATCH

FILE = """
[experiment]
name = "pair_rare"

[scene]
bundled = "elastic_pair"

[scene.building.B2]
mass_factor = 2.0

[synthetic.wn]
type = "white_noise"
S0 = 0.01
duration = 2.0
dt = 0.02

[rare_event]
method = "subset"
response = "closure"
contact = 1
target_probability = 1e-3
samples_per_level = {samples}
p0 = 0.1
seed = 3
"""


def _file(folder: Path, samples: int = 20, **edits: str) -> Path:
    text = FILE.format(samples=samples)
    for old, new in edits.items():
        text = text.replace(old, new)
    path = folder / "pair.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(("old", "new", "message"), [
    ('method = "subset"', 'method = "line"', r"rare_event.method: must be one of subset, got 'line'"),
    ("target_probability = 1e-3", "target_probability = 0.5", r"rare_event.target_probability: must be <= 0.1, got 0.5"),
    ("p0 = 0.1", "p0 = 0.7", r"rare_event.p0: must be <= 0.5, got 0.7"),
    ("seed = 3", "seed = -1", r"rare_event.seed: must be an integer in \[0, "),
    ("contact = 1", "contact = 2", r"rare_event.contact: must be an integer in \[0, 1\], got 2"),
    ('response = "closure"', 'response = "speed"', "rare_event.response: must be one of closure, peak_storey_drift, base_displacement, impact_force, max_closure, limit_state"),
    ('response = "closure"\ncontact = 1', 'response = "base_displacement"\nbuilding = "B1"', "rare_event.building: 'B1' has a fixed base"),
    ('response = "closure"\ncontact = 1', 'response = "peak_storey_drift"\nbuilding = "B1"\nfloor = 3', r"rare_event.floor: must be an integer in \[1, 2\], got 3"),
    ("p0 = 0.1", "p0 = 0.1\nfloor = 1", "rare_event.floor: not used by response = 'closure'"),
    ("S0 = 0.01", "S9 = 0.01", "synthetic.wn.S9: unknown field"),
    ("p0 = 0.1", 'p0 = 0.1\nproposal = "gibbs"', "rare_event.proposal: must be one of mma, acs, got 'gibbs'"),
])
def test_bad_fields_are_named_in_one_line(tmp_path, old, new, message):
    path = _file(tmp_path, **{old: new})
    assert is_rare_event_file(path)
    with pytest.raises(ExperimentError, match=message) as error:
        load_rare_event(path)
    assert "\n" not in str(error.value)


def test_samples_per_level_must_split_into_chains(tmp_path):
    with pytest.raises(ExperimentError, match=r"rare_event.samples_per_level: p0 × samples_per_level must be an integer that divides it"):
        load_rare_event(_file(tmp_path, samples=25))


def test_the_table_is_typed_and_the_store_holds_the_levels(tmp_path):
    definition = load_rare_event(_file(tmp_path))
    assert definition.table.response == "closure" and definition.table.samples_per_level == 20 and definition.motion["type"] == "white_noise"
    report = run_rare_event(definition, tmp_path / "a.nc")
    assert report.complete and report.levels == 3 and report.runs == 20 + 2 * 2 * 9
    assert is_rare_event_store(tmp_path / "a.nc") and not is_rare_event_store(tmp_path / "pair.toml")
    store = open_rare_event_store(tmp_path / "a.nc")
    assert store.attrs["runs"] == report.runs and store.attrs["complete"] == 1
    assert list(store["level_runs"].values) == [20, 18, 18]
    assert np.isneginf(store["level_threshold"].values[0]) and np.all(np.diff(store["level_threshold"].values) > 0)
    results = rare_event_results(store)
    # the levels' thresholds have the estimated probabilities p0 and p0²; the curve reaches the target
    assert 0.0 < float(results.curve.probability.min()) <= 1e-3 * (1 + 1e-9)
    assert np.isfinite(results.separations["value"][0]) and np.isnan(results.separations["value"][1])


def test_an_interrupted_run_resumes_at_the_last_finished_batch(tmp_path):
    definition = load_rare_event(_file(tmp_path, samples=200))
    whole = run_rare_event(definition, tmp_path / "whole.nc")
    first = run_rare_event(definition, tmp_path / "split.nc", stop_after=3)
    assert first.interrupted and not first.complete and first.batches_now == 3
    again = run_rare_event(definition, tmp_path / "split.nc")
    per_level = [2] + [-(-20 // (RUNS_PER_BATCH // 10))] * (whole.levels - 1)
    assert first.batches_now + again.batches_now == sum(per_level)  # nothing redone
    assert again.runs == whole.runs
    assert (tmp_path / "whole.nc").read_bytes() == (tmp_path / "split.nc").read_bytes()


def test_adaptive_conditional_sampling_resumes_to_the_run_made_in_one_process(tmp_path):
    """With ``proposal = "acs"`` a level's adaptation groups run one after the other (groups of one of the 10 chains,
    one batch each): a run stopped inside level 1 resumes, its λ rebuilt from the groups' batch files, to the store of an
    uninterrupted run, and its levels are subset_simulation's in one process (the same thresholds, runs and λ). Reading
    the table warns that aCS is not certified on a scene's responses (its reported CoV too small on peaks over time)."""
    with pytest.warns(UserWarning, match="adaptive conditional sampling is not certified on a run's peaks over time"):
        definition = load_rare_event(_file(tmp_path, samples=100, **{"p0 = 0.1": 'p0 = 0.1\nproposal = "acs"'}))
    assert definition.table.proposal == "acs" and definition.table.to_dict()["proposal"] == "acs"
    run_rare_event(definition, tmp_path / "whole.nc")
    first = run_rare_event(definition, tmp_path / "split.nc", stop_after=6)
    again = run_rare_event(definition, tmp_path / "split.nc")
    assert (tmp_path / "whole.nc").read_bytes() == (tmp_path / "split.nc").read_bytes()
    store = open_rare_event_store(tmp_path / "whole.nc")
    # level 0: one batch; then one group (one batch) a chain, 10 chains a level or a few more where the threshold ties
    assert first.batches_now + again.batches_now == 1 + int(store["level_chains"].values[1:].sum())
    sampler = rare_event_sampler(definition)
    alone = subset_simulation(sampler.function, target_probability=1e-3, samples_per_level=100, p0=0.1, seed=3, dimension=sampler.dimension,
                              proposal="acs")
    assert np.array_equal(alone.attrs["level_thresholds"], store["level_threshold"].values[1:]) and alone.attrs["runs"] == store.attrs["runs"]
    assert np.array_equal(alone.attrs["acceptance"], store["level_acceptance"].values[1:])
    assert np.array_equal(alone.threshold.values, store.threshold.values) and np.array_equal(alone.cov.values, store["cov"].values)  # the same genealogy
    assert store.attrs["method"].startswith("subset simulation (Au & Beck 2001), adaptive conditional sampling")
    from stochpound.report.sections._rare_events import _conditions

    assert "Au & Beck 2001; adaptive conditional sampling" in _conditions(rare_event_results(store))


def test_the_default_proposal_keeps_the_definition_of_earlier_stores(tmp_path):
    definition = load_rare_event(_file(tmp_path))
    assert definition.table.proposal == "mma" and "proposal" not in definition.table.to_dict()


def test_a_killed_command_resumes_to_the_same_store(tmp_path):
    """``experiment run`` killed (SIGKILL) once its first batch is written, then run again: the store of an uninterrupted run, bit for bit."""
    environment = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parent.parent)}
    command = [sys.executable, "-m", "stochpound", "experiment", "run", "pair.toml", "--store", "pair.nc", "--quiet"]
    for name in ("killed", "whole"):
        (tmp_path / name).mkdir()
        _file(tmp_path / name, samples=400)
    subprocess.run(command, cwd=tmp_path / "whole", env=environment, check=True, capture_output=True)
    process = subprocess.Popen(command, cwd=tmp_path / "killed", env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    parts = tmp_path / "killed" / "pair.nc.parts"
    deadline = time.monotonic() + 120
    while not list(parts.glob("batch-*.npz")) and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    process.send_signal(signal.SIGKILL)
    process.wait()
    assert list(parts.glob("*.npz")) and not (tmp_path / "killed" / "pair.nc").exists()
    resumed = subprocess.run(command, cwd=tmp_path / "killed", env=environment, check=True, capture_output=True, text=True)
    assert "0 of the level under way before" not in resumed.stdout
    assert (tmp_path / "killed" / "pair.nc").read_bytes() == (tmp_path / "whole" / "pair.nc").read_bytes()


@pytest.mark.slow
def test_one_or_two_workers_give_the_same_store(tmp_path):
    definition = load_rare_event(_file(tmp_path))
    for workers in (1, 2):
        run_rare_event(definition, tmp_path / f"{workers}.nc", workers=workers)
    assert (tmp_path / "1.nc").read_bytes() == (tmp_path / "2.nc").read_bytes()


def test_a_store_of_another_definition_is_refused(tmp_path):
    run_rare_event(load_rare_event(_file(tmp_path)), tmp_path / "a.nc", stop_after=1)
    other = load_rare_event(_file(tmp_path, **{"seed = 3": "seed = 4"}))
    with pytest.raises(ExperimentError, match="made by another definition"):
        run_rare_event(other, tmp_path / "a.nc")
    run_rare_event(other, tmp_path / "b.nc")
    restarted = run_rare_event(other, tmp_path / "a.nc", restart=True)
    assert restarted.complete and restarted.batches_before == 0
    assert (tmp_path / "a.nc").read_bytes() == (tmp_path / "b.nc").read_bytes()


def test_the_report_draws_the_curve_and_states_the_separations(tmp_path):
    """``report build`` on a rare-event store: a section of its own with the curve to the target, its interval, and the separation table."""
    from stochpound.report.assemble import assemble_report
    from stochpound.report.render import FigureItem, Table

    definition = load_rare_event(_file(tmp_path))
    run_rare_event(definition, tmp_path / "a.nc")
    report = assemble_report([tmp_path / "a.nc"])
    section = next(s for s in report.sections if s.key == "rare-pair_rare")
    figure = next(b for b in section.blocks if isinstance(b, FigureItem))
    table = next(b for b in section.blocks if isinstance(b, Table))
    results = rare_event_results(open_rare_event_store(tmp_path / "a.nc"))
    assert list(table.frame.index) == [1e-3, 1e-4, 1e-6]
    assert table.frame["separation (m)"].values[0] == results.separations["value"][0]
    assert np.all(results.curve.lower <= results.curve.probability) and np.all(results.curve.probability <= results.curve.upper)
    assert "down to 0.001" in figure.caption and "n = 56 runs" in section.blocks[0].text


STOCHASTIC = """
[experiment]
name = "pair_stoch"

[scene]
bundled = "elastic_pair"

[scene.building.B2]
mass_factor = 2.0

[grid]
gap = [0.03, 0.035, inf]

[synthetic.wn]
type = "white_noise"
S0 = 0.01
duration = 2.0
dt = 0.02
count = 40
seed = 1
"""


def test_a_stochastic_experiment_of_the_same_runs_checks_the_curve_at_its_gaps(tmp_path):
    """With the stochastic store of the same scene and motion, the section gives crude Monte Carlo at its gaps beside the curve;
    a store of another motion is refused in one line, by the check and by the report."""
    from stochpound.experiment import crude_check, load_experiment, run_experiment
    from stochpound.report.assemble import assemble_report

    run_rare_event(load_rare_event(_file(tmp_path)), tmp_path / "a.nc")
    for name, text in (("same", STOCHASTIC), ("other", STOCHASTIC.replace("S0 = 0.01", "S0 = 0.02"))):
        (tmp_path / f"{name}.toml").write_text(text.replace("pair_stoch", f"pair_{name}"))
        run_experiment(load_experiment(tmp_path / f"{name}.toml"), tmp_path / f"{name}.nc", workers=0, progress=False)
    rare = open_rare_event_store(tmp_path / "a.nc")
    with stochpound_store(tmp_path / "same.nc") as same, stochpound_store(tmp_path / "other.nc") as other:
        check = crude_check(rare, same)
        with pytest.raises(ExperimentError, match="rare-event experiment pair_rare against experiment pair_other: none of its ensembles has the motion") as error:
            crude_check(rare, other)
        assert "\n" not in str(error.value)
        closure = same.pound.contact_free()["peak_contact_closure"].isel(record=0, contact=1).values
        assert list(check["gap"].values) == [0.03, 0.035] and check.attrs["cell"] == ""
        assert check["crude"].values[0] == np.mean(closure >= 0.03) and check["realizations"].values[0] == 40
        assert np.all(np.isfinite(check["subset"].values)) and check["subset"].values[0] >= check["subset"].values[1] > 0.0
    report = assemble_report([tmp_path / "same.nc", tmp_path / "a.nc"])
    section = next(s for s in report.sections if s.key == "rare-pair_rare")
    assert any(getattr(block, "key", "") == "rare-pair_rare-crude" for block in section.blocks)
    assert any(s.key == "rare-pair_rare" for s in assemble_report([tmp_path / "other.nc", tmp_path / "same.nc", tmp_path / "a.nc"]).sections)
    with pytest.raises(ExperimentError, match="none of its ensembles has the motion .*: give the store of the stochastic experiment it is a cell of"):
        assemble_report([tmp_path / "other.nc", tmp_path / "a.nc"])


GRID_SCENE = """
g = 9.81

[[building]]
name = "B1"
mass = [1.0e5, 1.0e5]
stiffness = [4.0e7, 4.0e7]
damping_ratio = 0.02
base = { mass = 5.0e4, mu = 0.1, radius = 2.24 }

[[building]]
name = "B2"
mass = [1.0e5, 1.0e5]
stiffness = [2.0e7, 2.0e7]
damping_ratio = 0.02

[[contact]]
between = [["B1", 1], ["B2", 1]]
gap = 0.02
stiffness = 5.0e7
restitution = 0.5

[[contact]]
between = [["B1", 2], ["B2", 2]]
gap = 0.02
stiffness = 5.0e7
restitution = 0.5
"""

GRID = """
[experiment]
name = "grid_stoch"

[scene]
file = "pair.toml"

[variants.neighbour.stiff.building.B2]
mass_factor = 0.5

[variants.neighbour.flexible.building.B2]
mass_factor = 2.0

[grid]
gap = [0.01, 0.03, inf]
mu = { values = [0.05, inf], buildings = ["B1"] }

[synthetic.low]
type = "white_noise"
S0 = 0.01
duration = 2.0
dt = 0.02
count = 30
seed = 1

[synthetic.high]
type = "white_noise"
S0 = 0.03
duration = 2.0
dt = 0.02
count = 30
seed = 2
"""

CELL = """
[experiment]
name = "cell_rare"

[scene]
file = "pair.toml"

[scene.building.B1]
base = { mu = 0.05 }

[scene.building.B2]
mass_factor = 2.0

[synthetic.high]
type = "white_noise"
S0 = 0.03
duration = 2.0
dt = 0.02

[rare_event]
response = "max_closure"
target_probability = 1e-3
samples_per_level = 20
seed = 4
"""


@pytest.mark.slow
def test_a_rare_event_store_is_checked_against_its_cell_of_a_grid(tmp_path):
    """A stochastic experiment over neighbour × μ × gap and two ensembles: the check takes the contact-free runs of the one cell whose
    scene and motion are the rare-event experiment's (the largest closure of either contact at each gap), and the report says which;
    a rare-event experiment that is none of its cells (another neighbour) is refused in one line, by the check and by the report."""
    from stochpound.experiment import crude_check, load_experiment, run_experiment
    from stochpound.report.assemble import assemble_report
    from stochpound.report.render import Table

    (tmp_path / "pair.toml").write_text(GRID_SCENE)
    (tmp_path / "grid.toml").write_text(GRID)
    run_experiment(load_experiment(tmp_path / "grid.toml"), tmp_path / "grid.nc", workers=0, progress=False)
    for name, text in (("cell", CELL), ("none", CELL.replace("mass_factor = 2.0", "mass_factor = 3.0").replace("cell_rare", "none_rare"))):
        (tmp_path / f"{name}.toml").write_text(text)
        assert load_rare_event(tmp_path / f"{name}.toml").table.contact is None
        run_rare_event(load_rare_event(tmp_path / f"{name}.toml"), tmp_path / f"{name}.nc")
    with stochpound_store(tmp_path / "grid.nc") as grid:
        check = crude_check(open_rare_event_store(tmp_path / "cell.nc"), grid)
        closure = grid.pound.contact_free()["peak_contact_closure"].sel(neighbour="flexible", mu=0.05, record="high").max("contact").values
        others = grid.pound.contact_free()["peak_contact_closure"].sel(neighbour="stiff", mu=0.05, record="high").max("contact").values
        assert check.attrs["cell"] == "neighbour flexible, μ 0.05" and check.attrs["record"] == "high"
        assert list(check["gap"].values) == [0.01, 0.03] and list(check["realizations"].values) == [30, 30]
        assert list(check["crude"].values) == [np.mean(closure >= 0.01), np.mean(closure >= 0.03)]
        assert np.mean(others >= 0.01) != np.mean(closure >= 0.01)  # the cells differ: the check took the right one
        with pytest.raises(ExperimentError, match="against experiment grid_stoch: none of its contact-free cells has the scene of none_rare") as error:
            crude_check(open_rare_event_store(tmp_path / "none.nc"), grid)
        assert "\n" not in str(error.value)
    report = assemble_report([tmp_path / "grid.nc", tmp_path / "cell.nc"])
    section = next(s for s in report.sections if s.key == "rare-cell_rare")
    table = next(b for b in section.blocks if isinstance(b, Table) and b.key == "rare-cell_rare-crude")
    assert "ensemble high in its cell neighbour flexible, μ 0.05" in table.caption
    assert list(table.frame["crude Monte Carlo"].values) == list(check["crude"].values)
    assert "largest closure of any contact" in section.blocks[0].text
    with pytest.raises(ExperimentError, match="none of its contact-free cells has the scene of none_rare"):
        assemble_report([tmp_path / "grid.nc", tmp_path / "none.nc"])


def stochpound_store(path):
    import stochpound

    return stochpound.open_store(path)


def test_experiment_check_names_a_rare_event_file(tmp_path):
    from click.testing import CliRunner

    from stochpound.cli import main

    result = CliRunner().invoke(main, ["experiment", "check", str(_file(tmp_path))])
    assert result.exit_code == 0 and "valid rare-event experiment" in result.output
    bad = CliRunner().invoke(main, ["experiment", "run", str(_file(tmp_path, **{"p0 = 0.1": "p0 = 0.9"}))])
    assert bad.exit_code == 1 and "rare_event.p0: must be <= 0.5, got 0.9" in bad.output


def test_a_run_stopped_by_max_levels_says_the_target_was_not_reached(tmp_path):
    run = run_rare_event(load_rare_event(_file(tmp_path, **{"seed = 3": "seed = 3\nmax_levels = 2"})), tmp_path / "a.nc")
    results = rare_event_results(open_rare_event_store(tmp_path / "a.nc"))
    assert run.complete and run.levels == 2 and results.complete and not results.target_reached
    assert np.all(np.isnan(results.separations["value"]))  # 1e-3 is below the reach of two levels of 20 samples


def test_a_limit_state_is_its_demand_over_its_capacity(tmp_path):
    """``response = "limit_state"``: the sampler's response is the demand's (here the impact force at contact 1, gaps kept) over the capacity."""
    from stochpound.experiment import rare_event_sampler

    force = load_rare_event(_file(tmp_path, **{'response = "closure"': 'response = "impact_force"', "S0 = 0.01": "S0 = 1.0"}))
    limit = load_rare_event(_file(tmp_path, **{'response = "closure"': 'response = "limit_state"\nlimit_state = "impact_force"\ncapacity = 2.0e5',
                                               "S0 = 0.01": "S0 = 1.0"}))
    assert limit.table.sampled == "impact_force" and limit.table.capacity == 2.0e5
    demand = rare_event_sampler(force).start(range(3))[1]
    ratio = rare_event_sampler(limit).start(range(3))[1]
    assert np.any(demand > 0.0) and np.array_equal(ratio, demand / 2.0e5)


def test_a_building_is_found_by_its_default_name(tmp_path):
    """A scene whose buildings carry no ``name`` calls them B1, B2, ... everywhere, the rare-event table included."""
    text = FILE.format(samples=20).replace('[scene]\nbundled = "elastic_pair"\n\n[scene.building.B2]\nmass_factor = 2.0\n', """[[scene.building]]
mass = [1.0e5, 1.0e5]
stiffness = [2.0e7, 2.0e7]
damping_ratio = 0.05
""").replace('response = "closure"\ncontact = 1', 'response = "peak_storey_drift"\nbuilding = "B1"\nfloor = 2')
    path = tmp_path / "alone.toml"
    path.write_text(text)
    table = load_rare_event(path).table
    assert (table.building, table.floor) == ("B1", 2)


def test_max_closure_is_the_largest_of_the_contacts_closures(tmp_path):
    """``response = "max_closure"`` samples, run by run, the larger of the two contacts' closures of the contact-free pair; it takes no contact."""
    from stochpound.experiment import rare_event_sampler

    closures = [rare_event_sampler(load_rare_event(_file(tmp_path, **{"contact = 1": f"contact = {c}"}))).start(range(4))[1] for c in (0, 1)]
    largest = rare_event_sampler(load_rare_event(_file(tmp_path, **{'response = "closure"\ncontact = 1': 'response = "max_closure"'}))).start(range(4))[1]
    assert np.array_equal(largest, np.maximum(*closures)) and not np.array_equal(closures[0], closures[1])
    with pytest.raises(ExperimentError, match="rare_event.contact: not used by response = 'max_closure'"):
        load_rare_event(_file(tmp_path, **{'response = "closure"': 'response = "max_closure"'}))
