"""The exact solver against an earlier revision of the project, measured in one session: ``python -m benchmarks compare REV``.

Warm-speed figures measured on different days are not comparable (the
machine's speed varies by 2x from one day to the next, docs/benchmarks.md).
This benchmark checks out ``REV`` (``git archive``) beside the working tree
and times both in alternating rounds, each round in fresh single-threaded
processes, on the study scenes (a), (b) and (c) under El Centro:

* ``simulate`` warm (the result dataset included) and the engine alone
  (``run_exact``: the recorded outputs, no dataset), best of the repeats of
  each round, then the best and the median over the rounds;
* the first call, with numba's cache in an empty folder (compile time), in
  the first round;
* the outputs compared: number of impacts and peak top-floor displacement of
  Building 1 (m).

With ``--demands`` every run also monitors the demand parameters (both
revisions must take ``demands``).

With ``--experiment [FILE]`` every round also runs an experiment file
(default :data:`EXPERIMENT`, the far-field stripes: 880 cases of the study's
fixed-base pair with two contacts under the 44 FEMA P695 far-field records,
about 10 s on an idle core) in both trees, each in a fresh single-threaded
process with the tree's warm numba cache (an untimed run of it fills the cache
before the first round; the engine is loaded by one warm call before each
run), every case in that process (``workers=0``), into a new store
in a temporary folder:

* the throughput, cases per second after the run's start-up
  (``RunReport.setup``: the store's checks and first write) and over the
  whole run, best and median over the rounds, and the start-up itself;
* whether the two trees' stores hold the same data: every data variable
  ``equals`` its twin (values, dimensions, coordinates; attributes such as
  provenance and dates aside), in every round.

It rewrites the section "Against an earlier revision" of
``docs/benchmarks.md`` (between :data:`SECTION`'s markers; the main suite
keeps it when it rewrites the file).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

import xarray as xr

from benchmarks import report
from benchmarks.sections import Section
from benchmarks.timing import REPOSITORY, run_subprocess

SECTION = Section("<!-- against an earlier revision: start -->", "<!-- against an earlier revision: end -->")
"""This benchmark's section of docs/benchmarks.md."""
SCENES = {"a": (0.2, None, 2.0, 0.02), "b": (None, None, 2.0, 0.02), "c": (0.1, 0.1, 0.5, 0.01)}
"""The study scenes (μ1, μ2, mass factor of Building 2, gap in m), as in :mod:`benchmarks.scenes`."""
EXPERIMENT = REPOSITORY / "experiments" / "intensity" / "far_field_stripes.toml"
"""The experiment of ``--experiment`` without a file: 880 cases of records scaled to stripes, which 4566c96 (2026-11-27) runs too."""

PROBE = """
import json, sys, time
sys.path.insert(0, {tree!r})
import stochpound
assert stochpound.__file__.startswith({tree!r}), stochpound.__file__
try:
    from stochpound.studies.agarwal2004 import study_scene
except ImportError:  # the layout before issue 32: the builders were the test suite's
    from tests.conftest import study_scene
try:
    from stochpound.solvers.exact import run_exact
except ImportError:  # the layout before issue 16
    from stochpound.exact import run_exact

def best(call, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return min(times)

out = {{}}
for key, arguments in {scenes!r}.items():
    scene = stochpound.scene_from_dict(study_scene(*arguments))
    start = time.perf_counter()
    result = stochpound.simulate(scene, method="exact", **{options!r})
    first = time.perf_counter() - start
    top = result.total_displacement.sel(building="B1").isel(floor=-1)
    out[key] = {{
        "first_call": first,
        "simulate": best(lambda: stochpound.simulate(scene, method="exact", **{options!r}), {repeats}),
        "engine": best(lambda: run_exact(scene, **{options!r}), {repeats}),
        "impacts": int(result.sizes["impact"]),
        "peak": float(abs(top).max()),
    }}
print(json.dumps(out))
"""

