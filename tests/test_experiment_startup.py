"""The start-up of an experiment run: which workers load the compiled kernels when, and which kernels are compiled."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from stochpound._memory import format_bytes
from stochpound.experiment import _runner
from tests.helpers import REPOSITORY


class _Client:
    """The two methods of a dask client the kernels' loading uses, recording what is submitted to which worker."""

    def __init__(self, hosts: dict[str, str]) -> None:
        self.hosts = hosts
        self.groups: list[list[str]] = []

    def scheduler_info(self) -> dict:
        return {"workers": {address: {"host": host} for address, host in self.hosts.items()}}

    def submit(self, function, spectrum, pure, workers):
        assert function is _runner.warm_up and pure is False
        return (workers[0], spectrum)


@pytest.fixture
def waits(monkeypatch):
    """The groups of workers :func:`_runner._load_solver` waits for, in order."""
    import distributed

    groups: list[list[tuple[str, bool]]] = []
    monkeypatch.setattr(distributed, "wait", lambda futures: groups.append(list(futures)))
    return groups


def test_a_scheduler_s_workers_load_one_per_host_first_then_the_others(waits):
    """Three workers on two hosts: one of each host compiles (or loads), then the third loads what its host's first compiled."""
    client = _Client({"tcp://a:1": "a", "tcp://a:2": "a", "tcp://b:1": "b"})
    assert _runner._load_solver(client, False, one_per_host_first=True) is client
    assert waits == [[("tcp://a:1", False), ("tcp://b:1", False)], [("tcp://a:2", False)]]


def test_local_workers_all_load_at_once(waits):
    """Local workers load what the run's own process compiled: all at once, with the spectrum's kernel when asked."""
    client = _Client({"tcp://127.0.0.1:1": "127.0.0.1", "tcp://127.0.0.1:2": "127.0.0.1"})
    _runner._load_solver(client, True, one_per_host_first=False)
    assert waits == [[("tcp://127.0.0.1:1", True), ("tcp://127.0.0.1:2", True)], []]


@pytest.mark.slow
def test_the_warm_up_compiles_the_spectrum_s_kernel_only_when_asked():
    """An experiment without [intensity] never measures a spectrum: its warm-up compiles the engine and the twin, not that kernel."""
    code = ("from stochpound.experiment._compute import warm_up\nfrom stochpound.motions import _spectrum\nfrom stochpound.solvers import twin\n"
            "warm_up(False)\nprint(len(_spectrum._spectrum_kernel.signatures), len(twin._recursion.signatures))\n"
            "warm_up(True)\nprint(len(_spectrum._spectrum_kernel.signatures))")
    # numba's own cache, as the session has it: a kernel loaded from the cache counts a signature as a compiled one does
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=900, env={**os.environ, "PYTHONPATH": str(REPOSITORY)})
    assert done.returncode == 0 and done.stdout.split() == ["0", "1", "1"], done.stderr


def test_a_small_run_given_no_workers_runs_in_this_process(tmp_path, monkeypatch):
    """No workers given: a run whose cases are estimated under IN_PROCESS_CPU_SECONDS of CPU runs in this process, without
    dask (said as it starts and in its report), and its estimate gives the store's data size without measuring the file
    (file_bytes, half a second of CPU); above it, the local cluster is chosen (not started here)."""
    from stochpound.experiment import _estimate, load_experiment, run_experiment
    from stochpound.experiment._estimate import cpu_seconds
    from stochpound.experiment._sources import resolve_motions
    from tests.helpers import write_experiment

    def measured(*arguments):
        raise AssertionError("a small run measured its store on its metadata")

    monkeypatch.setattr(_estimate, "file_bytes", measured)

    experiment = load_experiment(write_experiment(tmp_path))
    grids = {label: motion.grid for label, motion in resolve_motions(experiment).items()}
    estimated = cpu_seconds(experiment, grids, experiment.n_cases)
    assert 0 < estimated < _runner.IN_PROCESS_CPU_SECONDS and _runner.in_process(experiment, grids, experiment.n_cases)
    lines: list[str] = []
    report = run_experiment(experiment, progress=False, say=lines.append)
    assert report.complete and report.executor == "this process (no dask) for a small run", report.executor
    assert any(line.startswith("running in this process, without dask") for line in lines), lines
    data = sum(spec.dtype.itemsize * spec_size for spec, spec_size in _sizes(experiment, grids))
    assert f"store about {format_bytes(data)} of data before compression (and as much again in its .parts folder)" in lines[0], lines
    monkeypatch.setattr(_runner, "IN_PROCESS_CPU_SECONDS", estimated)
    assert not _runner.in_process(experiment, grids, experiment.n_cases)


def _sizes(experiment, grids):
    """Each variable of the experiment's store with its number of elements (the layout's, written out here)."""
    import math

    from stochpound.experiment._file_layout import layout

    store = layout(experiment, grids, 0)
    return [(spec, math.prod(store.sizes[d] for d in spec.dims)) for spec in store.specs]
