"""The quick start's start-up, from an empty and from a warm numba cache: ``python -m benchmarks startup``.

Runs the README's quick start (``experiments/quickstart.toml`` with the
default workers, into a temporary store: wherever the tree runs it, a
local dask cluster of one worker per core or, for a run this small, the
process itself) in fresh
processes: first with numba's cache in an empty folder (``NUMBA_CACHE_DIR``:
the first run on a new machine compiles the solver), then again with the
cache that run filled. Each run is timed from its process's start (the
interpreter, the imports and the experiment file's checks included) to the
first batch of cases submitted, the wait a user has before any case runs;
the runner's own start-up (:attr:`stochpound.experiment.RunReport.setup`,
what ``experiment run`` prints as "start-up") and the running time are
given too. Targets (issue 48): on an idle 2-core machine, at most 15 s
with an empty cache and 3 s with a warm one.

With ``--against REV`` an earlier revision of the project (``git archive``)
is timed in the same session, alternating with this tree round by round:
on a shared machine the ratios of the two are what the measurements show
reliably. It rewrites the section "Start-up" of ``docs/benchmarks.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from benchmarks import report
from benchmarks.compare import trees
from benchmarks.sections import Section
from benchmarks.timing import REPOSITORY

SECTION = Section("<!-- start-up: start -->", "<!-- start-up: end -->")
"""This benchmark's section of docs/benchmarks.md."""
EXPERIMENT = "experiments/quickstart.toml"
"""The README's quick start, relative to the tree timed."""
TARGETS = {"empty": 15.0, "warm": 3.0}
"""Most seconds from the process's start to the first case, by numba cache, on an idle 2-core machine (issue 48)."""

PROBE = """
import json, resource, sys, time
import psutil
born = psutil.Process().create_time()
from stochpound.experiment import _runner, load_experiment, run_experiment
cpu = []
def _cpu_then_bar(*arguments, bar=_runner._progress_bar):
    cpu.append(sum(u.ru_utime + u.ru_stime for u in map(resource.getrusage, (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))))
    return bar(*arguments)
_runner._progress_bar = _cpu_then_bar  # called by the runner as the first case is submitted, right after the start-up is timed
experiment = load_experiment(sys.argv[1])
began = time.time()
report = run_experiment(experiment, sys.argv[2], progress=False)
assert report.complete, report
print(json.dumps({"first_case": began - born + report.setup, "before_run": began - born, "setup": report.setup,
                  "running": report.elapsed - report.setup, "executor": report.executor, "cpu": cpu[0]}))
"""
"""Run in a fresh interpreter: the quick start into the store ``argv[2]``; prints its times (s) as JSON, with ``cpu``, the CPU time
of the process and of the child processes it waited for, up to the first case."""


def parse_arguments(argv: list[str] | None) -> argparse.Namespace:
    """Options of ``python -m benchmarks startup``."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks startup", description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="rounds, each a run with an empty cache then one with the cache it filled (default 3)")
    parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "benchmarks.md", help="the Markdown file whose section is rewritten")
    parser.add_argument("--against", metavar="REV", default=None, help="also time revision REV of this repository, alternating round by round")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Measure and rewrite the section of ``--out``."""
    arguments, started, info = parse_arguments(argv), time.perf_counter(), report.machine()
    with tempfile.TemporaryDirectory(prefix="stochpound-startup-") as folder:
        rounds = measure(trees(arguments.against, Path(folder)), arguments.rounds, Path(folder))
    results = {"rounds": rounds, "elapsed": time.perf_counter() - started, "load_end": f"{os.getloadavg()[0]:.2f}"}
    SECTION.write(arguments.out, section(results, info))
    print(f"wrote the section 'Start-up' of {arguments.out} in {results['elapsed']:.0f} s")
    return 0


def measure(trees: dict[str, Path], rounds: int, folder: Path) -> dict[str, list[dict[str, Any]]]:
    """Each tree's quick start with an empty cache, then with the cache it filled, in alternating rounds."""
    measured: dict[str, list[dict[str, Any]]] = {name: [] for name in trees}
    for round_ in range(rounds):
        for index, (name, tree) in enumerate(trees.items()):
            cache = folder / f"cache-{round_}-{index}"
            for state in ("empty", "warm"):
                times = run_quickstart(tree, cache, folder / f"store-{round_}-{index}-{state}.nc")
                measured[name].append({"round": round_ + 1, "cache": state, **times})
                print(f"round {round_ + 1}, {name}, {state} cache: {json.dumps(times)}", flush=True)
    return measured


