"""A real dask scheduler and two workers on 127.0.0.1 run an experiment via ``--scheduler``: same store as one process."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from stochpound.experiment import load_experiment, run_experiment
from tests.helpers import assert_same_results, cli, write_experiment

pytestmark = pytest.mark.slow

DASK = str(Path(sys.executable).with_name("dask"))


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _wait_for_port(port: int, processes: list[subprocess.Popen], timeout: float = 60.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        for process in processes:
            if process.poll() is not None:
                raise AssertionError(f"a dask process exited early: {process.communicate()}")
        with socket.socket() as sock:
            if sock.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.1)
    raise AssertionError("the dask scheduler did not start")


@pytest.fixture
def cluster(tmp_path):
    """A scheduler and two single-threaded workers, stopped afterwards whatever happens."""
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = dict(os.environ)
    logs = tmp_path / "dask-logs"
    logs.mkdir()
    processes: list[subprocess.Popen] = []

    def start(name: str, *args: str) -> None:
        log = open(logs / f"{name}.log", "w")
        processes.append(subprocess.Popen([DASK, *args], stdout=log, stderr=subprocess.STDOUT, env=env, cwd=tmp_path, start_new_session=True))

    try:
        start("scheduler", "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard")
        _wait_for_port(port, processes)
        for i in range(2):
            start(f"worker{i}", "worker", address, "--host", "127.0.0.1", "--nthreads", "1", "--nworkers", "1", "--no-dashboard", "--name", f"test-worker-{i}")
        yield address
    finally:
        for process in reversed(processes):
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGTERM)
        for process in processes:
            try:
                process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait(timeout=10)


def test_scheduler_and_two_workers_give_the_same_store(tmp_path, cluster):
    local = tmp_path / "local"
    local.mkdir()
    reference = run_experiment(load_experiment(write_experiment(local)), workers=0, progress=False)
    remote = tmp_path / "remote"
    remote.mkdir()
    experiment = write_experiment(remote)
    result = cli("experiment", "run", str(experiment), "--scheduler", cluster, "--batch", "3")
    assert f"dask scheduler {cluster}" in result.stdout and "complete: 27/27" in result.stdout, result.stdout
    assert_same_results(reference.store, remote / "small.nc")
    # both workers took part
    from distributed import Client

    with Client(cluster, timeout="20s") as client:
        assert len(client.scheduler_info()["workers"]) == 2
