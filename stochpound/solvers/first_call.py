"""The exact solver's engine called: its first call in a process compiles it, said and timed, and start-up times measured here.

:func:`run` is how the engine is called (:mod:`stochpound.solvers.driver`):
a process's first call compiles it, or loads it from numba's cache, in
:func:`~stochpound.solvers.compiling.engine_compile`.

numba compiles the event engine on a process's first call unless its
on-disk cache (``cache=True``) holds it; then the call takes about 15 s of CPU
(docs/benchmarks.md, "Start-up"; minutes on a loaded machine) instead of
milliseconds. A library should not print, so the
engine says it through ``logging``: one ``WARNING`` record of the logger
``stochpound.solvers`` before a compile (not when it loads from the cache),
which Python shows on stderr without any logging set up (its "last resort"
handler) and which ``logging.getLogger("stochpound").setLevel(logging.ERROR)``
silences (``experiment run --quiet`` does).

The durations of the start-up steps are measured as they happen and kept,
per machine, beside numba's cache of the engine (:data:`TIMINGS_FILE`): the
cold compile (``"compile"``), and the rest of an experiment run's start-up
(loading the solver, the store, a local dask cluster; named by the runner).
The runner's estimate adds the last measured ones to the run time
(:func:`measured`); a step not yet measured on this machine is said to be so.
"""

from __future__ import annotations

import contextlib
import json
import logging
import time
from collections.abc import Iterator
from pathlib import Path

import numba

from stochpound.solvers.compiling import engine_compile, numba_default_requested
from stochpound.solvers.engine import run_engine

_LOG = logging.getLogger("stochpound.solvers")

TIMINGS_FILE = "stochpound-startup.json"
"""Name of the file of measured start-up durations, in the folder of numba's cache of the engine."""


def run(*arguments: object) -> int:
    """Call :func:`~stochpound.solvers.engine.run_engine`: a process's first call compiles it (or loads it from numba's cache)
    in :func:`~stochpound.solvers.compiling.engine_compile`, announced and timed when the cache is cold (:func:`announced_compile`)."""
    if _COMPILED:
        return run_engine(*arguments)
    with announced_compile(), (contextlib.nullcontext() if numba_default_requested() else engine_compile()):
        status = run_engine(*arguments)
    _COMPILED.append(True)
    return status


_COMPILED: list[bool] = []


def engine_cached() -> bool:
    """True if numba's cache holds the engine compiled from its current source (read from the cache's index, no compilation)."""
    try:
        return bool(run_engine._cache._cache_file._load_index())  # numba's cache index: empty if absent or stale
    except Exception:  # noqa: BLE001 - numba's private API changed: say the compile may happen
        return False


def measured(step: str) -> float | None:
    """The last duration of a start-up step measured on this machine (s), or None if never measured.

    Parameters
    ----------
    step : str
        ``"compile"`` (the engine's compile into an empty cache) or the
        name of another step (the experiment runner's).
    """
    path = _timings_path()
    try:
        value = json.loads(path.read_text()).get(step) if path is not None else None
    except (OSError, ValueError, AttributeError):
        return None
    return float(value) if isinstance(value, (int, float)) else None


def record(step: str, seconds: float) -> None:
    """Keep the duration of a start-up step (s) as the last measured on this machine (nothing if the cache folder is not writable)."""
    path = _timings_path()
    if path is None:
        return
    try:
        timings = json.loads(path.read_text()) if path.is_file() else {}
        timings = timings if isinstance(timings, dict) else {}
        path.write_text(json.dumps({**timings, step: round(seconds, 2)}))
    except (OSError, ValueError):
        return


def compile_text() -> str:
    """How long the engine's compile takes here: the last measured duration, or that it was never measured on this machine."""
    seconds = measured("compile")
    if seconds is None:
        return "not yet timed on this machine: about 15 s on an idle one, minutes on a loaded one"
    return f"{seconds:.0f} s when last timed on this machine"


@contextlib.contextmanager
def announced_compile() -> Iterator[None]:
    """A block that calls the engine first in a process: with a cold cache, it is announced (one log line) and timed.

    The engine's first call runs in one; so does the experiment runner's
    warm-up, which compiles the engine and the few kernels runs also use (the
    whole warm-up is then timed, and the engine's own call inside says nothing more).
    """
    cold = not _OPEN and not numba.config.DISABLE_JIT and not engine_cached()
    if cold:
        _LOG.warning("stochpound: compiling the exact solver's engine (numba's cache of it is empty; %s); "
                     "later calls, and later processes, load it from the cache", compile_text())
    started = time.perf_counter()
    _OPEN.append(True)
    try:
        yield
    finally:
        _OPEN.pop()
    if cold:
        record("compile", time.perf_counter() - started)


_OPEN: list[bool] = []


def _timings_path() -> Path | None:
    try:
        return Path(run_engine._cache._cache_path) / TIMINGS_FILE  # numba's cache folder of the engine (private: it may move)
    except Exception:  # noqa: BLE001 - numba's private API changed: nothing is measured across processes
        return None
