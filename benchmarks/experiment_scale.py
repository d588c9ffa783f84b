"""The experiment layer at scale: ``python -m benchmarks scaling``.

The getting-started pair (``experiments/scenes/study_b1_isolated_flexible.toml``:
Building 1 on a sliding base, μ = 0.2, next to the flexible Building 2, gap
2 cm, the quick-start file's grid point but for its contacts' stiffness, which
the scene file rounds at 5e-5) under 20 s Kanai–Tajimi
realizations, summaries and impacts only, run by ``stochpound experiment run``
on local workers for 10³, 10⁴, 10⁵ (and 10⁶) realizations, against the same
case run alone (warm ``simulate`` calls) in the same session:

* realizations per second and cost per realization (start-up excluded, and
  the whole command), peak memory of all the run's processes (proportional
  set size, sampled every 0.1 s), files beside the store and its size;
* a run of 10⁵ realizations killed twice (SIGKILL to the client and its
  workers) and resumed, compared bit for bit with the uninterrupted one;
* questions answered with dask on the largest store (its time and peak memory).

It rewrites the "Experiments at scale" section of ``docs/benchmarks.md``
(between :data:`START` and :data:`END`; the rest of the file is the main
suite's, which keeps this section when it rewrites the file).
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

from benchmarks import report
from benchmarks.sections import Section
from benchmarks.timing import REPOSITORY, run_subprocess, single_thread_environment

START = "<!-- experiments at scale: start -->"
END = "<!-- experiments at scale: end -->"
SECTION = Section(START, END)
"""This benchmark's section of docs/benchmarks.md."""
SIZES = (1_000, 10_000, 100_000, 1_000_000)
SCENE = REPOSITORY / "experiments" / "scenes" / "study_b1_isolated_flexible.toml"
"""The getting-started pair: Building 1 on a sliding base (μ = 0.2) next to the flexible Building 2, gap 2 cm."""
EXPERIMENT = """
[experiment]
name = "{name}"
description = "experiments at scale: the getting-started pair, {count} Kanai-Tajimi realizations"
scene = "{scene}"
studied = "B1"

[grid]
gap = [0.02]
[synthetic.kt_firm]
type = "kanai_tajimi"
count = {count}
seed = 2024
omega_g = 15.0
zeta_g = 0.6
pga = 3.0
envelope = "jennings"
duration = 20.0
dt = 0.02

[output]
impacts = true
"""
"""The benchmark's experiment: :data:`SCENE` under the quick-start file's Kanai–Tajimi ensemble with ``count`` realizations, summaries and impacts only."""


def parse_arguments(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python -m benchmarks scaling", description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=list(SIZES), help="numbers of realizations (default: 1e3 1e4 1e5 1e6)")
    parser.add_argument("--workers", type=int, default=2, help="local dask workers (default 2)")
    parser.add_argument("--kill-check", type=int, default=100_000, help="realizations of the killed-twice run (0: none; default 1e5)")
    parser.add_argument("--single-runs", type=int, default=500, help="warm simulate calls of the single-run rate")
    parser.add_argument("--work", type=Path, default=None, help="folder for the stores (default: a temporary folder)")
    parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "benchmarks.md", help="the document whose section is rewritten")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Run the measurements and rewrite the section of ``--out``."""
    arguments = parse_arguments(argv)
    info = report.machine()
    started = time.perf_counter()

    def log(message: str) -> None:
        print(f"[{time.perf_counter() - started:7.1f} s] {message}", flush=True)

    with tempfile.TemporaryDirectory(prefix="stochpound-scaling-", dir=arguments.work) as folder:
        results = measure(Path(folder), arguments, log)
    results["elapsed"] = time.perf_counter() - started
    info["load average (1 min) at end"] = f"{os.getloadavg()[0]:.2f}"
    SECTION.write(arguments.out, section(results, info))
    log(f"wrote the section 'Experiments at scale' of {arguments.out}")
    return 0


def measure(folder: Path, arguments: argparse.Namespace, log: Callable[[str], None]) -> dict[str, Any]:
    """Every measurement of the section, in one session."""
    sizes = sorted(arguments.sizes)
    results: dict[str, Any] = {"workers": arguments.workers, "runs": []}
    for size in sizes:
        log(f"single run: {arguments.single_runs} warm simulate calls")
        alone = single(folder, arguments.single_runs)
        log(f"  {json.dumps(alone)}")
        log(f"experiment: {size} realizations on {arguments.workers} workers")
        results["runs"].append({**experiment_run(folder, size, arguments.workers), "single": alone})
        log(f"  {json.dumps(results['runs'][-1])}")
        if size == arguments.kill_check:
            log(f"the same run killed twice and resumed ({size} realizations)")
            results["kill"] = killed_twice(folder, size, arguments.workers)
            log(f"  {json.dumps(results['kill'])}")
    largest = folder / f"cell_{sizes[-1]}.nc"
    log(f"analysis of the {sizes[-1]}-realization store with dask")
    results["analysis"] = run_subprocess(f"from benchmarks import probes; probes.store_analysis({str(largest)!r})", monitor_memory="rss", timeout=7200)
    return results


def experiment_file(folder: Path, count: int, name: str) -> Path:
    """Write the benchmark's experiment: :data:`SCENE` (flexible neighbour, gap 2 cm, μ = 0.2), ``count`` realizations."""
    path = folder / f"{name}.toml"
    path.write_text(EXPERIMENT.format(name=name, count=count, scene=SCENE.as_posix()))
    return path


