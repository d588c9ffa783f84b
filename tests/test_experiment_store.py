"""The experiment store: layout, CF metadata, provenance, summaries against direct runs, refusals."""

from __future__ import annotations

import hashlib

import dask.array
import numpy as np
import h5py
import pytest
import xarray as xr

import stochpound
from stochpound.analysis._summary import top_floor_total_displacement
from stochpound.experiment import ExperimentError, load_experiment, open_store, run_experiment, store_status
from stochpound.experiment._parts import FolderLock, parts_folder
from tests.helpers import N_CASES, SMALL_EXPERIMENT, cli, write_experiment


@pytest.fixture(scope="module")
def small_store(tmp_path_factory):
    folder = tmp_path_factory.mktemp("store")
    path = write_experiment(folder)
    report = run_experiment(load_experiment(path), workers=0, progress=False)
    assert report.complete and report.done_now == N_CASES and not report.failed
    return path, report.store


def test_layout_and_metadata(small_store):
    path, store = small_store
    assert store == path.with_suffix(".nc")
    with xr.open_dataset(store) as ds:
        for dim, size in {"neighbour": 2, "gap": 2, "mu": 2, "record": 2, "realization": 2, "building": 2, "floor": 2, "time": 401}.items():
            assert ds.sizes[dim] == size, dim
        assert ds["mu"].values[-1] == np.inf
        assert list(ds["record"].values) == ["el_centro", "kt"]
        assert ds["impacts"].dims == ("neighbour", "gap", "mu", "record", "realization")
        assert ds["peak_total_displacement"].dims == ("neighbour", "gap", "mu", "record", "realization", "building")
        assert ds["total_displacement"].dims == ("neighbour", "gap", "mu", "record", "realization", "building", "floor", "time")
        assert ds["reference_response_std"].dims == ("record", "realization")
        assert ds["impact_start"].dims == ("impact",) and ds.sizes["impact"] > 0
        assert "peak_wall_penetration" not in ds  # a scene without walls: no wall summary
        for name, variable in ds.variables.items():
            assert "units" in variable.attrs and "long_name" in variable.attrs, name
        # a record has one realization: the others are not in the grid
        status = ds["case_status"].sel(record="el_centro")
        assert (status.sel(realization=0) == 1).all() and (status.sel(realization=1) == -1).all()
        assert int(ds.attrs["cases_done"]) == N_CASES and ds.attrs["complete"] == 1
        assert ds.attrs["experiment_text"] == SMALL_EXPERIMENT
        assert ds.attrs["experiment_sha256"] == hashlib.sha256(SMALL_EXPERIMENT.encode()).hexdigest()
        for key in ("definition_sha256", "stochpound_version", "git_commit", "solver", "seeds", "created", "updated", "machine", "runs"):
            assert ds.attrs[key] != "", key
        assert '"kt": 7' in ds.attrs["seeds"]
        # the B2 time histories were not kept
        assert np.isnan(ds["total_displacement"].sel(building="B2")).all()
        assert not np.isnan(ds["total_displacement"].sel(building="B1", record="el_centro", realization=0)).any()
    with xr.open_datatree(store) as tree:
        assert "impacts" in tree.dataset