EXPERIMENT_PROBE = """
import json, sys
sys.path.insert(0, {tree!r})
import stochpound
assert stochpound.__file__.startswith({tree!r}), stochpound.__file__
try:
    from stochpound.studies.agarwal2004 import study_scene
except ImportError:  # the layout before issue 32
    from tests.conftest import study_scene
from stochpound.experiment import load_experiment, run_experiment

stochpound.simulate(stochpound.scene_from_dict(study_scene(*{warm!r})), method="exact")  # the engine loaded from numba's cache, outside the run
run = run_experiment(load_experiment({file!r}), {store!r}, workers=0, progress=False)
print(json.dumps({{"cases": run.done_now, "failed": len(run.failed), "elapsed": run.elapsed, "setup": run.setup}}))
"""


def parse_arguments(argv: list[str] | None) -> argparse.Namespace:
    """Options of ``python -m benchmarks compare``."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks compare", description=__doc__.splitlines()[0])
    parser.add_argument("revision", help="the earlier revision (a commit, tag or branch of this repository)")
    parser.add_argument("--rounds", type=int, default=5, help="alternating rounds (default 5)")
    parser.add_argument("--repeats", type=int, default=30, help="timed calls per scene and round (default 30)")
    parser.add_argument("--demands", action="store_true", help="runs monitor the demand parameters (both revisions must take demands)")
    parser.add_argument("--experiment", type=Path, nargs="?", const=EXPERIMENT, default=None, metavar="FILE",
                        help="every round also runs this experiment file in both trees (default file: experiments/intensity/far_field_stripes.toml): "
                             "cases/s after start-up, and whether the stores' data are identical")
    parser.add_argument("--out", type=Path, default=REPOSITORY / "docs" / "benchmarks.md", help="the Markdown file whose section is rewritten")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Measure both trees and rewrite the section of ``--out``."""
    arguments = parse_arguments(argv)
    info = report.machine()
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="stochpound-compare-") as folder:
        rounds = measure(trees(arguments.revision, Path(folder)), arguments.rounds, arguments.repeats, arguments.demands, Path(folder),
                         arguments.experiment)
    results = {"revision": arguments.revision, "head": info["commit"], "rounds": rounds, "repeats": arguments.repeats,
               "demands": arguments.demands, "elapsed": time.perf_counter() - started, "load_at_end": f"{os.getloadavg()[0]:.2f}",
               "experiment": None if arguments.experiment is None else _shown(arguments.experiment)}
    SECTION.write(arguments.out, section(results, info))
    print(f"wrote the section 'Against an earlier revision' of {arguments.out} in {results['elapsed']:.0f} s")
    return 0


def trees(revision: str | None, folder: Path) -> dict[str, Path]:
    """The trees to time, by name: this one and, given a ``revision``, its files checked out in ``folder``/earlier."""
    if revision is None:
        return {"this tree": REPOSITORY}
    checkout(revision, folder / "earlier")
    return {"this tree": REPOSITORY, revision: folder / "earlier"}


def checkout(revision: str, folder: Path) -> None:
    """The files of ``revision`` in ``folder`` (``git archive``; the working tree is left alone)."""
    folder.mkdir(parents=True)
    archive = subprocess.run(["git", "archive", "--format=tar", revision], cwd=REPOSITORY, capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(folder)], input=archive, check=True)


def measure(trees: dict[str, Path], rounds: int, repeats: int, demands: bool, folder: Path,
            experiment: Path | None = None) -> dict[str, list[dict[str, Any]]]:
    """Every tree's probe, in alternating rounds (runs monitoring the demand parameters when ``demands``); the first round of each tree with numba's cache in an empty folder.

    With an ``experiment`` file, every round then runs it in every tree (:data:`EXPERIMENT_PROBE`; the first round
    runs it once more before, untimed, so that the tree's numba cache holds every kernel it runs) into a store of
    ``folder``; the round's results get its ``"experiment"`` run and,
    for the first tree, ``"stores_differ"``: :func:`store_differences` of its store and each other tree's.
    """
    measured: dict[str, list[dict[str, Any]]] = {name: [] for name in trees}
    for round_ in range(rounds):
        for index, (name, tree) in enumerate(trees.items()):
            cache = folder / f"numba-cache-{index}"
            code = PROBE.format(tree=str(tree), scenes=SCENES, repeats=repeats, options={"demands": True} if demands else {})
            measured[name].append(run_subprocess(code, extra_env={"NUMBA_CACHE_DIR": str(cache)}))
            print(f"round {round_ + 1}: {name} {json.dumps(measured[name][-1])}", flush=True)
        if experiment is not None and round_ == 0:  # an untimed run fills each tree's numba cache with every kernel the experiment runs
            run_experiments(trees, experiment, folder, {name: {} for name in trees})
        if experiment is not None:
            run_experiments(trees, experiment, folder, {name: results[-1] for name, results in measured.items()})
    return measured