def run_quickstart(tree: Path, cache: Path, store: Path) -> dict[str, Any]:
    """The quick start of ``tree`` in a fresh interpreter with numba's cache in ``cache``: its times (s) and the load average before it."""
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(tree)}
    load = os.getloadavg()[0]
    done = subprocess.run([sys.executable, "-c", PROBE, EXPERIMENT, str(store)], cwd=tree, env=environment, capture_output=True, text=True, timeout=1800)
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    if done.returncode != 0 or not lines:
        raise RuntimeError(f"the quick start failed ({done.returncode}): {done.stderr.strip()[-2000:]}")
    return {**json.loads(lines[-1]), "load": round(load, 2)}


def section(results: dict[str, Any], info: dict[str, str]) -> str:
    """The Markdown section, markers included."""
    rounds = results["rounds"]
    names = list(rounds)
    lines = [
        SECTION.start,
        "## Start-up",
        "",
        f"The README's quick start (`stochpound experiment run {EXPERIMENT}`, default workers) in fresh processes, "
        "first with numba's cache in an empty folder, then with the cache that run filled; "
        f"commit {info['commit']}, {info['date']}, in {results['elapsed']:.0f} s (load average {info['load average (1 min) at start']} "
        f"at the start, {results['load_end']} at the end). *First case*: from the process's start (interpreter, imports and the "
        "experiment's checks included) to the first batch submitted; *start-up*: the runner's own (what `experiment run` prints); "
        "*load*: the 1-minute load average before the run. Other work on the machine slows every run (with a load above the number of cores, "
        "several times over), while the targets are an idle machine's: on a shared machine the ratios of two trees timed in the same session "
        "(`--against`) are what the runs show reliably. `python -m benchmarks startup [--against REV]` rewrites this section.",
        "",
        "Where the cases ran: " + "; ".join(f"{name}: {_executors(rounds[name])}" for name in names) + ".",
        "",
        "| tree | round | numba cache | first case (s) | of which start-up (s) | CPU to the first case (s) | running (s) | load |",
        "|---|---|---|---:|---:|---:|---:|---:|",
    ]
    for name in names:
        for row in rounds[name]:
            cpu = f"{row['cpu']:.1f}" if "cpu" in row else "–"
            lines.append(f"| {name} | {row['round']} | {row['cache']} | {row['first_case']:.1f} | {row['setup']:.1f} | {cpu} | {row['running']:.1f} | {row['load']:.2f} |")
    lines += ["", "Medians of the first case, s:", "", "| tree | empty cache | warm cache | target (empty / warm, idle machine) |", "|---|---:|---:|---|"]
    for name in names:
        empty, warm = (_median(rounds[name], state) for state in ("empty", "warm"))
        lines.append(f"| {name} | {empty:.1f} | {warm:.1f} | ≤ {TARGETS['empty']:g} s / ≤ {TARGETS['warm']:g} s |")
    if len(names) == 2:
        this, earlier = names
        ratios = [f"{_median(rounds[this], state) / _median(rounds[earlier], state):.2f}× with {article} {state} cache"
                  for state, article in (("empty", "an"), ("warm", "a"))]
        lines += ["", f"This tree against {earlier}, measured in the same session: {' and '.join(ratios)} (medians of the first case)."]
        if all("cpu" in row for name in names for row in rounds[name]):
            cpu = [f"{_median(rounds[this], state, 'cpu') / _median(rounds[earlier], state, 'cpu'):.2f}× with {article} {state} cache"
                   for state, article in (("empty", "an"), ("warm", "a"))]
            lines += [f"CPU time to the first case (all the run's processes, less sensitive to other work on the machine): {' and '.join(cpu)}."]
    lines += [SECTION.end]
    return "\n".join(lines) + "\n"


def _median(rows: list[dict[str, Any]], state: str, key: str = "first_case") -> float:
    return statistics.median(row[key] for row in rows if row["cache"] == state)


def _executors(rows: list[dict[str, Any]]) -> str:
    """The executors a tree's runs reported (what ``experiment run`` prints after "on")."""
    return ", ".join(dict.fromkeys(row.get("executor", "?") for row in rows))