def test_summaries_match_a_direct_run(small_store):
    path, store = small_store
    experiment = load_experiment(path)
    case = next(c for c in experiment.cases if c.kind == "case" and c.label_dict == {"neighbour": "flexible", "gap": 0.02, "mu": np.inf, "record": "el_centro", "realization": 0})
    run = stochpound.simulate(stochpound.scene_from_dict({**experiment.structure(case), "motion": {"record": "el_centro_1940_study", "duration": 8.0}}))
    alone = stochpound.simulate(stochpound.scene_from_dict({**experiment.reference_structure(case), "motion": {"record": "el_centro_1940_study", "duration": 8.0}}))
    y = top_floor_total_displacement(run, "B1").values
    y0 = top_floor_total_displacement(alone, "B1").values
    with open_store(store) as ds:
        assert isinstance(ds["impacts"].data, dask.array.Array)
        point = ds.sel(neighbour="flexible", gap=0.02, mu=np.inf, record="el_centro", realization=0).compute()
        assert point["impacts"] == run.sizes["impact"] > 0
        assert point["impacts_in_phase"] + point["impacts_out_of_phase"] == point["impacts"]
        assert point["peak_impact_force"] == run["impact_peak_force"].max()
        assert point["response_mean"] == pytest.approx(y.mean(), rel=1e-12, abs=1e-15)
        assert point["response_std"] == pytest.approx(y.std(), rel=1e-12)
        centred = y - y.mean()
        assert point["response_excess"] == pytest.approx(np.mean(centred**4) / np.mean(centred**2) ** 2 - 3, rel=1e-10)
        assert point["fixed_base_correlation"] == pytest.approx(np.corrcoef(y, y0)[0, 1], rel=1e-10)
        assert point["reference_response_std"] == pytest.approx(y0.std(), rel=1e-12)
        assert point["peak_total_displacement"].sel(building="B1") == np.abs(run["total_displacement"].sel(building="B1")).max()
        np.testing.assert_array_equal(point["total_displacement"].sel(building="B1").values, run["total_displacement"].sel(building="B1").values)
        table = ds[["impact_start", "impact_peak_force"]].compute()
        table = table.where(
            (table.impact_neighbour == "flexible") & (table.impact_gap == 0.02) & (table.impact_mu == np.inf) & (table.impact_record == "el_centro"), drop=True
        )
        np.testing.assert_array_equal(table["impact_start"].values, run["impact_start"].values)


def test_rerun_is_a_no_op_and_status_is_complete(small_store):
    path, store = small_store
    report = run_experiment(load_experiment(path), workers=0, progress=False)
    assert report.done_now == 0 and report.done_before == N_CASES and report.complete
    status = store_status(store)
    assert status.n_done == N_CASES and status.n_missing == 0 and not status.cases(done=False) and status.rebuilt


def _snapshot(store):
    folder = parts_folder(store)
    return store.read_bytes(), sorted(p.name for p in folder.iterdir())


def test_changed_definition_is_refused_without_restart(small_store, tmp_path):
    path, store = small_store
    before = _snapshot(store)
    changed = tmp_path / "small.toml"
    changed.write_text(SMALL_EXPERIMENT.replace("gap = [0.01, 0.02]", "gap = [0.01, 0.03]"))
    result = cli("experiment", "run", str(changed), "--store", str(store), "--workers", "0", check=False)
    assert result.returncode != 0
    assert "made from a different experiment definition" in result.stderr and "--restart" in result.stderr
    assert _snapshot(store) == before


def test_restart_replaces_a_store(tmp_path):
    path = write_experiment(tmp_path, SMALL_EXPERIMENT.replace("count = 2", "count = 1").replace("gap = [0.01, 0.02]", "gap = [0.02]"))
    store = tmp_path / "other.nc"
    with h5py.File(store, "w") as handle:  # a store of another definition (its identity attribute is what tells a store)
        handle.attrs["definition_sha256"] = "0" * 64
    before = store.read_bytes()
    with pytest.raises(ExperimentError, match=r"other\.nc: made from a different experiment definition .*--restart"):
        run_experiment(load_experiment(path), store, workers=0, progress=False)
    assert store.read_bytes() == before
    report = run_experiment(load_experiment(path), store, workers=0, progress=False, restart=True)
    assert report.complete and report.total == 2 * 2 * 2 + 2
    with open_store(store) as ds:
        assert ds.sizes["gap"] == 1


def test_a_store_being_written_is_refused(small_store):
    path, store = small_store
    lock = FolderLock(parts_folder(store))
    assert lock.acquire()
    try:
        with pytest.raises(ExperimentError, match="another run is writing this store"):
            run_experiment(load_experiment(path), workers=0, progress=False)
        assert store_status(store).running
    finally:
        lock.release()


def test_open_store_errors(tmp_path):
    with pytest.raises(ExperimentError, match="store not found"):
        open_store(tmp_path / "missing.nc")
    bad = tmp_path / "bad.nc"
    bad.write_bytes(b"garbage")
    with pytest.raises(ExperimentError, match="not a readable"):
        open_store(bad)
    with pytest.raises(ExperimentError, match=r"bad\.nc: not a readable"):
        store_status(bad)


