"""Absurd sizes are refused before anything is allocated, with one line naming the field and the estimate."""

from __future__ import annotations

import re
import tracemalloc

import numpy as np
import pytest
import xarray as xr

import stochpound
from stochpound.experiment._ensemble import simulate_ensemble
from stochpound._memory import LIMIT_VARIABLE, MemoryLimitError, memory_limit, parse_size, physical_memory, sample_bytes
from stochpound.studies.agarwal2004 import study_scene
from tests.helpers import SMALL_EXPERIMENT, invoke, write_experiment

HARMONIC = {"type": "harmonic", "amplitude": 3.0, "omega": 9.0, "duration": 20.0, "dt": 0.02}


def _write_scene(tmp_path, motion: dict) -> str:
    lines = ["[[building]]", "mass = [1.0e5]", "stiffness = [4.0e7]", "damping = [1.0e5]", "[motion]"]
    lines += [f"{key} = {value!r}" if isinstance(value, str) else f"{key} = {value}" for key, value in motion.items()]
    path = tmp_path / "scene.toml"
    path.write_text("\n".join(lines).replace("'", '"') + "\n")
    return str(path)


@pytest.mark.parametrize(
    "change, field",
    [({"duration": 1e9}, r"motion: duration 1e\+09 s at dt 0.02 s is 5e\+10 samples"), ({"dt": 1e-9}, r"motion: duration 20 s at dt 1e-09 s is 2e\+10 samples")],
)
def test_simulate_refuses_an_absurd_motion_in_one_line(tmp_path, change, field):
    result = invoke("simulate", _write_scene(tmp_path, {**HARMONIC, **change}), "--out", str(tmp_path / "run.nc"), env={LIMIT_VARIABLE: ""})
    assert result.exit_code == 1 and isinstance(result.exception, SystemExit)  # a clean command error, no traceback
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert re.search(field + r"; a run needs about [0-9.]+ TiB, more than the memory limit of .*" + LIMIT_VARIABLE, lines[0]), lines[0]
    assert not (tmp_path / "run.nc").exists()


def test_the_limit_is_the_variable_when_set(tmp_path):
    scene = _write_scene(tmp_path, HARMONIC)
    refused = invoke("simulate", scene, "--out", str(tmp_path / "run.nc"), env={LIMIT_VARIABLE: "100kB"})
    assert refused.exit_code == 1 and f"more than the memory limit of 97.7 KiB ({LIMIT_VARIABLE}=100kB)" in refused.stderr
    assert invoke("simulate", scene, "--out", str(tmp_path / "run.nc"), env={LIMIT_VARIABLE: "1GiB"}).exit_code == 0
    assert (tmp_path / "run.nc").is_file()


def test_an_experiment_ensemble_of_absurd_duration_is_refused(tmp_path):
    path = write_experiment(tmp_path, SMALL_EXPERIMENT.replace("duration = 8.0\ndt = 0.02", "duration = 1e8\ndt = 0.02"))
    result = invoke("experiment", "check", str(path), env={LIMIT_VARIABLE: ""})
    assert result.exit_code == 1 and isinstance(result.exception, SystemExit)
    assert result.stderr.startswith("Error: synthetic.kt: duration 1e+08 s at dt 0.02 s is 5e+09 samples; a run needs about"), result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_sizes_and_the_default_limit(monkeypatch):
    assert parse_size("64GiB") == 64 * 2**30 and parse_size("500MB") == 500 * 10**6 and parse_size("2e9") == 2 * 10**9 and parse_size("1.5 kib") == 1536
    with pytest.raises(ValueError, match=f"{LIMIT_VARIABLE}: must be a size such as 64GiB"):
        parse_size("lots")
    monkeypatch.delenv(LIMIT_VARIABLE, raising=False)
    assert memory_limit()[0] == physical_memory() // 2
    monkeypatch.setenv(LIMIT_VARIABLE, "3GiB")
    assert memory_limit() == (3 * 2**30, f"{LIMIT_VARIABLE}=3GiB")


@pytest.mark.parametrize("mu1, mu2", [(0.2, None), (None, None), (0.1, 0.1)])
@pytest.mark.parametrize("motion", [HARMONIC, {"type": "kanai_tajimi", "omega_g": 15.0, "zeta_g": 0.6, "S0": 0.01, "seed": 1, "duration": 20.0, "dt": 0.02}])
def test_the_estimate_bounds_a_real_run_within_a_factor_of_three(mu1, mu2, motion):
    """Peak of numpy's allocations (tracemalloc) while a scene is built and simulated, against the estimate."""
    long_motion = {**motion, "duration": 1000.0, "dt": 0.01}
    stochpound.simulate(stochpound.scene_from_dict(study_scene(mu1, mu2, motion={**motion, "duration": 1.0})))  # compile, warm caches
    tracemalloc.start()
    try:
        scene = stochpound.scene_from_dict(study_scene(mu1, mu2, motion=long_motion))
        stochpound.simulate(scene)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    n_dof = sum(b.n_floors + (b.base is not None) for b in scene.buildings)
    estimate = len(scene.motion.times) * sample_bytes(n_dof, len(scene.buildings), scene.max_floors, len(scene.contacts))
    assert 1.0 <= estimate / peak <= 3.0, (estimate, peak)


def test_an_ensemble_beyond_the_limit_is_refused(monkeypatch):
    scene = stochpound.scene_from_dict(study_scene(motion={**HARMONIC, "duration": 1.0}))
    motions = xr.DataArray(np.zeros((4, 1001)), dims=("realization", "time"), attrs={"dt": 0.01})
    monkeypatch.setenv(LIMIT_VARIABLE, "1MB")
    with pytest.raises(MemoryLimitError, match=r"^batch_size: 8 runs of 1001 samples at a time \(1 workers\) needs about"):
        simulate_ensemble(scene, motions, workers=1)
    many = xr.DataArray(np.zeros((2000, 1001)), dims=("realization", "time"), attrs={"dt": 0.01})
    monkeypatch.setenv(LIMIT_VARIABLE, "10MB")
    with pytest.raises(MemoryLimitError, match=r"^motions: 2000 realizations of 1001 samples kept as histories needs about 183 MiB"):
        simulate_ensemble(scene, many, keep="histories", workers=1, batch_size=1)
    assert simulate_ensemble(scene, motions, workers=1).sizes["realization"] == 4
