"""``stochpound simulate SCENE.toml --out RUN.nc`` writes the result dataset of docs/scene-files.md (refusing to overwrite, following the umask)."""

import os
import stat
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


SMALL_SCENE = """
[[building]]
mass = [1.0e5]
stiffness = [4.0e7]
damping = [1.0e5]

[motion]
type = "harmonic"
amplitude = 3.0
omega = 9.0
duration = 2.0
dt = 0.01
"""


def _simulate(folder, *args: str, umask: int | None = None) -> subprocess.CompletedProcess:
    scene = folder / "scene.toml"
    scene.write_text(SMALL_SCENE)

    def set_umask() -> None:
        if umask is not None:
            os.umask(umask)

    return subprocess.run([sys.executable, "-m", "stochpound", "simulate", str(scene), *args], capture_output=True, text=True, preexec_fn=set_umask)


def test_an_existing_output_is_refused_without_overwrite_and_other_suffixes_are_warned_about(tmp_path):
    from tests.helpers import invoke

    scene = tmp_path / "scene.toml"
    scene.write_text(SMALL_SCENE)
    out = tmp_path / "run.h5"
    written = invoke("simulate", str(scene), "--out", str(out))
    assert written.exit_code == 0 and "warning: --out" in written.stderr and "usual suffix is .nc (got .h5)" in written.stderr
    out.write_bytes(b"keep me")
    refused = invoke("simulate", str(scene), "--out", str(out))
    assert refused.exit_code == 2 and f"{out} exists; give --overwrite to replace it" in refused.stderr
    assert out.read_bytes() == b"keep me"
    replaced = invoke("simulate", str(scene), "--out", str(out), "--overwrite")
    assert replaced.exit_code == 0, replaced.stderr
    with xr.open_dataset(out) as run:
        assert run.sizes["time"] == 201
    assert "warning" not in invoke("simulate", str(scene), "--out", str(tmp_path / "run.nc")).stderr


def test_the_output_follows_the_umask(tmp_path):
    out = tmp_path / "run.nc"
    assert _simulate(tmp_path, "--out", str(out), umask=0o027).returncode == 0
    assert stat.S_IMODE(out.stat().st_mode) == 0o640  # neither mkstemp's 0600 nor the usual 0644
