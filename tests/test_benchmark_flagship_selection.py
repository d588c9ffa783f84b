"""The selection-only run of a flagship (benchmarks/flagship_selection.py): its file's pool size replaced, and its stripe table
read off a selection."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from benchmarks.flagship_selection import stripe_rows, with_simulated, worst
from benchmarks.timing import REPOSITORY


def test_the_flagship_s_pool_size_is_replaced_in_a_copy(tmp_path):
    """The copy differs from the flagship in its simulated_motions line alone; a file without one is refused; None keeps the file."""
    flagship = REPOSITORY / "experiments" / "risk" / "fixed_pair.toml"
    copy = with_simulated(flagship, 12345, tmp_path)
    old, new = flagship.read_text().splitlines(), copy.read_text().splitlines()
    changed = [(a, b) for a, b in zip(old, new) if a != b]
    assert len(old) == len(new) and len(changed) == 1 and changed[0][1].startswith("simulated_motions = 12345 ")
    assert with_simulated(flagship, None, tmp_path) == flagship
    other = tmp_path / "other.toml"
    other.write_text("[site]\nvs30 = 400.0\n")
    with pytest.raises(SystemExit, match="no \\[site\\] simulated_motions"):
        with_simulated(other, 10, tmp_path)


class _Selection:
    """A stand-in for a flagship's selection: one stripe of 4 motions, one of them simulated, two of one earthquake."""

    def __init__(self) -> None:
        periods = [0.1, 1.0]
        self.experiment_levels = [0.5]
        self.simulated = {"simulated 1.7": None}
        self.targets = [xr.Dataset(attrs={"epsilon": 2.0})]
        self.selections = [xr.Dataset({"motion": ("selected", ["a", "b", "c", "simulated 1.7"]),
                                       "earthquake": ("selected", ["e1", "e1", "e2", "simulated 1.7"]),
                                       "mean_ln": ("period", np.log([0.5, 0.3]) + [0.15, -0.02]), "median": ("period", [0.5, 0.3]),
                                       "std_ln": ("period", [0.5, 0.6]), "sigma_ln": ("period", [0.55, 0.6])},
                                      coords={"period": periods}, attrs={"pool": 2100, "target_reachable": 0, "chosen_by": "misfit"})]


def test_a_stripe_s_row_gives_its_counts_shares_and_worst_misses():
    """The row: level, ε, N Φ(−ε), pool, recorded + simulated, the largest share of one earthquake, the worst differences, the verdict, the rule that chose the set."""
    row = stripe_rows(type("E", (), {"selection": _Selection()})(), 1000)[0]
    assert row == ["0.5", "2.00", "22.8", "2100", "3 + 1", "0.500", "+0.150 (0.1 s)", "-0.050 (0.1 s)", "**miss**", "**no**", "misfit"]
    assert worst(np.array([0.01, -0.09]), np.array([1.0, 2.0])) == "-0.090 (2 s)"
    assert stripe_rows(type("E", (), {"selection": _Selection()})(), 1000, tilted=True)[0][2] == "-"



def test_the_benchmark_s_copy_replaces_the_sampling_line_or_adds_one(tmp_path):
    """A flagship's ``simulated_sampling`` line is replaced, not repeated (a repeated key is not TOML); a file without one gets one
    after its ``simulated_motions`` line."""
    flagship = REPOSITORY / "experiments" / "risk" / "isolated.toml"
    old, new = flagship.read_text().splitlines(), with_simulated(flagship, None, tmp_path, "scenario").read_text().splitlines()
    changed = [(a, b) for a, b in zip(old, new) if a != b]
    assert len(new) == len(old) and len(changed) == 1 and changed[0][1].startswith('simulated_sampling = "scenario" ')
    bare = tmp_path / "bare" / "isolated.toml"
    bare.parent.mkdir()
    bare.write_text("\n".join(line for line in old if not line.startswith("simulated_sampling")) + "\n")
    added = with_simulated(bare, None, tmp_path, "tilted").read_text().splitlines()
    assert added[added.index(next(line for line in added if line.startswith("simulated_motions"))) + 1] == 'simulated_sampling = "tilted"'
    assert len(added) == len(old)


def test_the_benchmark_s_parameter_rows_count_each_stripe_s_chosen_simulated_motions(tilted_experiment):
    from benchmarks.flagship_selection import COLUMNS, parameter_rows

    selection = tilted_experiment.selection
    rows = parameter_rows(tilted_experiment)
    assert [len(row) for row in rows] == [len(COLUMNS)] * 2
    for row, chosen in zip(rows, selection.selections):
        count = sum(str(m) in selection.simulated for m in chosen["motion"].values)
        assert row[1] == str(count) and (count == 0 or float(row[5]) > 0.0)
