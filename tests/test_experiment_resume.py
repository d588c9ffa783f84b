"""Crash safety: a real ``experiment run`` killed with SIGKILL at several points resumes to the same store.

Also: N local dask workers give the same store as one process.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import xarray as xr

from stochpound._atomic import temporaries
from stochpound.experiment import load_experiment, run_experiment
from stochpound.experiment._parts import part_paths, parts_folder
from tests.helpers import N_CASES, assert_same_results, cli, cli_process, done_cases, invoke, quickstart_cell, write_experiment


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
    return temporaries(store.parent, store.name)


def _part_temporaries(store: Path) -> list[Path]:
    return temporaries(parts_folder(store))


def _check_after_kill(store: Path) -> int:
    """The store opens, and status counts exactly the finished parts."""
    with xr.open_dataset(store) as ds:
        assert int(ds.attrs["cases_total"]) == N_CASES
        assert int((ds["case_status"] == 1).sum()) + int((ds["reference_status"] == 1).sum()) == int(ds.attrs["cases_done"])
    done = done_cases(store)
    out = _status(str(store), "--all")
    assert f"{done}/{N_CASES} cases done, {N_CASES - done} missing" in out, out
    assert out.count("missing  ") == N_CASES - done
    with xr.open_dataset(store) as ds:  # status rebuilt the file from the parts
        assert int(ds.attrs["cases_done"]) == done
    return done


def _status(*args: str) -> str:
    """``stochpound experiment status ARGS``'s output, run in this process (the killed runs are real processes; reading what
    they left needs none)."""
    result = invoke("experiment", "status", *args)
    assert result.exit_code == 0, result.output
    return result.stdout


@pytest.mark.slow
def test_sigkill_at_several_points_then_resume(tmp_path, baseline):
    experiment = write_experiment(tmp_path)
    store = tmp_path / "small.nc"
    run = ("experiment", "run", str(experiment), "--workers", "0", "--quiet", "--batch", "1")
    small_parts = {"STOCHPOUND_EXPERIMENT_PART_CASES": "1"}  # a part per case: kill points between parts

    def parts() -> int:
        return done_cases(store)

    # 1. during the very first write of the store file, before any case: no store file yet
    process = cli_process(*run)
    _wait_for(lambda: _store_temporaries(store), process, "the first store write")
    _kill(process)
    assert not store.exists() and parts() == 0
    assert "0/27 cases done, 27 missing" in _status(str(store))

    # 2. after a few cases (parts written slowly so that the run is still going)
    process = cli_process(*run, env={**small_parts, "STOCHPOUND_EXPERIMENT_WRITE_DELAY": "0.1"})
    _wait_for(lambda: parts() >= 3, process, "three parts")
    _kill(process)
    first = _check_after_kill(store)
    assert 3 <= first < N_CASES

    # 3. in the middle of writing a part (between writing its temporary file and renaming it)
    process = cli_process(*run, env={**small_parts, "STOCHPOUND_EXPERIMENT_WRITE_DELAY": "0.3"})
    _wait_for(lambda: parts() > first and _part_temporaries(store), process, "a part write")
    _kill(process)
    assert _part_temporaries(store), "the kill should leave a stray temporary part"
    second = _check_after_kill(store)
    assert second > first

    # 4. in the middle of rebuilding the store file at a checkpoint (as often as the rebuilds' duration allows)
    process = cli_process(*run, "--checkpoint", "0", env=small_parts)
    _wait_for(lambda: parts() > second and _store_temporaries(store), process, "a checkpoint")
    _kill(process)
    third = _check_after_kill(store)
    assert third > second

    # 5. the rerun completes only the missing cases, and the store equals the uninterrupted one
    result = cli(*run)
    assert f"({N_CASES - third} this run, {third} before)" in result.stdout, result.stdout
    assert not _part_temporaries(store) and not _store_temporaries(store)
    assert parts() == N_CASES and len(part_paths(parts_folder(store))) <= N_CASES
    assert_same_results(baseline, store)


@pytest.mark.slow
def test_local_cluster_matches_one_process(tmp_path, baseline):
    experiment = write_experiment(tmp_path)
    result = cli("experiment", "run", str(experiment), "--workers", "2", "--batch", "2")
    assert "local dask cluster, 2 worker processes" in result.stdout
    assert_same_results(baseline, tmp_path / "small.nc")


#: One cell of the quick-start grid (gap 5 mm: impacts) under many short Kanai-Tajimi realizations: the batched path.
MANY_REALIZATIONS = quickstart_cell("""
[synthetic.kt]
count = 400
seed = 11
omega_g = 15.0
zeta_g = 0.6
pga = 3.0
envelope = "jennings"
duration = 2.0
dt = 0.02
""", gap=0.005)


@pytest.mark.slow
def test_a_large_run_killed_twice_resumes_to_the_same_store(tmp_path):
    """400 realizations, SIGKILLed twice mid-run (in one process, then on two local workers: the whole process
    group), then completed with other batches: the store equals an uninterrupted run's, and there is at most
    one part per 50 cases (the part size, lowered from 500 for a small run) plus one per run.

    The benchmark (``python -m benchmarks scaling``) does the same with 100 000 realizations."""
    whole = tmp_path / "whole"
    whole.mkdir()
    reference = run_experiment(load_experiment(write_experiment(whole, MANY_REALIZATIONS, "many.toml")), workers=0, progress=False, batch_size=50)
    assert reference.complete and reference.total == 800
    experiment = write_experiment(tmp_path, MANY_REALIZATIONS, "many.toml")
    store = tmp_path / "many.nc"
    run = [sys.executable, "-m", "stochpound", "experiment", "run", str(experiment), "--quiet"]
    env = {**os.environ, "STOCHPOUND_EXPERIMENT_PART_CASES": "50"}
    done = [0]
    for workers in ("0", "2"):
        process = subprocess.Popen([*run, "--workers", workers], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True, env=env)
        _wait_for(lambda: done_cases(store) > done[-1] + 50, process, "more parts", timeout=600)
        os.killpg(process.pid, signal.SIGKILL)
        process.wait(timeout=60)
        done.append(done_cases(store))
    assert 50 < done[1] < done[2] < 800
    result = cli(*run[3:], "--workers", "0", "--batch", "7", env=env)
    assert f"({800 - done[2]} this run, {done[2]} before)" in result.stdout, result.stdout
    assert len(part_paths(parts_folder(store))) <= 800 // 50 + 3
    assert_same_results(reference.store, store)