def single(folder: Path, runs: int) -> dict[str, Any]:
    """The single warm run's cost per realization, in a fresh single-threaded process."""
    path = experiment_file(folder, runs, "single")
    return run_subprocess(f"from benchmarks import probes; probes.single_cell({str(path)!r}, {runs})")


def experiment_run(folder: Path, count: int, workers: int) -> dict[str, Any]:
    """One uninterrupted run into ``cell_<count>.nc``, with the peak memory of its process tree and the files it leaves."""
    path = experiment_file(folder, count, f"cell_{count}")
    store = folder / f"cell_{count}.nc"
    code = f"from benchmarks import probes; probes.experiment_run({str(path)!r}, {workers}, {str(store)!r})"
    measured = run_subprocess(code, monitor_memory="rss", timeout=6 * 3600)
    measured.update(count=count, files=files_beside(store), store_bytes=store.stat().st_size)
    return measured


def files_beside(store: Path) -> int:
    """Files the run left beside its store: in the store's folder (but the store and the experiment files) and in its parts folder."""
    folder = store.parent
    parts = folder / f"{store.name}.parts"
    own = [p for p in folder.iterdir() if p.is_file() and p != store and p.suffix != ".toml"]
    return len(own) + sum(1 for p in parts.iterdir() if p.is_file())


def killed_twice(folder: Path, count: int, workers: int) -> dict[str, Any]:
    """The run killed (client and workers, SIGKILL) at about a third and two thirds of its cases, then resumed."""
    path = experiment_file(folder, count, f"killed_{count}")
    store = folder / f"killed_{count}.nc"
    command = [sys.executable, "-m", "stochpound", "experiment", "run", str(path), "--workers", str(workers), "--quiet"]
    total = 2 * count
    done_at_kill = []
    for fraction in (1 / 3, 2 / 3):
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True, env=_environment(), cwd=REPOSITORY)
        while _done(store) < fraction * total and process.poll() is None:
            time.sleep(2.0)
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
        process.wait()
        done_at_kill.append(_done(store))
    finished = subprocess.run(command, capture_output=True, text=True, env=_environment(), cwd=REPOSITORY)
    identical, difference = same_stores(folder / f"cell_{count}.nc", store)
    return {"count": count, "done_at_kills": done_at_kill, "resumed": finished.stdout.strip().splitlines()[:1], "identical": identical, "difference": difference}


def _environment() -> dict[str, str]:
    environment = single_thread_environment(dict(os.environ))
    environment["PYTHONPATH"] = os.pathsep.join(filter(None, [str(REPOSITORY), environment.get("PYTHONPATH", "")]))
    return environment


def _done(store: Path) -> int:
    """Finished cases in a store's parts."""
    from stochpound.experiment import Experiment, PartsIndex, parts_folder, read_experiment_json

    folder = parts_folder(store)
    try:
        return PartsIndex.scan(Experiment(read_experiment_json(folder).definition), folder).n_done
    except Exception:  # noqa: BLE001 - not there yet
        return 0


