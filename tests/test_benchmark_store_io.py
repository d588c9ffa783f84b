"""benchmarks.store_io: opening a store and creating its metadata, through h5netcdf and through netCDF4, timed in one run."""

from __future__ import annotations

import re

from benchmarks.store_io import main
from stochpound.experiment import load_experiment, run_experiment
from tests.helpers import TINY_EXPERIMENT, write_experiment


def test_the_benchmark_times_both_engines_on_the_store_given(tmp_path, capsys) -> None:
    store = run_experiment(load_experiment(write_experiment(tmp_path, TINY_EXPERIMENT, "tiny.toml")), workers=0, progress=False).store
    assert main([str(store), "--repeat", "1"]) == 0
    out = capsys.readouterr().out
    assert f"Store `{store.name}`, " in out and "| operation | h5netcdf (s) | netcdf4 (s) | h5netcdf / netcdf4 |" in out
    assert re.search(r"\| open \| [\d.]+ \| [\d.]+ \| [\d.]+ \|", out) and re.search(r"\| create \| [\d.]+ \| [\d.]+ \| [\d.]+ \|", out)
