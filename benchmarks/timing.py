"""Wall-clock measurements: best-of-N timing in this process, and measurements in fresh subprocesses.

The benchmark process runs on one thread (:func:`single_thread_environment`
is applied before numpy is imported); measurements that need a clean
interpreter (first-call compile time) or several cores (ensembles) run in
subprocesses started by :func:`run_subprocess`.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Generic, TypeVar

THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS", "NUMBA_NUM_THREADS")
"""Environment variables that set the thread pools of BLAS, OpenMP and numba."""
REPOSITORY = Path(__file__).resolve().parent.parent
"""The repository root (the benchmarks run from a checkout)."""

T = TypeVar("T")


def single_thread_environment(environment: dict[str, str] | None = None, threads: int = 1) -> dict[str, str]:
    """Set every thread-pool variable of ``environment`` (default: ``os.environ``) to ``threads``.

    Must run before numpy is imported to take effect in this process.
    """
    target = os.environ if environment is None else environment
    for name in THREAD_VARIABLES:
        target[name] = str(threads)
    return target


@dataclass(frozen=True)
class Timing(Generic[T]):
    """Best-of-N wall time of a call.

    Attributes
    ----------
    best : float
        Shortest wall time of the timed calls, s.
    runs : int
        Number of timed calls after the untimed warm-up call (0: the
        measurement is the single cold call).
    result : object
        The warm-up call's return value.
    """

    best: float
    runs: int
    result: T


def best_of(call: Callable[[], T], repeats: int, budget: float = 30.0) -> Timing[T]:
    """Time ``call``: one warm-up call, then up to ``repeats`` timed calls.

    Parameters
    ----------
    call : callable
        The work to time (no arguments).
    repeats : int
        Largest number of timed calls. With 0, or when the warm-up call alone
        took longer than ``budget``, the warm-up call is the measurement
        (``runs`` = 0: one cold call).
    budget : float
        Stop repeating once the calls have taken this long in total, s.
    """
    start = time.perf_counter()
    result = call()
    cold = time.perf_counter() - start
    if repeats <= 0 or cold >= budget:
        return Timing(cold, 0, result)
    times: list[float] = []
    while len(times) < repeats and cold + sum(times) < budget:
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return Timing(min(times), len(times), result)


def run_subprocess(
    code: str, threads: int = 1, extra_env: dict[str, str] | None = None, timeout: float = 3600.0, monitor_memory: bool | str = False
) -> dict[str, Any]:
    """Run Python ``code`` in a fresh interpreter and return the JSON object it prints last.

    Parameters
    ----------
    code : str
        A script that prints one JSON object as its last line of output.
    threads : int
        Value of the thread-pool variables in the child.
    extra_env : dict, optional
        More environment variables for the child.
    timeout : float
        Seconds before the child is killed (:class:`subprocess.TimeoutExpired` is raised).
    monitor_memory : bool or str
        Sample, every 0.1 s from this process, the memory of the child and
        its own children, and add the peaks to the result (see
        :class:`MemoryPeaks`): ``True`` or ``"pss"`` the proportional set
        size, ``"rss"`` the resident set size (an upper bound that counts
        shared pages in every process, and far cheaper to read: a few
        microseconds a process instead of milliseconds).
    """
    environment = single_thread_environment(dict(os.environ), threads)
    environment.update(extra_env or {})
    environment["PYTHONPATH"] = os.pathsep.join(filter(None, [str(REPOSITORY), environment.get("PYTHONPATH", "")]))
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        child = subprocess.Popen([sys.executable, "-c", code], stdout=out, stderr=err, env=environment, cwd=REPOSITORY, text=True)
        peaks = MemoryPeaks(child.pid, proportional=monitor_memory != "rss") if monitor_memory else None
        _wait(child, timeout, peaks)
        out.seek(0)
        err.seek(0)
        lines = [line for line in out.read().splitlines() if line.startswith("{")]
        if child.returncode != 0 or not lines:
            raise RuntimeError(f"benchmark subprocess failed ({child.returncode}): {err.read().strip()[-2000:]}")
    result = json.loads(lines[-1])
    if peaks is not None:
        result.update(peak_total=peaks.total, peak_main=peaks.main)
    return result


def _wait(child: subprocess.Popen, timeout: float, peaks: MemoryPeaks | None) -> None:
    """Wait for ``child`` (sampling its memory every 0.1 s if asked); kill it after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while child.poll() is None:
        if time.monotonic() > deadline:
            child.kill()
            child.wait()
            raise subprocess.TimeoutExpired(child.args, timeout)
        if peaks is not None:
            peaks.sample()
        time.sleep(0.1)


class MemoryPeaks:
    """Peak proportional set size (PSS, bytes) of a process and of its process tree, or resident set size (RSS).

    PSS divides the pages that processes share (e.g. after ``fork``) among
    them, so the sum over a process tree counts every page once; reading it
    costs milliseconds of CPU per process. RSS counts shared pages in every
    process that maps them (the sum is an upper bound) and costs microseconds.

    Attributes
    ----------
    main : int
        Peak of the process itself.
    total : int
        Peak of the sum over the process and its descendants.
    """

    def __init__(self, pid: int, proportional: bool = True) -> None:
        import psutil

        self._process = psutil.Process(pid)
        self._read = (lambda process: process.memory_full_info().pss) if proportional else (lambda process: process.memory_info().rss)
        self.main = self.total = 0

    def sample(self) -> None:
        """Read the PSS of the tree now and update the peaks (processes that end meanwhile are skipped)."""
        import psutil

        try:
            main = self._read(self._process)
            children = self._process.children(recursive=True)
        except psutil.Error:
            return
        total = main
        for child in children:
            try:
                total += self._read(child)
            except psutil.Error:
                continue
        self.main, self.total = max(self.main, main), max(self.total, total)