def same_stores(first: Path, second: Path) -> tuple[bool, str]:
    """Whether every variable of two stores is bitwise equal, read block by block (and the first difference)."""
    import numpy as np
    import xarray as xr

    with xr.open_dataset(first, chunks={}) as a, xr.open_dataset(second, chunks={}) as b:
        if sorted(a.variables) != sorted(b.variables):
            return False, "different variables"
        for name in sorted(a.variables):
            x, y = a[name].variable, b[name].variable
            if x.shape != y.shape or x.dtype != y.dtype:
                return False, f"{name}: shape or dtype"
            step = 1_000_000
            flat_x, flat_y = x.data.reshape(-1), y.data.reshape(-1)
            for start in range(0, flat_x.shape[0], step):
                u, v = np.asarray(flat_x[start : start + step]), np.asarray(flat_y[start : start + step])
                same = np.array_equal(u.view(np.uint8), v.view(np.uint8)) if u.dtype.kind == "f" else np.array_equal(u, v)
                if not same:
                    return False, f"{name}: differs in elements {start}..{start + step}"
    return True, ""


# ------------------------------------------------------------------ the document


def section(results: dict[str, Any], info: dict[str, str]) -> str:
    """The section's Markdown."""
    rows = [_row(run) for run in results["runs"]]
    parts = [
        START,
        "## Experiments at scale",
        _introduction(results, info),
        report._table(
            ["realizations", "cases", "realizations/s", "ms per realization", "single run (ms)", "× single run", "whole command (s)",
             "start-up (s)", "CPU per realization (ms), workers + client", "× single run's CPU", "peak memory, all processes",
             "files beside the store", "store"],
            rows,
        ),
        _criteria(results),
        _kill_paragraph(results.get("kill")),
        _analysis_paragraph(results),
        END,
    ]
    return "\n\n".join(p.strip() for p in parts if p) + "\n"


def _introduction(results: dict[str, Any], info: dict[str, str]) -> str:
    one = results["runs"][-1]["single"]
    costs = [_single_cost(run) * 1e3 for run in results["runs"]]
    machine = f"{info['CPU']}, {info['cores']} cores, {info['memory']}; commit {info['commit']}, {info['date']}"
    load = f"load average {info['load average (1 min) at start']} at the start, {info['load average (1 min) at end']} at the end"
    return (
        "Generated by `python -m benchmarks scaling` "
        f"in {results['elapsed'] / 60:.1f} min on {machine} ({load}). "
        "The experiment is the getting-started pair (experiments/scenes/study_b1_isolated_flexible.toml: B1 on a sliding base, "
        "μ = 0.2, next to the flexible B2, gap 2 cm) under 20 s Kanai–Tajimi realizations (firm soil, expected PGA 3 m/s², Jennings envelope, dt 0.02 s), "
        "summaries and impacts only; each realization also runs the fixed-base reference. "
        f"`stochpound experiment run` ran it on {results['workers']} local worker processes.\n\n"
        "**Single run**: the same case alone in one fresh process, measured just before each experiment run (the machine is shared, "
        f"so its speed drifts): warm `stochpound.simulate` (mean of {one['runs']} realizations) plus its motion generated 64 at a time "
        f"(one at a time it costs {one['motion_single'] * 1e3:.3g} ms instead of {one['motion_batched'] * 1e3:.3g} ms in the last "
        f"measurement): {min(costs):.3g}–{max(costs):.3g} ms per realization; {one['mean_impacts']:.2f} impacts per realization on average.\n\n"
        "Per realization below: the run's wall time after its start-up (the store's first write, the local cluster's start, "
        "loading the compiled solver in every worker) divided by the realizations; the whole command's time is given too. The CPU time of "
        "all the command's processes per realization (start-up included) shows the work itself, independent of how much of "
        "the shared machine the run got: with the two cores to itself, the run's wall time per realization would be about "
        "half of it. "
        "Memory: peak of the resident set size (RSS) summed over the command's process and its workers, sampled every 0.1 s "
        "(an upper bound: pages the processes share are counted in each)."
    )


def _per_realization(run: dict[str, Any]) -> float:
    return (run["elapsed"] - run["setup"]) / run["count"]