def run_experiments(trees: dict[str, Path], experiment: Path, folder: Path, this_round: dict[str, dict[str, Any]]) -> None:
    """Run ``experiment`` in every tree into a new store of ``folder``, add each run to ``this_round`` and compare the stores (then removed)."""
    stores = {}
    for index, (name, tree) in enumerate(trees.items()):
        stores[name] = folder / f"store-{index}.nc"
        code = EXPERIMENT_PROBE.format(tree=str(tree), warm=SCENES["a"], file=str(experiment.resolve()), store=str(stores[name]))
        this_round[name]["experiment"] = run_subprocess(code, extra_env={"NUMBA_CACHE_DIR": str(folder / f"numba-cache-{index}")})
        print(f"  experiment: {name} {json.dumps(this_round[name]['experiment'])}", flush=True)
    first, *others = trees
    this_round[first]["stores_differ"] = {name: store_differences(stores[first], stores[name]) for name in others}
    for store in stores.values():
        store.unlink()
        shutil.rmtree(store.with_name(store.name + ".parts"), ignore_errors=True)


def store_differences(ours: Path, theirs: Path) -> list[str]:
    """The variables of two stores that differ: their data variables and coordinates, each compared on its own with
    :meth:`xarray.Variable.equals` (values and dimensions; not the attributes, which hold provenance and dates, nor the
    other coordinates, each compared in its own right: a coordinate only one store holds does not make every variable on
    its dimension differ), and those only one holds (named ``"<name> (only in one)"``). Empty: the stores hold the same data."""
    with xr.open_dataset(ours) as a, xr.open_dataset(theirs) as b:
        names = set(a.variables) | set(b.variables)
        return sorted(name if name in a.variables and name in b.variables else f"{name} (only in one)"
                      for name in names if not (name in a.variables and name in b.variables and a.variables[name].equals(b.variables[name])))


def throughput(run: dict[str, Any]) -> float:
    """Cases per second of an experiment run after its start-up: ``cases / (elapsed − setup)``."""
    return run["cases"] / (run["elapsed"] - run["setup"])


def _shown(path: Path) -> str:
    """``path`` relative to the repository where it lies in it (no machine's folder in the document)."""
    return str(path.resolve().relative_to(REPOSITORY)) if path.resolve().is_relative_to(REPOSITORY) else path.name


def section(results: dict[str, Any], info: dict[str, str]) -> str:
    """The Markdown section, markers included."""
    names = list(results["rounds"])
    this, earlier = names
    lines = [
        SECTION.start,
        "## Against an earlier revision",
        "",
        f"`python -m benchmarks compare {results['revision']}{_flags(results)}` ({results['elapsed'] / 60:.0f} min): this tree ({results['head']}) and "
        f"revision {results['revision']} timed in {len(results['rounds'][this])} alternating rounds in one session, each round in fresh "
        f"single-threaded processes, {results['repeats']} calls per scene and round; the study scenes under El Centro"
        f"{', every run monitoring the demand parameters (--demands)' if results['demands'] else ''}. Times in ms: best "
        "over the rounds (median of the rounds' bests). *simulate* is the warm call with its result dataset; *engine* is `run_exact` "
        "alone (the recorded outputs, no dataset). The first call compiles the engine into an empty numba cache.",
        "",
        f"| scene | quantity | {this} | {earlier} | ratio (best) |",
        "|---|---|---:|---:|---:|",
    ]
    for key in SCENES:
        for quantity in ("simulate", "engine"):
            ours, theirs = (_times(results["rounds"][name], key, quantity) for name in (this, earlier))
            lines.append(f"| ({key}) | {quantity} | {_cell(ours)} | {_cell(theirs)} | {min(ours) / min(theirs):.3f} |")
    first = {name: results["rounds"][name][0]["a"]["first_call"] for name in names}
    lines.append(f"| (a) | first call (s) | {first[this]:.1f} | {first[earlier]:.1f} | {first[this] / first[earlier]:.2f} |")
    lines += ["", _outputs_sentence(results, this, earlier)]
    if results.get("experiment"):
        lines += ["", *experiment_lines(results, this, earlier)]
    machine = "; ".join(f"{k} {v}" for k, v in info.items())
    lines += ["", f"Machine: {machine}; load average (1 min) at end {results.get('load_at_end', '?')}.", SECTION.end]
    return "\n".join(lines) + "\n"


