"""Batched ensembles: one dataset with a realization dimension, independent of batching and workers."""

import dataclasses
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import stochpound
from stochpound import motions as synthetic
from stochpound.experiment._ensemble import simulate_ensemble
from stochpound.motions.ground import SampledMotion
from stochpound.studies.agarwal2004 import study_scene

N_REALIZATIONS = 6


@pytest.fixture(scope="module")
def scene():
    return stochpound.scene_from_dict(study_scene(0.1, 0.1, 0.5, gap=0.01))


@pytest.fixture(scope="module")
def motions():
    return synthetic.kanai_tajimi(N_REALIZATIONS, 6.0, 0.01, omega_g=15.0, zeta_g=0.6, pga=3.4, envelope="jennings", seed=3)


@pytest.fixture(scope="module")
def ensemble(scene, motions):
    return simulate_ensemble(scene, motions, keep="histories", batch_size=4)


def test_summaries_match_single_runs(scene, motions, ensemble):
    """Every summary equals the one computed from a single simulate() run of that realization."""
    assert ensemble.sizes["realization"] == N_REALIZATIONS
    for r in (0, N_REALIZATIONS - 1):
        run = stochpound.simulate(dataclasses.replace(scene, motion=SampledMotion(0.01, motions.values[r])), method="exact")
        one = ensemble.isel(realization=r)
        np.testing.assert_array_equal(one.total_displacement.values, run.total_displacement.values)
        peak = np.nanmax(np.abs(run.total_displacement.values), axis=(1, 2))
        np.testing.assert_array_equal(one.peak_total_displacement.values, peak)
        np.testing.assert_array_equal(one.residual_sliding.values, run.sliding_displacement.values[:, -1])
        assert int(one.impacts) == run.sizes["impact"]
        assert int(one.impacts_in_phase) == int(run.impact_in_phase.sum())
        assert int(one.impacts_in_phase + one.impacts_out_of_phase) == int(one.impacts)
        if run.sizes["impact"]:
            assert float(one.peak_impact_force) == float(run.impact_peak_force.max())
            assert float(one.longest_impact) == float(run.impact_duration.max())
        top = run.total_displacement.sel(building="B1", floor=2).values
        assert float(one.response_mean.sel(building="B1")) == pytest.approx(top.mean(), rel=1e-12)
        assert float(one.response_std.sel(building="B1")) == pytest.approx(top.std(), rel=1e-12)
        deviation = top - top.mean()
        excess = np.mean(deviation**4) / np.mean(deviation**2) ** 2 - 3.0
        assert float(one.response_excess.sel(building="B1")) == pytest.approx(excess, rel=1e-9)
        assert float(one.energy_friction) == float(run.energy_friction[-1])


def test_result_does_not_depend_on_batching_or_workers(scene, motions, ensemble):
    summary = simulate_ensemble(scene, motions, batch_size=1, workers=2)
    for name in summary.data_vars:
        np.testing.assert_array_equal(summary[name].values, ensemble[name].values, err_msg=name)
    assert "total_displacement" not in summary  # summaries only: no histories kept
    assert summary.realization.values.tolist() == motions.realization.values.tolist()


DASK_AFTER_PARENT_COMPUTE = """
import sys
import numpy as np
import stochpound
from stochpound import motions as synthetic
from stochpound.experiment._ensemble import simulate_ensemble
from stochpound.studies.agarwal2004 import study_scene

scene = stochpound.scene_from_dict(study_scene(0.1, 0.1, 0.5, gap=0.01))
motions = synthetic.kanai_tajimi({n}, 6.0, 0.01, omega_g=15.0, zeta_g=0.6, pga=3.4, envelope="jennings", seed=3)
motions = motions.chunk(realization=2)
motions.isel(realization=0).values  # the parent computes a chunk first (dask's threaded scheduler)
result = simulate_ensemble(scene, motions, workers=2, batch_size=1)
np.savez(sys.argv[1], **{{name: result[name].values for name in result.data_vars}})
"""


@pytest.mark.slow
def test_dask_motions_in_worker_processes_after_the_parent_computed_a_chunk(ensemble, tmp_path):
    """Forked workers used to block on the lock of the parent's dask scheduler: the run must finish, unchanged."""
    output = tmp_path / "result.npz"
    script = DASK_AFTER_PARENT_COMPUTE.format(n=N_REALIZATIONS)
    process = subprocess.Popen([sys.executable, "-c", script, str(output)], cwd=Path(__file__).parents[1], start_new_session=True)
    try:
        assert process.wait(timeout=300) == 0
    finally:
        if process.poll() is None:  # hung: stop it and its workers
            os.killpg(process.pid, signal.SIGKILL)
    with np.load(output) as result:
        for name in result.files:
            np.testing.assert_array_equal(result[name], ensemble[name].values, err_msg=name)


def test_ivp_method_gives_the_same_summaries(scene, motions, ensemble):
    subset = motions.isel(realization=slice(0, 2))
    reference = simulate_ensemble(scene, subset, method="ivp")
    np.testing.assert_allclose(reference.peak_total_displacement.values, ensemble.peak_total_displacement.values[:2], rtol=0, atol=1e-8)
    np.testing.assert_array_equal(reference.impacts.values, ensemble.impacts.values[:2])


def test_motions_need_uniform_times_from_zero(scene, motions):
    shifted = motions.assign_coords(time=motions.time + 1.0)
    with pytest.raises(ValueError, match="start at 0"):
        simulate_ensemble(scene, shifted)
    with pytest.raises(ValueError, match="keep"):
        simulate_ensemble(scene, motions, keep="everything")
    bare = xr.DataArray(motions.values, dims=("realization", "time"), attrs={"dt": 0.01})
    assert simulate_ensemble(scene, bare.isel(realization=[0])).sizes["realization"] == 1