@pytest.mark.parametrize("mu1, mu2", [(0.2, None), (None, None), (0.1, 0.1)])
def test_numpy_summaries_equal_the_analysis_definitions(mu1, mu2):
    from stochpound.experiment._summary import case_summary, case_values, reference_summary, reference_values, top_floor
    from stochpound.studies.agarwal2004 import reference_building, study_scene

    motion = {"record": "el_centro_1940_study", "duration": 10.0}
    run = stochpound.simulate(stochpound.scene_from_dict(study_scene(mu1=mu1, mu2=mu2, motion=motion)))
    alone = stochpound.simulate(stochpound.scene_from_dict({"g": 9.814, "building": [reference_building("B1")], "motion": motion}))
    fast = case_values(run, "B1", top_floor(alone, "B1"))
    slow = case_summary(run, "B1", top_floor_total_displacement(alone, "B1"))
    assert set(fast) == set(slow.data_vars)
    for name, value in fast.items():
        np.testing.assert_allclose(value, slow[name].values, rtol=1e-12, atol=1e-15, err_msg=name)
    fast, slow = reference_values(alone["total_displacement"].values[0]), reference_summary(alone, "B1")
    assert set(fast) == set(slow.data_vars)
    for name, value in fast.items():
        np.testing.assert_allclose(value, slow[name].values, rtol=1e-12, atol=1e-15, err_msg=name)


def test_both_netcdf_engines_read_the_same_store(small_store):
    """The file xarray creates through the netCDF C library (its netCDF4 back end), filled block by block with h5py, reads the
    same with h5netcdf (HDF5 through h5py) and with netCDF4."""
    _, store = small_store
    with xr.open_dataset(store, engine="h5netcdf") as a, xr.open_dataset(store, engine="netcdf4") as b:
        assert sorted(a.variables) == sorted(b.variables) and set(a.coords) == set(b.coords)
        for name in a.variables:
            assert a[name].dtype == b[name].dtype and a[name].dims == b[name].dims, name
            np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
        assert a.attrs == b.attrs


def test_a_store_written_through_h5netcdf_opens_the_same(small_store, tmp_path):
    """Stores written before the store's metadata went through the netCDF C library were created by h5netcdf: open_store
    reads such a file as the same dataset as one created through the netCDF library."""
    _, store = small_store
    earlier = tmp_path / "earlier.nc"
    with xr.open_dataset(store, engine="h5netcdf") as data:
        data.load().to_netcdf(earlier, engine="h5netcdf")
    with open_store(store) as expected, open_store(earlier) as actual:
        xr.testing.assert_identical(actual.load(), expected.load())


def test_a_large_ensemble_is_chunked_along_realization(tmp_path):
    """Blocks (and the file's chunks) of consecutive realizations; open_store keeps them as dask chunks."""
    from stochpound.experiment._file_layout import SUMMARY_BLOCK, block_shape, blocks

    assert block_shape((1, 1000000), SUMMARY_BLOCK) == (1, SUMMARY_BLOCK)
    assert block_shape((2, 3, 4, 1, 10), 50) == (1, 1, 4, 1, 10)
    assert block_shape((2, 3, 4, 1, 10), 100) == (1, 2, 4, 1, 10)
    assert [b[-1] for b in blocks((1, 10), (1, 4))] == [slice(0, 4), slice(4, 8), slice(8, 10)]
    text = SMALL_EXPERIMENT.replace("count = 2", "count = 300").replace("duration = 8.0\ndt = 0.02", "duration = 1.0\ndt = 0.02")
    text = text.replace("gap = [0.01, 0.02]", "gap = [0.01]\nneighbour = [\"stiff\"]").replace("values = [0.2, inf]", "values = [0.2]")
    path = write_experiment(tmp_path, text.replace('time_histories = ["total_displacement", "impact_force"]', ""))
    import stochpound.experiment._file_layout as layout

    original = layout.SUMMARY_BLOCK
    layout.SUMMARY_BLOCK = 128
    try:
        report = run_experiment(load_experiment(path), workers=0, progress=False)
    finally:
        layout.SUMMARY_BLOCK = original
    with open_store(report.store) as ds:
        assert ds["impacts"].data.chunks[-1] == (128, 128, 44) and ds["reference_response_std"].data.chunks[-1] == (128, 128, 44)
        whole = ds.compute()
    with xr.open_dataset(report.store) as ds:
        assert ds["impacts"].encoding["chunksizes"] == (1, 1, 1, 1, 128)
        xr.testing.assert_identical(ds.load(), whole)