def _flags(results: dict[str, Any]) -> str:
    """The command's options that change what is measured, as typed (`` --demands``, `` --experiment``)."""
    experiment = results.get("experiment")
    return (" --demands" if results["demands"] else "") + ("" if not experiment else " --experiment" + ("" if experiment == _shown(EXPERIMENT) else f" {experiment}"))


def experiment_lines(results: dict[str, Any], this: str, earlier: str) -> list[str]:
    """The section's part of ``--experiment``: its sentence, its table (cases/s, start-up) and whether the stores hold the same data."""
    rounds = {name: [measured["experiment"] for measured in results["rounds"][name]] for name in (this, earlier)}
    rates = {name: [throughput(run) for run in runs] for name, runs in rounds.items()}
    whole = {name: [run["cases"] / run["elapsed"] for run in runs] for name, runs in rounds.items()}
    setups = {name: [run["setup"] for run in runs] for name, runs in rounds.items()}
    cases = rounds[this][0]["cases"]
    failed = sum(run["failed"] for runs in rounds.values() for run in runs)
    return [
        f"**Experiment** (`--experiment`): `{results['experiment']}`, {cases} cases run in each tree in every round, each in a fresh "
        "single-threaded process with the tree's warm numba cache, every case in that process (`workers=0`), into a new store. "
        "Cases per second after the run's start-up (`RunReport.setup`), and over the whole run (the two revisions may split "
        f"their work differently between start-up and cases): best over the rounds (median){'' if not failed else f'; {failed} cases failed'}; "
        f"{_stores_sentence(results['rounds'][this])}.",
        "",
        f"| quantity | {this} | {earlier} | ratio (best) |",
        "|---|---:|---:|---:|",
        _rate_row("cases/s", rates[this], rates[earlier]),
        _rate_row("cases/s, start-up included", whole[this], whole[earlier]),
        f"| start-up (s) | {min(setups[this]):.2f} ({statistics.median(setups[this]):.2f}) | {min(setups[earlier]):.2f} "
        f"({statistics.median(setups[earlier]):.2f}) | {min(setups[this]) / min(setups[earlier]):.2f} |",
    ]


def _times(rounds: list[dict[str, Any]], key: str, quantity: str) -> list[float]:
    """The rounds' best times (ms) of one scene and quantity."""
    return [1e3 * measured[key][quantity] for measured in rounds]


def _cell(times: list[float]) -> str:
    return f"{min(times):.2f} ({statistics.median(times):.2f})"


def _outputs_sentence(results: dict[str, Any], this: str, earlier: str) -> str:
    """Whether both trees gave the same impacts and peak displacements."""
    parts = []
    for key in SCENES:
        ours, theirs = results["rounds"][this][0][key], results["rounds"][earlier][0][key]
        parts.append(f"({key}) {ours['impacts']} and {theirs['impacts']} impacts, peaks differ by {abs(ours['peak'] - theirs['peak']):.1e} m")
    return "Outputs of the two trees: " + "; ".join(parts) + "."


def _rate_row(quantity: str, ours: list[float], theirs: list[float]) -> str:
    """A table row of rates: the best (largest) over the rounds (median) of both trees and the ratio of the bests."""
    return f"| {quantity} | {max(ours):.1f} ({statistics.median(ours):.1f}) | {max(theirs):.1f} ({statistics.median(theirs):.1f}) | {max(ours) / max(theirs):.3f} |"


def _stores_sentence(rounds: list[dict[str, Any]]) -> str:
    """Whether the stores of the two trees held the same data in every round (``stores_differ`` of the first tree's rounds)."""
    differ = sorted({name for measured in rounds for names in measured["stores_differ"].values() for name in names})
    if differ:
        return "the two trees' stores differ in " + ", ".join(differ)
    return ("the two trees' stores hold the same data in every round (each data variable and coordinate `equals` its twin; "
            "attributes, which hold provenance and dates, aside)")