def _single_cost(run: dict[str, Any]) -> float:
    """The single run's cost per realization measured before ``run``: warm simulate plus the motion (generated 64 at a time), s."""
    return run["single"]["simulate"] + run["single"]["motion_batched"]


def _cpu(run: dict[str, Any]) -> float:
    """CPU time of the whole command (client and workers, start-up included) per realization, s."""
    return (run["cpu_client"] + run["cpu_workers"]) / run["count"]


def _single_cpu(run: dict[str, Any]) -> float:
    """The single run's CPU time per realization (simulate's CPU time plus the batched motion's wall time), s."""
    return run["single"]["simulate_cpu"] + run["single"]["motion_batched"]


def _row(run: dict[str, Any]) -> list[Any]:
    cost, single_cost = _per_realization(run), _single_cost(run)
    return [
        f"{run['count']:,}", f"{run['total']:,}", f"{1 / cost:.0f}", f"{cost * 1e3:.3g}", f"{single_cost * 1e3:.3g}", f"{cost / single_cost:.2f}",
        f"{run['wall']:.1f}", f"{run['setup']:.1f}", f"{_cpu(run) * 1e3:.3g}", f"{_cpu(run) / _single_cpu(run):.2f}",
        f"{run['peak_total'] / 2**20:.0f} MiB", f"{run['files']}", f"{run['store_bytes'] / 2**20:.1f} MiB",
    ]


def _criteria(results: dict[str, Any]) -> str:
    runs = {run["count"]: run for run in results["runs"]}
    if 10_000 not in runs or 100_000 not in runs:
        return ""
    small, large = _per_realization(runs[10_000]), _per_realization(runs[100_000])
    ratios = [_per_realization(runs[n]) / _single_cost(runs[n]) for n in (10_000, 100_000)]
    checks = [
        ("10⁵ against 10⁴ realizations, cost per realization", "≤ 1.25×", f"{large / small:.2f}×", large <= 1.25 * small),
        ("cost per realization against the single run, 10⁴ / 10⁵", "≤ 0.75×", f"{ratios[0]:.2f}× / {ratios[1]:.2f}×", max(ratios) <= 0.75),
        ("peak memory of all processes, 10⁵ realizations", "≤ 2 GiB", f"{runs[100_000]['peak_total'] / 2**30:.2f} GiB", runs[100_000]["peak_total"] <= 2**30 * 2),
        ("files beside the store, N realizations", "≤ N/500 + 10", ", ".join(f"{r['files']} for {n:,}" for n, r in sorted(runs.items())),
         all(r["files"] <= n / 500 + 10 for n, r in runs.items())),
    ]
    return "Targets (issue 15):\n\n" + report._table(["target", "goal", "measured", "verdict"], [[*c[:3], report._verdict(c[3])] for c in checks])


def _kill_paragraph(kill: dict[str, Any] | None) -> str:
    if not kill:
        return ""
    verdict = "**bitwise identical** to the uninterrupted run's" if kill["identical"] else f"**different** from the uninterrupted run's ({kill['difference']})"
    return (
        f"**Killed twice.** The {kill['count']:,}-realization run, started again into another store, was killed with SIGKILL "
        f"(client and workers) after {kill['done_at_kills'][0]:,} and {kill['done_at_kills'][1]:,} of its {2 * kill['count']:,} cases "
        f"had been persisted, then rerun to completion: the store is {verdict}. (`{' '.join(kill['resumed'])}`)"
    )


def _analysis_paragraph(results: dict[str, Any]) -> str:
    analysis = results.get("analysis", {})
    if "elapsed" not in analysis:
        return f"Analysis of the largest store failed: {analysis.get('error', 'not run')}"
    return (
        f"**Analysis with dask** of the {analysis['realizations']:,}-realization store (`stochpound.open_store`, chunks of the file, "
        f"synchronous scheduler): the probability of pounding with its Clopper–Pearson interval, the mean response std, and the "
        f"largest force and the in-phase count over the {analysis['impacts']:,} rows of the impact table took {analysis['elapsed']:.1f} s, "
        f"peak memory {analysis['peak_total'] / 2**20:.0f} MiB (probability of pounding {analysis['probability']:.4f})."
    )
