"""``stochpound simulate SCENE.toml --out RUN.nc`` writes the result dataset of docs/scene-files.md."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import xarray as xr

import stochpound

EXAMPLE = Path(__file__).parents[1] / "experiments" / "scenes" / "study_b1_isolated_flexible.toml"
CONTRACT_NAMES = {
    "total_displacement": ("building", "floor", "time"),
    "relative_displacement": ("building", "floor", "time"),
    "sliding_displacement": ("building", "time"),
    "impact_force": ("contact", "time"),
    "impact_contact": ("impact",),
    "impact_start": ("impact",),
    "impact_end": ("impact",),
    "impact_peak_force": ("impact",),
    "impact_in_phase": ("impact",),
}


def test_simulate_writes_the_contract_dataset(tmp_path):
    out = tmp_path / "run.nc"
    result = subprocess.run(
        [sys.executable, "-m", "stochpound", "simulate", str(EXAMPLE), "--out", str(out), "--method", "ivp"],
        capture_output=True, text=True, check=True,
    )
    assert "impacts" in result.stdout
    with xr.open_dataset(out) as run:
        for name, dims in CONTRACT_NAMES.items():
            assert run[name].dims == dims, name
            assert "units" in run[name].attrs
        assert list(run.building.values) == ["B1", "B2"]
        assert list(run.floor.values) == [1, 2]
        assert run.time.values[0] == 0.0 and len(run.time) == 2500
        assert run.attrs["solver"] == "ivp" and run.attrs["integrator"] == "DOP853"
        assert run.attrs["stochpound_version"] == stochpound.__version__
        assert run.impact_in_phase.dtype == bool
        np.testing.assert_array_equal(run.sliding_displacement.sel(building="B2"), 0.0)
        in_memory = stochpound.simulate(stochpound.load_scene(EXAMPLE), method="ivp")
        np.testing.assert_array_equal(run.total_displacement.values, in_memory.total_displacement.values)