def test_kept_histories_of_a_later_building_land_on_its_row(tmp_path):
    """Only B2's histories kept: they are B2's (not written on B1's row), and B1's are NaN."""
    from tests.helpers import TINY_EXPERIMENT

    text = TINY_EXPERIMENT.replace('[solver]\nmethod = "ivp"', '[output]\ntime_histories = ["total_displacement", "sliding_displacement"]\nbuildings = ["B2"]')
    path = write_experiment(tmp_path, text, "tiny.toml")
    report = run_experiment(load_experiment(path), workers=0, progress=False)
    experiment = load_experiment(path)
    run = stochpound.simulate(stochpound.scene_from_dict({**experiment.structure(experiment.points("case")[0]), "motion": experiment.motion_table("push")}))
    with open_store(report.store) as ds:
        point = ds.sel(record="push", realization=0).squeeze().compute()
    np.testing.assert_array_equal(point["total_displacement"].sel(building="B2").values, run["total_displacement"].sel(building="B2").values)
    np.testing.assert_array_equal(point["sliding_displacement"].sel(building="B2").values, run["sliding_displacement"].sel(building="B2").values)
    assert np.isnan(point["total_displacement"].sel(building="B1")).all() and np.isnan(point["sliding_displacement"].sel(building="B1")).all()


def test_the_store_is_written_under_a_lock_of_this_process_while_a_dask_client_is_active(small_store, tmp_path, monkeypatch):
    """xarray's default write lock is a dask.distributed Lock while a client is active; a last checkpoint rebuilt as the run's
    cluster closed failed on it ("IOLoop is closed"). The store writer must take no distributed lock, and the rebuilt
    store must hold the same data."""
    from distributed import Client, LocalCluster
    from distributed import Lock as DistributedLock
    from xarray.backends import NetCDF4DataStore

    from stochpound.experiment import _file_assembly as file_assembly
    from stochpound.experiment._session import StoreSession

    opened = []

    class RecordingStore(NetCDF4DataStore):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            opened.append(self)

    def locks(lock):  # the locks inside xarray's CombinedLock
        return [inner for part in lock.locks for inner in locks(part)] if hasattr(lock, "locks") else [lock]

    monkeypatch.setattr(file_assembly, "NetCDF4DataStore", RecordingStore)
    _, store = small_store
    session = StoreSession.open(store)
    rebuilt = tmp_path / "rebuilt.nc"
    with LocalCluster(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None) as cluster, Client(cluster):
        assert any(isinstance(lock, DistributedLock) for lock in locks(xr.backends.locks.get_write_lock("probe")))  # the default
        file_assembly.write_store(session.experiment, session.scan(), session.motion_grids, session.attrs(), rebuilt)
    assert opened and not any(isinstance(lock, DistributedLock) for store in opened for lock in locks(store.lock))
    with xr.open_dataset(store) as expected, xr.open_dataset(rebuilt) as actual:
        xr.testing.assert_identical(actual.drop_attrs(), expected.drop_attrs())


@pytest.mark.slow  # two runs of the small experiment (about 4 min at load 13)
def test_a_changed_comment_is_recorded_without_running_again(tmp_path):
    path = write_experiment(tmp_path)
    store = run_experiment(load_experiment(path), workers=0, progress=False).store
    with open_store(store) as ds:
        before = {name: ds[name].values.copy() for name in ds.data_vars}
    commented = "# the header, rewritten after the run\n" + SMALL_EXPERIMENT
    path.write_text(commented)
    report = run_experiment(load_experiment(path), workers=0, progress=False)
    assert report.done_now == 0 and report.complete
    with open_store(store) as ds:
        assert ds.attrs["experiment_text"] == commented
        assert ds.attrs["experiment_sha256"] == hashlib.sha256(commented.encode()).hexdigest()
        for name, values in before.items():
            np.testing.assert_array_equal(ds[name].values, values)
