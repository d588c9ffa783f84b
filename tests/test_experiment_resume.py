"""Crash safety: a real ``experiment run`` killed with SIGKILL at several points resumes to the same store.

Also: N local dask workers give the same store as one process.
"""

from __future__ import annotations

import signal
import time
from pathlib import Path

import pytest
import xarray as xr

from stochpound.experiment import load_experiment, run_experiment
from stochpound.experiment.parts import part_ids, parts_folder
from tests.test_experiment_helpers import N_CASES, assert_same_results, cli, cli_process, write_experiment


@pytest.fixture(scope="module")
def baseline(tmp_path_factory):
    """The small experiment run uninterrupted in one process."""
    folder = tmp_path_factory.mktemp("baseline")
    report = run_experiment(load_experiment(write_experiment(folder)), workers=0, progress=False)
    assert report.complete
    return report.store


def _wait_for(condition, process, what: str, timeout: float = 180.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        if process.poll() is not None:
            raise AssertionError(f"the run ended before the kill point ({what}): {process.communicate()}")
        if time.monotonic() > deadline:
            process.kill()
            raise AssertionError(f"kill point ({what}) not reached in time")
        time.sleep(0.002)


def _kill(process) -> None:
    process.send_signal(signal.SIGKILL)
    process.wait(timeout=30)
    assert process.returncode == -signal.SIGKILL


def _store_temporaries(store: Path) -> list[Path]:
    return list(store.parent.glob(f".{store.name}.*.tmp"))


def _part_temporaries(store: Path) -> list[Path]:
    return list(parts_folder(store).glob(".tmp-*"))


def _check_after_kill(store: Path) -> int:
    """The store opens, and status counts exactly the finished parts."""
    with xr.open_dataset(store) as ds:
        assert int(ds.attrs["cases_total"]) == N_CASES
        assert int((ds["case_status"] == 1).sum()) + int((ds["reference_status"] == 1).sum()) == int(ds.attrs["cases_done"])
    done = len(part_ids(parts_folder(store)))
    out = cli("experiment", "status", str(store), "--all").stdout
    assert f"{done}/{N_CASES} cases done, {N_CASES - done} missing" in out, out
    assert out.count("missing  ") == N_CASES - done
    with xr.open_dataset(store) as ds:  # status rebuilt the file from the parts
        assert int(ds.attrs["cases_done"]) == done
    return done


def test_sigkill_at_several_points_then_resume(tmp_path, baseline):
    experiment = write_experiment(tmp_path)
    store = tmp_path / "small.nc"
    run = ("experiment", "run", str(experiment), "--workers", "0", "--quiet")

    def parts() -> int:
        return len(part_ids(parts_folder(store)))

    # 1. during the very first write of the store file, before any case: no store file yet
    process = cli_process(*run)
    _wait_for(lambda: _store_temporaries(store), process, "the first store write")
    _kill(process)
    assert not store.exists() and parts() == 0
    assert "0/27 cases done, 27 missing" in cli("experiment", "status", str(store)).stdout

    # 2. after a few cases (parts written slowly so that the run is still going)
    process = cli_process(*run, env={"STOCHPOUND_EXPERIMENT_WRITE_DELAY": "0.1"})
    _wait_for(lambda: parts() >= 3, process, "three parts")
    _kill(process)
    first = _check_after_kill(store)
    assert 3 <= first < N_CASES

    # 3. in the middle of writing a part (between writing its temporary file and renaming it)
    process = cli_process(*run, env={"STOCHPOUND_EXPERIMENT_WRITE_DELAY": "0.3"})
    _wait_for(lambda: parts() > first and _part_temporaries(store), process, "a part write")
    _kill(process)
    assert _part_temporaries(store), "the kill should leave a stray temporary part"
    second = _check_after_kill(store)
    assert second > first

    # 4. in the middle of rebuilding the store file at a checkpoint (one after every case)
    process = cli_process(*run, "--checkpoint", "0")
    _wait_for(lambda: parts() > second and _store_temporaries(store), process, "a checkpoint")
    _kill(process)
    third = _check_after_kill(store)
    assert third > second

    # 5. the rerun completes only the missing cases, and the store equals the uninterrupted one
    result = cli(*run)
    assert f"({N_CASES - third} this run, {third} before)" in result.stdout, result.stdout
    assert not _part_temporaries(store) and not _store_temporaries(store)
    assert parts() == N_CASES
    assert_same_results(baseline, store)


def test_local_cluster_matches_one_process(tmp_path, baseline):
    experiment = write_experiment(tmp_path)
    result = cli("experiment", "run", str(experiment), "--workers", "2", "--batch", "2")
    assert "local dask cluster, 2 worker processes" in result.stdout
    assert_same_results(baseline, tmp_path / "small.nc")
