"""``stochpound experiment run --seed``: the same experiment with another [intensity] seed, into its own store, no copy of the file."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
import xarray as xr

from stochpound._errors import ExperimentError
from stochpound._plurals import counted
from stochpound.experiment import load_experiment, seed_store
from stochpound.experiment._reseed import reseeded_text
from tests.helpers import invoke, stripes_site_text

SELECTION = '[intensity]\nmeasure = "psa"\nselection = "conditional_spectrum"\n'


def _reseeded(text: str, seed: int) -> str:
    return reseeded_text(text, seed, "x.toml")


def test_the_seed_line_of_the_intensity_table_alone_is_set_its_comment_kept():
    text = f'[experiment]\nseed = 9\n{SELECTION}seed = 1   # the selection\'s\nmotions = 4\n[site]\nseed = 8\n'
    assert _reseeded(text, 5) == f'[experiment]\nseed = 9\n{SELECTION}seed = 5   # the selection\'s\nmotions = 4\n[site]\nseed = 8\n'


def test_a_file_without_a_seed_line_gets_one_after_the_header():
    text = f"{SELECTION}motions = 4\n"
    edited = _reseeded(text, 3)
    assert edited == '[intensity]\nseed = 3\nmeasure = "psa"\nselection = "conditional_spectrum"\nmotions = 4\n'
    assert tomllib.loads(edited)["intensity"]["seed"] == 3


@pytest.mark.parametrize(("text", "message"), [
    ('[intensity]\nmeasure = "psa"\nlevels = [0.1]\n', '--seed: x.toml has no [intensity] selection = "conditional_spectrum", whose seed it sets'),
    ('[experiment]\nname = "a"\n', '--seed: x.toml has no [intensity] selection = "conditional_spectrum", whose seed it sets'),
    ('intensity = { selection = "conditional_spectrum", seed = 1 }\n',
     "--seed: cannot set the [intensity] seed of x.toml alone by editing its seed line (set it in the file)"),
])
def test_a_file_whose_seed_the_edit_cannot_set_is_refused_in_one_line(text: str, message: str):
    with pytest.raises(ExperimentError) as raised:
        _reseeded(text, 2)
    assert str(raised.value) == message


@pytest.mark.parametrize(("text", "seed"), [(f"{SELECTION}seed = 4\n", 4), (SELECTION, 1)])  # the selection's default seed: 1
def test_the_file_s_own_seed_is_refused_rather_than_run_twice(text: str, seed: int):
    with pytest.raises(ExperimentError) as raised:
        _reseeded(text, seed)
    assert str(raised.value) == f"--seed: {seed} is x.toml's own [intensity] seed: run the file without --seed (its store is beside it)"


def test_a_negative_seed_is_refused():
    with pytest.raises(ExperimentError, match=r"--seed: must be an integer >= 0, got -1"):
        _reseeded(f"{SELECTION}seed = 1\n", -1)


@pytest.fixture(scope="module")
def seeded(tmp_path_factory):
    """A small conditional-spectrum experiment run by the CLI with its own seed (3) and with --seed 7 and 8."""
    folder = tmp_path_factory.mktemp("seeded")
    path = folder / "site.toml"
    path.write_text(stripes_site_text('[hazard]\nbundled = "fox_plaza_los_angeles_sa1p0s"\n'))
    runs = [invoke("experiment", "run", str(path), "--workers", "0", "--quiet", *extra) for extra in ((), ("--seed", "7"), ("--seed", "8"))]
    return path, runs


def test_the_seed_run_goes_to_its_own_store_and_records_the_reseeded_text(seeded):
    from stochpound.risk import check_alternative

    path, runs = seeded
    assert [run.exit_code for run in runs] == [0, 0, 0], [run.output for run in runs]
    store = seed_store(path, 7)
    assert store == path.parent / "seed7" / "site.nc" and store.is_file()
    with xr.open_dataset(path.with_suffix(".nc")) as main, xr.open_dataset(store) as other:
        assert check_alternative(main, other, "seed") == "selection seed 7"  # the same experiment but for the seed
        assert other.attrs["experiment_text"] == path.read_text().replace("seed = 3\n", "seed = 7\n")
        assert not main["selection_mean_ln"].equals(other["selection_mean_ln"])  # another seed, other motions
    assert load_experiment(path, seed=7).sha256 != load_experiment(path).sha256


def test_rerunning_the_seed_command_finds_its_store_complete(seeded):
    path, _ = seeded
    again = invoke("experiment", "run", str(path), "--workers", "0", "--quiet", "--seed", "7")
    assert again.exit_code == 0 and "nothing to run" in again.output.lower(), again.output


def test_seed_refuses_a_file_without_a_selection_in_one_line(tmp_path):
    path = tmp_path / "plain.toml"
    path.write_text('[experiment]\nname = "plain"\n')
    result = invoke("experiment", "run", str(path), "--seed", "2")
    assert result.exit_code == 1
    assert result.output.strip().splitlines()[-1] == f'Error: --seed: {path} has no [intensity] selection = "conditional_spectrum", whose seed it sets'


def test_seed_refuses_a_rare_event_file_in_one_line():
    path = "experiments/stochastic/rare/firm_stiff_fixed.toml"
    result = invoke("experiment", "run", path, "--seed", "2")
    assert result.exit_code == 2
    assert f"{path}: a [rare_event] file's seed is its [rare_event] seed, not set by --seed" in result.output


def test_the_api_s_default_store_of_a_reseeded_experiment_is_its_seed_store(seeded):
    """load_experiment(path, seed=7) run without a store finds the CLI's seed-7 store complete: not the file's own store."""
    from stochpound.experiment import run_experiment

    path, _ = seeded
    report = run_experiment(load_experiment(path, seed=7), workers=0, progress=False)
    assert report.store == seed_store(path, 7) and report.nothing_to_run


def test_three_seeds_give_the_sensitivity_table_their_median_and_largest_g_star(seeded):
    """With the store's seed and two seed stores, the table adds the median and the largest g* over the three, each
    with its change from g*: recomputed here from the three seeds' own columns."""
    from stochpound.risk import separation_sensitivity, store_risk

    path, _ = seeded
    with xr.open_dataset(path.with_suffix(".nc")) as main, xr.open_dataset(seed_store(path, 7)) as seven, \
            xr.open_dataset(seed_store(path, 8)) as eight:
        risk = store_risk(main, bootstrap=0)
        sensitivity = separation_sensitivity(risk, main, alternatives=[("seed", seven), ("seed", eight)])
    frame = sensitivity.frame
    over = frame[["g* (m)", "selection seed 7", "selection seed 8"]].to_numpy(dtype=float)
    both = sensitivity.seeds_beside_design(risk.design_frame(), risk.years)  # no bootstrap: the gap to design to is g* itself
    withheld = int(risk.design_frame()["design"].isna().sum())  # g* only a lower bound: no gap to design to, the row left out
    assert len(both) == int(np.isfinite(over).all(axis=1).sum()) - withheld > 0
    np.testing.assert_array_equal(both["largest"].to_numpy(), frame.loc[both.index, "selection seeds (3): largest"].to_numpy())
    np.testing.assert_array_equal(both["design"].to_numpy(), frame.loc[both.index, "g* (m)"].to_numpy())
    np.testing.assert_array_equal(frame["selection seeds (3): median"].to_numpy(dtype=float), np.median(over, axis=1))
    np.testing.assert_array_equal(frame["selection seeds (3): largest"].to_numpy(dtype=float), np.max(over, axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        np.testing.assert_allclose(frame["selection seeds (3): largest: Δ (%)"], 100 * (over.max(axis=1) / over[:, 0] - 1))
    spread = frame["selection seeds (3): λ_P at their median g*: largest / smallest (×)"].to_numpy(dtype=float)
    assert np.all((spread >= 1.0) | np.isnan(spread)) and list(frame.columns)[-1].endswith("(×)")


def test_the_risk_cli_sets_the_seeds_largest_g_star_beside_the_gap_to_design_to(seeded):
    """`stochpound risk` with two seed stores prints, after the sensitivity table, the three seeds' largest g* beside the gap
    to design to, and how many rows lie above it: the count matches the rows the API marks."""
    from stochpound.risk import separation_sensitivity, store_risk

    path, _ = seeded
    stores = [path.with_suffix(".nc"), seed_store(path, 7), seed_store(path, 8)]
    result = invoke("risk", str(stores[0]), "--bootstrap", "40", *(f"--sensitivity-store=seed={store}" for store in stores[1:]))
    assert result.exit_code == 0, result.output
    with xr.open_dataset(stores[0]) as main, xr.open_dataset(stores[1]) as seven, xr.open_dataset(stores[2]) as eight:
        risk = store_risk(main, bootstrap=40)
        both = separation_sensitivity(risk, main, alternatives=[("seed", seven), ("seed", eight)]).seeds_beside_design(risk.design_frame(), risk.years)
    assert not both.empty and both["above"].tolist() == (both["largest"] > both["design"]).tolist()
    assert (f"The 3 selection seeds' largest g* beside the gap to design to (m): above it in {int(both['above'].sum())} of {counted(len(both), 'row')} "
            "(the gap to design to does not bound which motions are chosen):") in result.output
